// The `vkcloth` subcommands. Each returns the process exit code (see exit_codes below).
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "vkcloth/result.hpp"

namespace vkcloth::cli {

enum Exit : int {
  exit_ok = 0,
  exit_failure = 1,   ///< an unexpected runtime failure (Vulkan error, out of memory)
  exit_bad_input = 2, ///< bad command line, unreadable or invalid scene, unwritable output
  exit_diverged = 3,  ///< the simulation blew up
  exit_no_device = 4, ///< no usable Vulkan device (or the backend is not built in)
  exit_mismatch = 5,  ///< `compare`: the backends differ by more than the tolerance
};

/// Maps an error to the exit code documented in --help and docs/scene-format.md.
int exit_code(const Error& e);
/// Prints "vkcloth: <message>" on stderr and returns exit_code(e).
int report(const Error& e);

struct RunOptions {
  std::string scene;
  std::vector<std::string> overrides; ///< --set, then --steps/--dt/--integrator
  std::string trace;                  ///< empty: no trace
  std::uint64_t trace_every = 1;
  std::string positions; ///< empty: no final positions file
  std::string backend = "cpu";
  std::string precision = "float";
};

struct InfoOptions {
  std::string scene;
  std::vector<std::string> overrides;
};

struct CompareOptions {
  std::string scene;
  std::vector<std::string> overrides; ///< --set, then --steps/--dt/--integrator
  std::uint64_t window = 0;           ///< steps per report row; 0: a tenth of the run
  double tolerance = 1e-5;            ///< max position difference (scene units) that passes
};

int run_command(const RunOptions& opt);
int info_command(const InfoOptions& opt);
int compare_command(const CompareOptions& opt);
int devices_command();

} // namespace vkcloth::cli
