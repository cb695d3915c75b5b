// SPDX-License-Identifier: MIT
// What the cloth figures (cloth.cpp) and the contact figures (contact.cpp) share: a finished run,
// the offscreen drawing set-up, and the labelled image grid drawn from the runs.
#pragma once

#include <chrono>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include <glm/vec3.hpp>

#include "figures.hpp"
#include "vkcloth/gpu/gpu_solver.hpp"
#include "vkcloth/render/camera.hpp"
#include "vkcloth/render/image.hpp"
#include "vkcloth/render/offscreen.hpp"
#include "vkcloth/scene.hpp"

namespace vkcloth::figures {

/// A finished simulation: the final state and (when drawing is possible) a GpuSolver holding it.
struct Run {
  Scene scene;
  ParticleSystem drawn; ///< the system the drawing solver was created from
  std::vector<glm::dvec3> initial, pos;
  std::string diverged; ///< the error message when the run blew up (the state is the last good one)
  std::optional<gpu::GpuSolver> gpu;
};

/// The Vulkan context and offscreen target the pictures are drawn with.
struct Drawing {
  std::optional<gpu::Context> ctx;
  std::string unavailable; ///< why nothing is drawn (no device)
  std::uint32_t w = 400, h = 300;
  std::optional<render::OffscreenTarget> target;
};

/// Opens the context and target (240 x 180 panels with --quick, else 400 x 300). Without a Vulkan
/// device on the CPU backend nothing is drawn (d.ctx empty, d.unavailable says why; stderr names the
/// figure `group`) and the numbers are computed all the same; on the Vulkan backend that is an error.
Result<void> open_drawing(const Gallery& G, Drawing& d, std::string_view group);

/// A GpuSolver holding run.pos, every particle pinned, stepped once so that its normals are those
/// of run.pos; it draws run.scene.params' colliders (set them to where they ended before calling).
Result<gpu::GpuSolver> display_solver(gpu::Context& ctx, Run& run);

std::vector<glm::dvec3> to_d(std::span<const glm::vec3> v);

/// Runs `scene` for `steps` on "cpu" (CpuSolver<float>) or "vulkan" (a GpuSolver on d.ctx) and,
/// when a device is there, makes the display solver of the final state.
Result<Run> simulate_cloth(Drawing& d, Scene scene, std::uint64_t steps, const std::string& backend);

/// Pulls the camera in until the 8 corners of `b` just fit the view (with a small margin).
render::Camera tighten(render::Camera c, const render::Bounds& b, float aspect);
/// One camera for all panels of a figure: framed tightly on the union of their final states and
/// (with `with_spheres`) their spheres.
render::Camera frame(const std::vector<const Run*>& runs, float aspect, glm::vec3 from,
                     bool with_spheres = true);

Result<render::Image> draw(Drawing& d, Run& run, const render::Camera& cam);

/// Renders the runs as one labelled grid (when a device is there) and adds it to the gallery, seen
/// from `from` (framed by frame()) or with the camera `cam`; `columns` panels per row (0: one row).
Result<void> grid_figure(Gallery& G, Drawing& d, std::vector<Run>& runs,
                         const std::vector<std::string>& labels, const std::string& file,
                         const std::string& section, const std::string& title, const std::string& caption,
                         glm::vec3 from = {0.9f, -1.6f, 1.0f}, bool with_spheres = true,
                         std::size_t columns = 0);
Result<void> grid_figure(Gallery& G, Drawing& d, std::vector<Run>& runs,
                         const std::vector<std::string>& labels, const std::string& file,
                         const std::string& section, const std::string& title, const std::string& caption,
                         const render::Camera& cam, std::size_t columns = 0);

/// Height of the lowest particle (m).
double min_z(const Run& r);
/// Largest structural strain (|x_b - x_a| - L0) / L0 of the final state (vkcloth/measure.hpp).
double max_strain(const Run& r);

/// Prints "figures: <group> <what> (<seconds since construction> s)" to stderr, one call per figure.
class Progress {
public:
  explicit Progress(std::string group) : group_(std::move(group)) {}
  void operator()(std::string_view what) const;

private:
  std::string group_;
  std::chrono::steady_clock::time_point start_ = std::chrono::steady_clock::now();
};

} // namespace vkcloth::figures
