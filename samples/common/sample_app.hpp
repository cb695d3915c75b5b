// SPDX-License-Identifier: MIT
// What every sample shares: its command line (--offscreen, --frames, --out, --size, --backend), and
// the loop that simulates a scene and draws it, either in a window (GLFW + a swapchain,
// like `vkcloth view`) or offscreen to numbered PNG files (no display needed, e.g. lavapipe).
#pragma once

#include <cstdint>
#include <filesystem>
#include <string>

#include "vkcloth/scene.hpp"

namespace samples {

struct Options {
  bool offscreen = false;
  std::uint32_t frames = 0;          ///< 0: until the window closes (windowed), 60 (offscreen)
  std::uint32_t steps_per_frame = 0; ///< 0: about real time at 60 frames per second
  std::filesystem::path out = "out"; ///< offscreen frames and the samples' plots go here
  std::uint32_t width = 800, height = 600;
  std::string preset; ///< `cloth --preset NAME`
  /// --backend auto | cpu | vulkan; auto lets gpu::choose_backend pick from the device.
  std::string backend = "auto";
};

/// Parses the shared options (and --preset when `presets_help` is not empty). Prints `--help`
/// (the usage, `about`, and `presets_help`) and exits 0, or exits 2 on a bad argument.
Options parse_args(int argc, char** argv, const std::string& about, const std::string& presets_help = {});

/// Runs `scene` on the chosen backend and draws it: windowed (drag orbits, wheel zooms, space pauses,
/// R resets, Esc quits) or, with --offscreen, `frames` PNGs out/<name>_NNNN.png. Returns the exit
/// code (0 ok, 1 failure, 3 diverged, 4 no Vulkan device / no display). Prints errors on stderr.
int run(const vkcloth::Scene& scene, const Options& options);

} // namespace samples
