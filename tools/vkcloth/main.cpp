// vkcloth: command-line front end to the scene loader and the solvers.
#include <fmt/format.h>

#include <CLI/CLI.hpp>

#include "commands.hpp"

namespace vkcloth::cli {

int exit_code(const Error& e) {
  switch (e.code) {
  case ErrorCode::invalid_argument:
  case ErrorCode::io:
  case ErrorCode::parse:
    return exit_bad_input;
  case ErrorCode::diverged:
    return exit_diverged;
  case ErrorCode::no_device:
  case ErrorCode::unsupported:
    return exit_no_device;
  case ErrorCode::vulkan:
  case ErrorCode::out_of_memory:
    return exit_failure;
  }
  return exit_failure;
}

int report(const Error& e) {
  fmt::print(stderr, "vkcloth: {}\n", e.message);
  return exit_code(e);
}

} // namespace vkcloth::cli

namespace {

constexpr const char* exit_codes_footer = R"(Exit codes:
  0  success
  1  unexpected runtime failure (Vulkan error, out of memory)
  2  bad input or usage: command line, scene file (the message names the key), output file
  3  the simulation diverged (the message names the step and time; --trace keeps the rows before it)
  4  no usable Vulkan device
  5  compare: the backends differ by more than the tolerance
Scene format and CSV outputs: docs/scene-format.md)";

void add_override_options(CLI::App& cmd, std::vector<std::string>& overrides) {
  cmd.add_option("--set", overrides,
                 "Override a scene key before validation: key.path=value (value is JSON, or a plain string), "
                 "e.g. cloth.stiffness.bend=15, wind.direction=[0,1,0], colliders.0.radius=0.3. Repeatable.")
      ->type_name("KEY=VALUE")
      ->allow_extra_args(false);
}

} // namespace

int main(int argc, char** argv) {
  using namespace vkcloth::cli;
  CLI::App app{"vkcloth: mass-spring cloth simulation on the CPU reference solver and on Vulkan compute", "vkcloth"};
  app.footer(exit_codes_footer);
  app.require_subcommand(1);

  RunOptions run;
  std::optional<std::uint64_t> steps;
  std::optional<double> dt;
  std::optional<std::string> integrator;
  CLI::App* run_cmd = app.add_subcommand("run", "Simulate a scene and optionally write CSV traces");
  run_cmd->footer(exit_codes_footer);
  run_cmd->add_option("scene", run.scene, "Scene file (JSON)")->required();
  run_cmd->add_option("--steps", steps, "Number of steps (sugar for --set integrator.steps=N)");
  run_cmd->add_option("--dt", dt, "Time step in seconds (sugar for --set integrator.dt=X)");
  run_cmd->add_option("--integrator", integrator,
                      "explicit_euler | semi_implicit_euler | rk4 (sugar for --set integrator.method=NAME)");
  add_override_options(*run_cmd, run.overrides);
  auto* trace =
      run_cmd->add_option("--trace", run.trace,
                          "Write every particle's state to a CSV file: step,time,particle,x,y,z,vx,vy,vz "
                          "(step 0 then every K steps)");
  run_cmd->add_option("--trace-every", run.trace_every, "K for --trace (default 1)")
      ->check(CLI::PositiveNumber)
      ->needs(trace);
  run_cmd->add_option("--positions", run.positions,
                      "Write the final positions to a CSV file: particle,x,y,z");
  run_cmd->add_option("--backend", run.backend, "Solver backend: cpu | vulkan (default cpu)");
  run_cmd->add_option("--precision", run.precision, "Solver arithmetic: float | double (default float)")
      ->check(CLI::IsMember({"float", "double"}));

  CompareOptions compare;
  std::optional<std::uint64_t> cmp_steps;
  std::optional<double> cmp_dt;
  std::optional<std::string> cmp_integrator;
  CLI::App* compare_cmd = app.add_subcommand(
      "compare", "Run a scene on the CPU reference and on Vulkan; print the max and RMS position difference "
                 "per window of steps; exit 5 above the tolerance");
  compare_cmd->footer(exit_codes_footer);
  compare_cmd->add_option("scene", compare.scene, "Scene file (JSON)")->required();
  compare_cmd->add_option("--steps", cmp_steps, "Number of steps (sugar for --set integrator.steps=N)");
  compare_cmd->add_option("--dt", cmp_dt, "Time step in seconds (sugar for --set integrator.dt=X)");
  compare_cmd->add_option("--integrator", cmp_integrator, "explicit_euler | semi_implicit_euler | rk4");
  add_override_options(*compare_cmd, compare.overrides);
  compare_cmd->add_option("--window", compare.window, "Steps per report row (default: a tenth of the run)")
      ->check(CLI::PositiveNumber);
  compare_cmd->add_option("--tolerance", compare.tolerance,
                          "Largest max position difference that passes, in scene units (default 1e-5)");

  CLI::App* devices_cmd =
      app.add_subcommand("devices", "List the Vulkan devices and the one a solver would use (exit 4 if none)");
  devices_cmd->footer(exit_codes_footer);

  InfoOptions info;
  CLI::App* info_cmd =
      app.add_subcommand("info", "Print a parsed scene: particles, springs per kind, parameters");
  info_cmd->footer(exit_codes_footer);
  info_cmd->add_option("scene", info.scene, "Scene file (JSON)")->required();
  add_override_options(*info_cmd, info.overrides);

  try {
    app.parse(argc, argv);
  } catch (const CLI::CallForHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForAllHelp& e) {
    return app.exit(e);
  } catch (const CLI::ParseError& e) {
    fmt::print(stderr, "vkcloth: {}\nRun 'vkcloth --help' for usage.\n", e.what());
    return exit_bad_input;
  }

  try {
    // The sugar flags come after --set, so they win over a --set of the same key.
    const auto add_sugar = [](std::vector<std::string>& overrides, const std::optional<std::uint64_t>& n,
                              const std::optional<double>& h, const std::optional<std::string>& method) {
      if (n)
        overrides.push_back(fmt::format("integrator.steps={}", *n));
      if (h)
        overrides.push_back(fmt::format("integrator.dt={:.17g}", *h));
      if (method)
        overrides.push_back(fmt::format("integrator.method={}", *method));
    };
    if (*run_cmd) {
      add_sugar(run.overrides, steps, dt, integrator);
      return run_command(run);
    }
    if (*compare_cmd) {
      add_sugar(compare.overrides, cmp_steps, cmp_dt, cmp_integrator);
      return compare_command(compare);
    }
    if (*devices_cmd)
      return devices_command();
    return info_command(info);
  } catch (const std::exception& e) {
    fmt::print(stderr, "vkcloth: unexpected error: {}\n", e.what());
    return exit_failure;
  }
}
