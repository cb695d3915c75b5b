// SPDX-License-Identifier: MIT
// For the chain samples: run the CPU reference solver and plot the masses' height and the
// energies over time as SVG (vkcloth_plot), next to the frames.
#pragma once

#include <filesystem>

#include "vkcloth/scene.hpp"

namespace samples {

/// Simulates `scene` on CpuSolver<double> for `seconds`, writes <out>/<name>_position.svg (z of
/// every free mass) and <out>/<name>_energy.svg (kinetic, gravitational, spring, total). Returns
/// false (after printing why) on an error.
bool plot_chain(const vkcloth::Scene& scene, double seconds, const std::filesystem::path& out);

} // namespace samples
