// SPDX-License-Identifier: MIT
// Real fabric: the cotton drop onto a sphere at 32 x 32, by semi-implicit Euler
// with substeps, implicit Euler by CG and vertex block descent, always on the CPU solver (the cost
// is what is drawn). Two plots over the run (the largest structural strain, and the wall time spent
// so far), the final states side by side, and metrics["stiff"].
#include <algorithm>
#include <chrono>
#include <cstdint>
#include <string>
#include <vector>

#include <fmt/format.h>

#include "cloth_drawing.hpp"
#include "figures.hpp"
#include "vkcloth/cpu_solver.hpp"
#include "vkcloth/measure.hpp"
#include "vkcloth_plot/svg_plot.hpp"

namespace vkcloth::figures {
namespace {

const char* const sec_stiff = "Real fabric: a stiff cloth";

// The cotton drop at 32 x 32 for 1.5 s: 1 m of cotton 0.25 m above a sphere of radius 0.25
// (friction 0.5), dt 1/300. The sphere's top is hit at ~0.23 s.
constexpr const char* drop_scene = R"({
  "name": "cotton_drop", "system": "cloth",
  "integrator": { "method": "vbd", "dt": 0.0033333333333333335, "steps": 450 },
  "cloth": { "resolution": [32, 32], "size": [1, 1], "origin": [-0.5, -0.5, 0.5],
             "orientation": "horizontal", "material": "cotton", "pins": [] },
  "colliders": [ { "type": "sphere", "center": [0, 0, 0], "radius": 0.25, "friction": 0.5 } ],
  "contact_epsilon": 1e-3
})";

struct Solver {
  const char* key;   ///< metrics["stiff"][key]
  const char* label; ///< the plots' legend
  const char* brief; ///< the panel's label
  std::vector<std::string> overrides;
};

const Solver solvers[] = {
    {"semi_implicit_euler",
     "semi-implicit Euler, 20 substeps",
     "semi-impl. x 20",
     {"integrator.method=semi_implicit_euler", "integrator.substeps=20"}},
    {"implicit_euler", "implicit Euler (CG)", "CG", {"integrator.method=implicit_euler"}},
    {"vbd", "vbd, 5 sweeps", "vbd 1 x 5", {"integrator.method=vbd"}},
    {"vbd_substeps",
     "vbd, 4 substeps of 1 sweep",
     "vbd 4 x 1",
     {"integrator.method=vbd", "integrator.substeps=4", "integrator.iterations=1"}},
};

/// One solver over the drop: the largest structural strain and the wall time so far, sampled every
/// `every` steps, the run's final state and its metrics.
struct Timeline {
  std::vector<double> t, strain_percent, seconds;
  Run run;
  nlohmann::json metrics;
};

Result<Timeline> run_timeline(const Solver& solver, std::uint64_t every) {
  auto scene = parse_scene(drop_scene, "the stiff-cloth figure", solver.overrides);
  if (!scene)
    return scene.error();
  Timeline tl;
  tl.run.scene = std::move(*scene);
  const Scene& s = tl.run.scene;
  for (const Particle& p : s.system.particles)
    tl.run.initial.push_back(p.position);
  auto cpu = CpuSolver<float>::create(s.system, s.params);
  if (!cpu)
    return cpu.error();
  double largest = 0.0, spent = 0.0;
  for (std::uint64_t step = 1; step <= s.steps; ++step) {
    const auto t0 = std::chrono::steady_clock::now();
    auto r = cpu->step();
    spent += std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    if (!r) {
      if (r.error().code != ErrorCode::diverged)
        return r.error();
      tl.run.diverged = r.error().message;
      break;
    }
    if (step % every != 0 && step != s.steps)
      continue;
    auto strain = structural_strain(s.system, cpu->positions());
    if (!strain)
      return strain.error();
    largest = std::max(largest, strain->max);
    tl.t.push_back(double(step) * s.params.dt);
    tl.strain_percent.push_back(100.0 * strain->max);
    tl.seconds.push_back(spent);
  }
  tl.run.pos = to_d(cpu->positions());
  tl.metrics = {{"solver", solver.label},
                {"steps", s.steps},
                {"dt", s.params.dt},
                {"substeps", s.params.substeps},
                {"vbd_iterations", s.params.vbd_iterations},
                {"particles", s.system.particles.size()},
                {"max_strain", largest},
                {"end_strain", max_strain(tl.run)},
                {"min_z", min_z(tl.run)},
                {"seconds", spent},
                {"diverged", !tl.run.diverged.empty()}};
  return tl;
}

} // namespace

Result<void> stiff_figures(Gallery& G) {
  Drawing d;
  VKCLOTH_TRY(open_drawing(G, d, "stiff"));
  auto& M = G.metrics["stiff"];
  const Progress progress("stiff");
  plot::Plot strain{"Largest structural strain over the run (cotton drop, 32 x 32, dt = 1/300 s)",
                    "t (s)",
                    "largest structural strain (%)",
                    {},
                    0,
                    0,
                    640,
                    400};
  plot::Plot cost{
      "Wall time spent so far (CPU solver, this machine)", "t (s)", "wall time (s)", {}, 0, 0, 640, 400};
  std::vector<Run> runs;
  std::vector<std::string> labels;
  std::size_t colour = 0;
  for (const Solver& solver : solvers) {
    progress(solver.label);
    auto tl = run_timeline(solver, 3);
    if (!tl)
      return tl.error();
    M[solver.key] = tl->metrics;
    const std::string note = tl->run.diverged.empty() ? "" : "diverged";
    strain.series.push_back({solver.label, plot::palette(colour), tl->t, tl->strain_percent, false, note});
    cost.series.push_back({solver.label, plot::palette(colour), tl->t, tl->seconds, false, note});
    ++colour;
    labels.push_back(
        fmt::format("{}: {:.0f} %", solver.brief, 100.0 * tl->metrics["max_strain"].get<double>()));
    if (d.ctx) {
      auto gpu = display_solver(*d.ctx, tl->run);
      if (!gpu)
        return gpu.error();
      tl->run.gpu.emplace(std::move(*gpu));
    }
    runs.push_back(std::move(tl->run));
  }
  const std::string scene_words =
      "1 m of cotton (32 x 32 points) dropped from 0.25 m above a sphere of radius 0.25 m (friction "
      "0.5), dt = 1/300 s for 1.5 s, on the CPU solver";
  VKCLOTH_TRY(G.write_text("stiff_strain.svg", to_svg(strain)));
  G.figures.push_back({"stiff_strain.svg", sec_stiff, "How far each solver lets cotton stretch",
                       scene_words +
                           ". Cotton's springs make dt = 1/300 s too long for semi-implicit Euler without "
                           "substeps; the implicit solvers take it whole. Sampled every 3 steps "
                           "(stiff.*.max_strain)."});
  VKCLOTH_TRY(G.write_text("stiff_cost.svg", to_svg(cost)));
  G.figures.push_back({"stiff_cost.svg", sec_stiff, "What each solver costs",
                       scene_words + ": the wall time of the steps so far, measurement excluded "
                                     "(stiff.*.seconds). Machine-dependent: compare the lines, not the "
                                     "numbers."});
  VKCLOTH_TRY(grid_figure(G, d, runs, labels, "stiff_final.png", sec_stiff, "The drop's end, per solver",
                          scene_words + ". Labels: the solver (substeps x sweeps for vbd) and the largest "
                                        "structural strain over the run.",
                          {0.9f, -1.6f, 1.0f}, true, 2));
  progress("done");
  return {};
}

} // namespace vkcloth::figures
