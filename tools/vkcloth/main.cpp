// SPDX-License-Identifier: MIT
// vkcloth: command-line front end to the scene loader and the solvers.
#include <cstdlib>
#include <cstring>

#include <fmt/format.h>

#include <CLI/CLI.hpp>

#include "commands.hpp"
#include "vkcloth/gpu/context.hpp"

int main(int argc, char** argv) {
  using namespace vkcloth::cli;
  CLI::App app{"vkcloth: mass-spring cloth simulation on the CPU reference solver and on Vulkan compute",
               "vkcloth"};
  app.footer(exit_codes_footer);
  app.require_subcommand(1);

  int exit = exit_ok; // set by the chosen command's callback
  // Global, before the subcommand: sets VKCLOTH_VALIDATION=1 as soon as it is parsed, so before any
  // command callback creates a Context.
  app.add_flag_callback(
         "--validate", [] { ::setenv("VKCLOTH_VALIDATION", "1", 1); },
         "Run Vulkan work under VK_LAYER_KHRONOS_validation with synchronization validation (same as "
         "VKCLOTH_VALIDATION=1); any validation message makes the command exit 1")
      ->trigger_on_parse();
  add_run_command(app, &exit);
  add_compare_command(app, &exit);
  add_info_command(app, &exit);
  add_devices_command(app, &exit);
  add_figures_command(app, &exit);
  add_bench_command(app, &exit);
  add_render_command(app, &exit);
  add_view_command(app, &exit);
  add_soak_command(app, &exit);

  try {
    app.parse(argc, argv);
  } catch (const CLI::CallForHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForAllHelp& e) {
    return app.exit(e);
  } catch (const CLI::ParseError& e) {
    fmt::print(stderr, "vkcloth: {}\nRun 'vkcloth --help' for usage.\n", e.what());
    return exit_bad_input;
  } catch (const std::exception& e) {
    fmt::print(stderr, "vkcloth: unexpected error: {}\n", e.what());
    return exit_failure;
  }
  // With validation on, a validation message is a failure even when the command succeeded.
  const char* v = std::getenv("VKCLOTH_VALIDATION");
  const bool validating = v && *v && std::strcmp(v, "0") != 0 && std::strcmp(v, "false") != 0;
  if (const auto n = vkcloth::gpu::Context::process_validation_message_count(); validating && n > 0) {
    fmt::print(stderr, "vkcloth: Vulkan validation reported {} message{} (see above)\n", n,
               n == 1 ? "" : "s");
    if (exit == exit_ok)
      return exit_failure;
  }
  return exit;
}
