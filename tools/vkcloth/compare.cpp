// SPDX-License-Identifier: MIT
// `vkcloth compare`: the same scene on the CPU reference (float) and on Vulkan, side by side,
// with the max and RMS position difference per window of steps.
#include <algorithm>
#include <cmath>

#include <fmt/format.h>
#include <glm/geometric.hpp>

#include "backend.hpp"
#include "commands.hpp"

namespace vkcloth::cli {
namespace {

struct CompareOptions {
  SceneArgs args;
  std::uint64_t window = 0; ///< steps per report row; 0: a tenth of the run
  double tolerance = 1e-5;  ///< max position difference (scene units) that passes
};

int compare_command(const CompareOptions& opt) {
  auto scene = opt.args.load();
  if (!scene)
    return report(scene.error());
  if (!std::isfinite(opt.tolerance) || opt.tolerance < 0.0)
    return report(make_error(ErrorCode::invalid_argument,
                             fmt::format("--tolerance must be finite and >= 0, got {}", opt.tolerance)));
  auto cpu = make_backend("cpu", *scene, Precision::float32);
  if (!cpu)
    return report(cpu.error());
  auto gpu = make_backend("vulkan", *scene, Precision::float32);
  if (!gpu)
    return report(gpu.error());

  const std::uint64_t total = scene->steps;
  const std::uint64_t window = opt.window ? opt.window : std::max<std::uint64_t>(1, (total + 9) / 10);
  fmt::print("{}: {} particles, {} steps of {:g} s ({}), cpu vs vulkan, float, tolerance {:g}\n", scene->name,
             scene->system.size(), total, scene->params.dt, to_string(scene->params.integrator),
             opt.tolerance);
  fmt::print("{:>21}  {:>12}  {:>12}\n", "steps", "max |dp|", "rms |dp|");

  std::vector<glm::dvec3> pc, vc, pg, vg;
  double worst = 0.0;
  for (std::uint64_t done = 0; done < total;) {
    const std::uint64_t n = std::min(window, total - done);
    auto rc = (*cpu)->step(n);
    auto rg = (*gpu)->step(n);
    if (!rc || !rg) {
      if (!rc && !rg && rc.error().code == ErrorCode::diverged && rg.error().code == ErrorCode::diverged) {
        fmt::print(stderr, "vkcloth: both backends diverged\n  cpu: {}\n  vulkan: {}\n", rc.error().message,
                   rg.error().message);
        return exit_diverged;
      }
      if (!rg && rg.error().code != ErrorCode::diverged)
        return report(rg.error());
      fmt::print(stderr, "vkcloth: the backends disagree: {} diverged, the other did not\n  {}\n",
                 rc ? "vulkan" : "cpu", rc ? rg.error().message : rc.error().message);
      return exit_mismatch;
    }
    if (auto r = (*cpu)->read_state(pc, vc); !r)
      return report(r.error());
    if (auto r = (*gpu)->read_state(pg, vg); !r)
      return report(r.error());
    double max_d = 0.0, sum_sq = 0.0;
    for (std::size_t k = 0; k < pc.size(); ++k) {
      const double d = glm::length(pc[k] - pg[k]);
      max_d = std::max(max_d, d);
      sum_sq += d * d;
    }
    const double rms = std::sqrt(sum_sq / double(pc.size()));
    fmt::print("{:>10}-{:<10}  {:12.3e}  {:12.3e}{}\n", done + 1, done + n, max_d, rms,
               max_d > opt.tolerance ? "  > tolerance" : "");
    worst = std::max(worst, max_d);
    done += n;
  }
  if (worst > opt.tolerance) {
    fmt::print(stderr, "vkcloth: FAIL: max position difference {:.3e} exceeds the tolerance {:g}\n", worst,
               opt.tolerance);
    return exit_mismatch;
  }
  fmt::print("PASS: max position difference {:.3e} <= {:g}\n", worst, opt.tolerance);
  return exit_ok;
}

} // namespace

void add_compare_command(CLI::App& app, int* exit) {
  auto opt = std::make_shared<CompareOptions>();
  CLI::App* cmd = app.add_subcommand(
      "compare",
      "Run a scene on the CPU reference and on Vulkan; print the max and RMS position difference per "
      "window of steps; exit 5 above the tolerance");
  cmd->footer(exit_codes_footer);
  add_scene_options(*cmd, opt->args);
  cmd->add_option("--window", opt->window, "Steps per report row (default: a tenth of the run)")
      ->check(whole_number_at_least_one);
  cmd->add_option("--tolerance", opt->tolerance,
                  "Largest max position difference that passes, in scene units (default 1e-5)");
  cmd->callback([opt, exit] { *exit = compare_command(*opt); });
}

} // namespace vkcloth::cli
