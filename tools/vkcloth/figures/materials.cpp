// SPDX-License-Identifier: MIT
// The stretch-control and material figures of the cloth gallery (cloth.cpp runs them after the
// report's): the report's Figure 7 cloth with and without the strain limit, one material at three
// resolutions, and the material presets over a sphere.
#include <cmath>

#include <fmt/format.h>

#include "cloth_drawing.hpp"
#include "figures.hpp"
#include "report_cloth.hpp"
#include "vkcloth/material.hpp"
#include "vkcloth/scene.hpp"

namespace vkcloth::figures {
namespace {

const char* const sec_materials = "Stretch control and materials";

/// The report's Figure 7 cloth with all three spring kinds (K_struct = 5 / 20 / 50, shear and bend 8),
/// without (top row) and with (bottom row) the strain limit (tethers + Provot, 10 %, 4 sweeps).
Result<void> strain_limit_figure(Gallery& G, Drawing& d, nlohmann::json& M, const std::string& note) {
  std::vector<Run> runs;
  std::vector<std::string> labels;
  for (bool limit : {false, true})
    for (double k : {5.0, 20.0, 50.0}) {
      SimParams p = report_params();
      if (limit)
        p.stretch_limit = {StretchLimit::Method::both, 0.1, 4};
      auto r = simulate_cloth(d, cloth_scene(hanging(k, 8, 8), p, "strain_limit"), 500, G.backend);
      if (!r)
        return r.error();
      M["strain_limit"][limit ? "on" : "off"][key(k)] = {{"max_strain", max_strain(*r)},
                                                         {"min_z", min_z(*r)},
                                                         {"sag", sag(*r)},
                                                         {"diverged", !r->diverged.empty()}};
      runs.push_back(std::move(*r));
      labels.push_back(fmt::format("K = {:g}, {}", k, limit ? "limit 0.1" : "no limit"));
    }
  return grid_figure(
      G, d, runs, labels, "cloth_strain_limit.png", sec_materials,
      "Figure 7 with and without the strain limit",
      note +
          "K_struct = 5 / 20 / 50 with shear and bend springs 8, after 10 s. Top row: the springs alone "
          "(the softer, the longer the cloth). Bottom row: stretch_limit = {method: both, max_strain: 0.1, "
          "iterations: 4} (tethers to the pinned corners, then Provot's sweeps over the structural "
          "springs): the cloth keeps its size whatever K_struct. Largest structural strain and lowest "
          "point of each panel: cloth.strain_limit.{off,on}.<K>.",
      {0.9f, -1.6f, 1.0f}, true, 3);
}

/// Cotton hanging from its two top corners at 16 x 16, 32 x 32 and 64 x 64: a material (not spring
/// constants) gives the same drape at every resolution.
Result<void> resolution_figure(Gallery& G, Drawing& d, nlohmann::json& M) {
  const Material cotton = *material_preset("cotton");
  std::vector<Run> runs;
  std::vector<std::string> labels;
  double lo = 1e30, hi = -1e30;
  for (std::uint32_t n : {16u, 32u, 64u}) {
    ClothDesc desc;
    desc.nx = desc.ny = n;
    desc.origin = {-0.5, 0.0, 0.5};
    desc.material = cotton;
    SimParams p = report_params();
    p.integrator = Integrator::implicit_euler;
    p.cg_tolerance = 1e-4;
    p.cg_max_iterations = 1000;
    p.damping = cotton.damping;
    // Always the CPU solver: the Vulkan implicit step records every allowed CG iteration, which on
    // lavapipe takes minutes at 64 x 64 (docs/performance.md).
    auto r = simulate_cloth(d, cloth_scene(desc, p, "resolution"), 50, "cpu");
    if (!r)
      return r.error();
    const double z = min_z(*r);
    lo = std::min(lo, z), hi = std::max(hi, z);
    M["resolution"][std::to_string(n)] = {
        {"min_z", z}, {"sag", sag(*r)}, {"max_strain", max_strain(*r)}, {"diverged", !r->diverged.empty()}};
    runs.push_back(std::move(*r));
    labels.push_back(fmt::format("{} x {}", n, n));
  }
  M["resolution"]["min_z_spread_percent"] = 100.0 * (hi - lo) / 1.0; // of the 1 m cloth
  return grid_figure(
      G, d, runs, labels, "cloth_resolution.png", sec_materials, "One material at three resolutions",
      "Cotton (density 0.15 kg/m^2, stretch 500 N/m, shear 50 N/m, bend 1e-5 N m, mu = 0.5; "
      "docs/model.md, Materials), 1 x 1 m hanging from its two top corners, at 16 x 16, 32 x 32 and "
      "64 x 64 points, implicit Euler at dt = 0.02 s (CG to a relative residual of 1e-4), after 1 s "
      "(settled: at 16 x 16 and 32 x 32 the lowest point moves by 2e-6 m more by 3 s). The masses "
      "and spring constants follow from the material for each spacing, so the drape is the same: lowest "
      "point of each and their spread in % of the cloth's size in cloth.resolution. Simulated by the CPU "
      "solver whatever --backend says (the Vulkan implicit step is slow on lavapipe).");
}

/// Every material preset dropped flat onto the sphere of samples/scenes/cloth_on_sphere.json.
Result<void> presets_figure(Gallery& G, Drawing& d, nlohmann::json& M) {
  const Collider sphere = Collider::sphere({0, 0, 0.3}, 0.3);
  std::vector<Run> runs;
  std::vector<std::string> labels;
  for (std::string_view name : material_preset_names()) {
    if (name == "report") // fitted to the report's 10 x 10 grid: needs a spacing of at least 0.09 m
      continue;
    const Material m = *material_preset(name);
    ClothDesc desc = horizontal(0.8);
    desc.nx = desc.ny = 20;
    desc.material = m;
    SimParams p = report_params(0.01);
    p.integrator = Integrator::implicit_euler;
    p.cg_max_iterations = 1000;
    p.damping = m.damping;
    p.colliders = {sphere, Collider::plane({0, 0, 1}, 0.0)};
    auto r = simulate_cloth(d, cloth_scene(desc, p, "presets"), 100, "cpu"); // as the resolution figure
    if (!r)
      return r.error();
    const double z = min_z(*r);
    M["presets"][std::string(name)] = {{"min_z", z},
                                       {"below_equator", sphere.center.z - z},
                                       {"sag", sag(*r)},
                                       {"max_strain", max_strain(*r)},
                                       {"diverged", !r->diverged.empty()}};
    runs.push_back(std::move(*r));
    labels.push_back(std::string(name));
  }
  return grid_figure(
      G, d, runs, labels, "cloth_presets.png", sec_materials, "The material presets over the sphere",
      "Each preset but report (cotton, silk, denim, leather, rubber; docs/scene-format.md, Materials) "
      "as a 1 x 1 m cloth of 20 x 20 points dropped flat from z = 0.8 m onto the sphere of "
      "samples/scenes/cloth_on_sphere.json (r = 0.3 m, centre z = 0.3 m, and its floor), implicit Euler "
      "at dt = 0.01 s, after 1 s: draped, before the frictionless sphere lets the cloth slide off. The "
      "stiffer in bending, the higher the cloth stays: the lowest points come in the order of the "
      "bending stiffness (silk 3e-6, cotton 1e-5, denim 1e-4, rubber 1.7e-4, leather 1e-3 N m). "
      "Lowest point and how far it hangs below the sphere's equator (z = 0.3 m) in cloth.presets. "
      "The impact is violent for the stiff presets: their largest structural strain is still 0.25 "
      "(denim) and 0.13 (leather) at 1 s (cloth.presets.*.max_strain; contact projection against "
      "stiff springs). (The report preset is fitted to the report's 10 x 10 grid: 20 x 20 is finer "
      "than its bending stiffness allows.) Simulated by the CPU solver whatever --backend says.",
      {0.9f, -1.6f, 1.0f});
}

} // namespace

Result<void> material_figures(Gallery& G, Drawing& d, nlohmann::json& M, const std::string& note,
                              const Progress& progress) {
  progress("Figure 7 with and without the strain limit");
  VKCLOTH_TRY(strain_limit_figure(G, d, M, note));
  progress("one material at three resolutions");
  VKCLOTH_TRY(resolution_figure(G, d, M));
  progress("the material presets over the sphere");
  VKCLOTH_TRY(presets_figure(G, d, M));
  return {};
}

} // namespace vkcloth::figures
