// SPDX-License-Identifier: MIT
// The simulation that `vkcloth render`, `view` and the samples draw, on either backend
// (gpu/backend_choice.hpp): the GpuSolver, drawn straight from its buffers, or a CpuWorld of one
// cloth (a CpuSolver<float>: the CPU reference, bit for bit the GPU's explicit integrators on
// lavapipe), whose positions and normals are uploaded into render::HostClothBuffers for each frame.
// Their callers see one object.
//
// Host code shared by the tools and the samples (not installed); it calls no Vulkan function
// itself, only the engine's.
#pragma once

#include <cstdint>
#include <memory>
#include <optional>
#include <string_view>
#include <vector>

#include <glm/vec3.hpp>

#include "vkcloth/cpu_solver.hpp"
#include "vkcloth/cpu_world.hpp"
#include "vkcloth/gpu/backend_choice.hpp"
#include "vkcloth/gpu/context.hpp"
#include "vkcloth/gpu/gpu_solver.hpp"
#include "vkcloth/render/camera.hpp"
#include "vkcloth/render/cloth_renderer.hpp"
#include "vkcloth/render/host_buffers.hpp"
#include "vkcloth/render/image.hpp"
#include "vkcloth/render/offscreen.hpp"
#include "vkcloth/result.hpp"
#include "vkcloth/system.hpp"

namespace vkcloth::host {

/// `--backend` of the drawing commands: "auto" (nullopt: choose_backend on the Context), "cpu",
/// "vulkan". Anything else: ErrorCode::invalid_argument naming the three.
Result<std::optional<gpu::Backend>> parse_backend(std::string_view name);
/// `requested` when set (the reason says it was asked for), else choose_backend(context).
gpu::BackendChoice resolve_backend(std::optional<gpu::Backend> requested, const gpu::Context& context);

/// A particle held where the mouse is (`vkcloth view`): its position, and zero velocity, are set
/// before each frame's steps; it moves freely during them.
struct HeldParticle {
  std::uint32_t index = 0;
  glm::vec3 position{0.0f};
};

class DrawnCloth {
public:
  /// A solver of `system` with `params` on `backend`; the CPU one with HostClothBuffers of two
  /// slots on `context` (one per frame in flight).
  static Result<DrawnCloth> create(gpu::Backend backend, gpu::Context& context, const ParticleSystem& system,
                                   const SimParams& params);

  gpu::Backend backend() const { return cpu_ ? gpu::Backend::cpu : gpu::Backend::vulkan; }

  /// One frame of a window: [the held particle], `steps` steps, and what the draws in `cmd`
  /// need, then the buffers to draw. Vulkan: all recorded into `cmd`, ending with THE compute ->
  /// vertex barrier. CPU: the steps run now, on the host, and the state is uploaded into slot
  /// `slot` (the frame that last drew from that slot must have finished); nothing is recorded.
  /// A CPU divergence is returned here; the GPU's by check_divergence(). Draw the colliders where
  /// the steps left them: renderer.set_colliders(params().colliders) before record_draw.
  Result<gpu::InstanceBuffers> record_frame(VkCommandBuffer cmd, std::uint32_t steps, std::uint32_t slot,
                                            const std::optional<HeldParticle>& held = {});
  /// Offscreen: `steps` steps, then the frame drawn, read back (one submission on the GPU); the
  /// colliders where the steps left them (CPU: renderer.set_colliders(params().colliders)).
  Result<render::Image> render(render::OffscreenTarget& target, render::ClothRenderer& renderer,
                               const render::Camera& camera, std::uint32_t steps = 0);
  /// `steps` steps, waited for (no drawing).
  Result<void> simulate(std::uint64_t steps);
  /// Current positions (the GPU's read back: every submission must be complete).
  Result<std::vector<glm::vec3>> positions();
  /// The GPU's divergence flags after the caller's submissions completed; always fine on the CPU
  /// (its steps return the error).
  Result<void> check_divergence();
  /// Replaces the parameters from the next step (no submission must be pending on the GPU).
  Result<void> set_params(const SimParams& params);
  const SimParams& params() const;
  const std::shared_ptr<const ClothTopology>& topology() const;
  std::uint64_t step_index() const;
  double time() const;

private:
  DrawnCloth() = default;
  const CpuSolver<float>& cpu_solver() const { return *cpu_->solver(cpu_id_); }
  /// A CPU error without the world's "cloth instance 1: " (one cloth: the solver's message).
  Error cpu_error(const Error& e) const;

  gpu::Context* context_ = nullptr;
  std::optional<gpu::GpuSolver> gpu_;
  std::optional<CpuWorld> cpu_; // one instance, cpu_id_
  InstanceId cpu_id_ = 0;
  std::optional<render::HostClothBuffers> host_;
};

} // namespace vkcloth::host
