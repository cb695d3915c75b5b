// SPDX-License-Identifier: MIT
// `vkcloth soak`: a long run that checks what a short test cannot: no NaN/inf after many steps,
// pinned particles exactly where they started, no growth of the process's memory. Opt-in (not in
// the test suite): tools/soak.sh runs it on the stable samples.
#include <cmath>
#include <cstdio>
#include <memory>

#include <fmt/format.h>
#include <glm/geometric.hpp>
#include <unistd.h>

#include "backend.hpp"
#include "commands.hpp"
#include "vkcloth/scene.hpp"

namespace vkcloth::cli {
namespace {

/// Resident set size of this process in KiB (from /proc/self/statm), 0 if unknown.
std::uint64_t rss_kib() {
  std::FILE* f = std::fopen("/proc/self/statm", "r");
  if (!f)
    return 0;
  unsigned long long size = 0, resident = 0;
  const int n = std::fscanf(f, "%llu %llu", &size, &resident);
  std::fclose(f);
  return n == 2 ? resident * static_cast<std::uint64_t>(sysconf(_SC_PAGESIZE)) / 1024 : 0;
}

struct SoakOptions {
  SceneArgs args;
  std::string backend = "cpu";
  std::uint64_t steps = 100000;
  std::uint64_t checks = 100; ///< state checks over the run
  std::uint64_t max_rss_growth_kib = 1024;
};

int soak_command(const SoakOptions& opt) {
  auto scene = opt.args.load();
  if (!scene)
    return report(scene.error());
  auto backend_r = make_backend(opt.backend, *scene, Precision::float32);
  if (!backend_r)
    return report(backend_r.error());
  SimBackend& backend = **backend_r;

  std::vector<glm::dvec3> pos, vel;
  if (auto r = backend.read_state(pos, vel); !r)
    return report(r.error());
  const std::vector<glm::dvec3> initial = pos;
  double max_pin_drift = 0.0, max_speed = 0.0;
  // One state check: after the warm-up (every step of a run of 10 or fewer) and after each chunk.
  const auto check_state = [&]() -> Result<void> {
    VKCLOTH_TRY(backend.read_state(pos, vel));
    for (std::size_t k = 0; k < pos.size(); ++k) {
      for (int c = 0; c < 3; ++c)
        if (!std::isfinite(pos[k][c]) || !std::isfinite(vel[k][c]))
          return make_error(ErrorCode::diverged, fmt::format("soak: particle {} is not finite at step {}", k,
                                                             backend.step_index()));
      if (scene->system.particles[k].pinned)
        max_pin_drift = std::max(max_pin_drift, glm::length(pos[k] - initial[k]));
      max_speed = std::max(max_speed, glm::length(vel[k]));
    }
    return {};
  };
  // Warm-up (first allocations of the solver and the readback), then the baseline RSS.
  if (auto r = backend.step(std::min<std::uint64_t>(opt.steps, 10)); !r)
    return report(r.error());
  if (auto r = check_state(); !r)
    return report(r.error());
  const std::uint64_t rss0 = rss_kib();

  const std::uint64_t chunk = std::max<std::uint64_t>(1, opt.steps / std::max<std::uint64_t>(1, opt.checks));
  while (backend.step_index() < opt.steps) {
    const std::uint64_t n = std::min(chunk, opt.steps - backend.step_index());
    if (auto r = backend.step(n); !r)
      return report(r.error());
    if (auto r = check_state(); !r)
      return report(r.error());
  }
  const std::uint64_t rss1 = rss_kib();
  const long long growth = static_cast<long long>(rss1) - static_cast<long long>(rss0);
  fmt::print("soak {} ({}): {} particles, {} steps, simulated {:.6g} s; max pinned drift {:.3g} m, max speed "
             "{:.6g} m/s, RSS {} KiB -> {} KiB ({:+} KiB)\n",
             scene->name, opt.backend, scene->system.size(), backend.step_index(), backend.time(),
             max_pin_drift, max_speed, rss0, rss1, growth);
  if (max_pin_drift != 0.0)
    return report(make_error(ErrorCode::diverged,
                             fmt::format("soak: pinned particles moved by {:.3g} m", max_pin_drift)));
  if (growth > static_cast<long long>(opt.max_rss_growth_kib))
    return report(make_error(ErrorCode::out_of_memory, fmt::format("soak: RSS grew by {} KiB (limit {} KiB)",
                                                                   growth, opt.max_rss_growth_kib)));
  return exit_ok;
}

} // namespace

void add_soak_command(CLI::App& app, int* exit) {
  auto opt = std::make_shared<SoakOptions>();
  CLI::App* cmd = app.add_subcommand(
      "soak",
      "Long run: checks no NaN/inf, no drift of pinned particles, no RSS growth (exit 3 / 1 on failure)");
  cmd->footer(exit_codes_footer);
  add_scene_options(*cmd, opt->args, /*sugar=*/false);
  cmd->add_option("--steps", opt->steps, "Steps to run (default 100000)")
      ->check(CLI::Range(std::uint64_t{1}, std::uint64_t{max_scene_steps}));
  cmd->add_option("--checks", opt->checks, "State checks over the run (default 100)")
      ->check(CLI::Range(std::uint64_t{1}, std::uint64_t{1000000}));
  cmd->add_option("--max-rss-growth", opt->max_rss_growth_kib, "Allowed RSS growth in KiB (default 1024)");
  cmd->add_option("--backend", opt->backend, "Solver backend: cpu | vulkan (default cpu)");
  cmd->callback([opt, exit] { *exit = soak_command(*opt); });
}

} // namespace vkcloth::cli
