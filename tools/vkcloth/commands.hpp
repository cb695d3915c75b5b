// SPDX-License-Identifier: MIT
// The `vkcloth` subcommands. Each returns the process exit code (see exit_codes below).
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

#include "vkcloth/result.hpp"
#include "vkcloth/scene.hpp"

namespace vkcloth::cli {

enum Exit : int {
  exit_ok = 0,
  exit_failure = 1,   ///< an unexpected runtime failure (Vulkan error, out of memory)
  exit_bad_input = 2, ///< bad command line, unreadable or invalid scene, unwritable output
  exit_diverged = 3,  ///< the simulation blew up
  exit_no_device = 4, ///< no usable Vulkan device (or the backend is not built in)
  exit_mismatch = 5,  ///< `compare`: the backends differ by more than the tolerance
};

/// Option checks whose messages name the bound and the value as typed (CLI11's PositiveNumber
/// wrote "Value 0 not in range 0.000000 to 1797...(300 digits)"): a whole number >= 1 (a K of
/// --trace-every and friends), a finite number > 0 and a finite number >= 0.
extern const CLI::Validator whole_number_at_least_one;
extern const CLI::Validator positive_number;
extern const CLI::Validator non_negative_number;

/// Maps an error to the exit code documented in --help and docs/scene-format.md.
int exit_code(const Error& e);
/// Prints "vkcloth: <message>" on stderr and returns exit_code(e).
int report(const Error& e);

/// The scene arguments shared by the commands that load a scene: the file, --set overrides and
/// the --steps / --dt / --integrator sugar (applied after --set, so they win).
struct SceneArgs {
  std::string scene;
  std::vector<std::string> sets;
  std::optional<std::string> steps; // as typed: the scene key's check names a bad count as it was given
  std::optional<double> dt;
  std::optional<std::string> integrator;
  /// --set values followed by the sugar flags, as key.path=value strings.
  std::vector<std::string> overrides() const;
  /// load_scene_file(scene, overrides()), printing each of the scene's warnings (a mesh's dropped
  /// faces, a pin region that pins nothing) as "vkcloth: warning: ..." on stderr.
  Result<Scene> load() const;
};

/// The exit-code table, shown under every command's --help.
extern const char* const exit_codes_footer;

/// Registers SCENE, --set, --steps, --dt and --integrator on `cmd`.
void add_scene_options(CLI::App& cmd, SceneArgs& args, bool sugar = true);

// Each command registers itself on the app; when chosen, its callback stores its exit code in
// *exit. One line per command in main.cpp.
void add_run_command(CLI::App& app, int* exit);
void add_info_command(CLI::App& app, int* exit);
void add_compare_command(CLI::App& app, int* exit);
void add_devices_command(CLI::App& app, int* exit);
void add_figures_command(CLI::App& app, int* exit);
void add_bench_command(CLI::App& app, int* exit);
void add_render_command(CLI::App& app, int* exit);
void add_view_command(CLI::App& app, int* exit);
void add_soak_command(CLI::App& app, int* exit);

} // namespace vkcloth::cli
