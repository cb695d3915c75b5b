// SPDX-License-Identifier: MIT
// Stability map: a 10 x 10 hanging cloth over a (K_struct, dt) grid, each cell stable
// or not for semi-implicit Euler, RK4 and implicit Euler; three panels of coloured cells.
#include <algorithm>
#include <array>
#include <cmath>

#include <fmt/format.h>
#include <glm/geometric.hpp>

#include "figures.hpp"
#include "vkcloth/cpu_solver.hpp"

namespace vkcloth::figures {
namespace {

constexpr std::array<double, 5> kStiffness = {40.0, 200.0, 1000.0, 5000.0, 20000.0};
constexpr std::array<double, 5> kDt = {0.005, 0.01, 0.02, 0.05, 0.1};
constexpr std::uint64_t kSteps = 200;
constexpr double kStrainLimit = 10.0; // bounded but absurd (a spring 11x its rest length) counts as unstable

struct Cell {
  bool stable = false;
  double strain = 0.0; // max structural strain at the end (inf when diverged)
};

Cell run_cell(Integrator integ, double k, double dt) {
  ClothDesc d;
  d.origin = {-0.5, 0.0, 0.5};
  d.stiffness = {k, k / 5.0, k / 5.0}; // the 10 000 / 2 000 / 2 000 ratio
  const ParticleSystem sys = *make_cloth(d);
  SimParams p;
  p.integrator = integ;
  p.dt = dt;
  p.divergence_limit = 100.0; // the cloth is 1 m: 100 m away is a blow-up
  auto s = CpuSolver<float>::create(sys, p);
  if (!s || !s->run(kSteps))
    return {false, INFINITY};
  double strain = 0.0;
  const auto pos = s->positions();
  for (const Spring& sp : sys.springs)
    if (sp.kind == SpringKind::structural)
      strain = std::max(strain, double(glm::length(pos[sp.b] - pos[sp.a])) / sp.rest_length - 1.0);
  return {strain < kStrainLimit, strain};
}

} // namespace

Result<void> stability_figures(Gallery& G) {
  const std::array<std::pair<Integrator, const char*>, 3> schemes = {
      {{Integrator::semi_implicit_euler, "Semi-implicit Euler"},
       {Integrator::rk4, "RK4"},
       {Integrator::implicit_euler, "Implicit Euler (CG)"}}};
  auto& M = G.metrics["stability_map"];
  M["k_struct"] = kStiffness;
  M["dt"] = kDt;
  M["steps"] = kSteps;
  M["cloth"] = "10 x 10, 1 m, particle mass 0.05 kg, K_shear = K_bend = K_struct / 5, damping 0.5, cpu float";
  M["strain_limit"] = kStrainLimit;
  const int cell = 44, left = 70, top = 50, panel_w = left + cell * int(kDt.size()) + 30;
  const int width = panel_w * int(schemes.size()), height = top + cell * int(kStiffness.size()) + 60;
  std::string svg =
      fmt::format("<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"{}\" height=\"{}\" "
                  "font-family=\"sans-serif\" font-size=\"11\">\n<rect width=\"100%\" height=\"100%\" "
                  "fill=\"white\"/>\n",
                  width, height);
  for (std::size_t s = 0; s < schemes.size(); ++s) {
    const auto [integ, title] = schemes[s];
    const int x0 = int(s) * panel_w + left;
    svg += fmt::format("<text x=\"{}\" y=\"20\" font-size=\"14\" text-anchor=\"middle\">{}</text>\n",
                       x0 + cell * int(kDt.size()) / 2, title);
    nlohmann::json grid = nlohmann::json::array(), strains = nlohmann::json::array();
    for (std::size_t i = 0; i < kStiffness.size(); ++i) {
      nlohmann::json row = nlohmann::json::array(), srow = nlohmann::json::array();
      const int y = top + int(kStiffness.size() - 1 - i) * cell; // stiffest on top
      svg += fmt::format("<text x=\"{}\" y=\"{}\" text-anchor=\"end\">{:g}</text>\n", x0 - 6,
                         y + cell / 2 + 4, kStiffness[i]);
      for (std::size_t j = 0; j < kDt.size(); ++j) {
        const Cell c = run_cell(integ, kStiffness[i], kDt[j]);
        row.push_back(c.stable);
        srow.push_back(std::isfinite(c.strain) ? nlohmann::json(c.strain) : nlohmann::json(nullptr));
        svg +=
            fmt::format("<rect x=\"{}\" y=\"{}\" width=\"{}\" height=\"{}\" fill=\"{}\" stroke=\"white\"/>\n",
                        x0 + int(j) * cell, y, cell, cell, c.stable ? "#2ca02c" : "#d62728");
        svg += fmt::format("<text x=\"{}\" y=\"{}\" text-anchor=\"middle\" fill=\"white\">{}</text>\n",
                           x0 + int(j) * cell + cell / 2, y + cell / 2 + 4, c.stable ? "ok" : "x");
      }
      grid.push_back(row);
      strains.push_back(srow);
    }
    for (std::size_t j = 0; j < kDt.size(); ++j)
      svg += fmt::format("<text x=\"{}\" y=\"{}\" text-anchor=\"middle\">{:g}</text>\n",
                         x0 + int(j) * cell + cell / 2, top + cell * int(kStiffness.size()) + 16, kDt[j]);
    svg += fmt::format("<text x=\"{}\" y=\"{}\" text-anchor=\"middle\">dt (s)</text>\n",
                       x0 + cell * int(kDt.size()) / 2, top + cell * int(kStiffness.size()) + 34);
    svg += fmt::format(
        "<text x=\"{}\" y=\"{}\" text-anchor=\"middle\" transform=\"rotate(-90 {} {})\">K_struct "
        "(N/m)</text>\n",
        x0 - 50, top + cell * int(kStiffness.size()) / 2, x0 - 50, top + cell * int(kStiffness.size()) / 2);
    M[to_string(integ)] = grid;
    M[std::string(to_string(integ)) + "_strain"] = strains;
  }
  svg += fmt::format(
      "<text x=\"10\" y=\"{}\">green: stable ({} steps, max structural strain &lt; {:g}); red: diverged "
      "or over-stretched</text>\n</svg>\n",
      height - 8, kSteps, kStrainLimit);
  VKCLOTH_TRY(G.write_text("stability_map.svg", svg));
  G.figures.push_back(
      {"stability_map.svg", "Stiff cloth: stability", "Stability map: K_struct x dt",
       fmt::format("10 x 10 cloth, 0.05 kg per particle, K_shear = K_bend = K_struct / 5, damping 0.5, "
                   "{} steps per cell (CPU float, whatever --backend). A cell is stable when the run "
                   "does not blow up (|p| > 100 m or NaN) and no structural spring ends stretched past {:g} "
                   "%. Implicit "
                   "Euler (backward Euler, CG, tolerance 1e-6) is stable on every cell.",
                   kSteps, 100.0 * kStrainLimit)});
  return {};
}

} // namespace vkcloth::figures
