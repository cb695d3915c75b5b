// SPDX-License-Identifier: MIT
// An offscreen target for the renderer: a colour image (RGBA8) + depth, its render pass and
// framebuffer, and the readback of a frame to an Image. Used by `vkcloth render` and the tests.
#pragma once

#include <cstdint>
#include <functional>
#include <memory>

#include "vkcloth/gpu/context.hpp"
#include "vkcloth/gpu/gpu_solver.hpp"
#include "vkcloth/render/camera.hpp"
#include "vkcloth/render/cloth_renderer.hpp"
#include "vkcloth/render/image.hpp"
#include "vkcloth/result.hpp"

namespace vkcloth::render {

class OffscreenTarget {
public:
  /// A width x height target (each 1..4096). The Context's queue needs graphics support.
  static Result<OffscreenTarget> create(gpu::Context& context, std::uint32_t width, std::uint32_t height);

  OffscreenTarget(OffscreenTarget&&) noexcept;
  OffscreenTarget& operator=(OffscreenTarget&&) noexcept;
  OffscreenTarget(const OffscreenTarget&) = delete;
  OffscreenTarget& operator=(const OffscreenTarget&) = delete;
  ~OffscreenTarget();

  /// The render pass to create a ClothRenderer for (RendererOptions::render_pass).
  VkRenderPass render_pass() const;
  std::uint32_t width() const;
  std::uint32_t height() const;

  /// Records `steps` solver steps, the one compute -> vertex barrier, the render pass (cleared to
  /// the renderer's background) with the draws (the colliders where the steps leave them:
  /// ClothRenderer::record_draw(cmd, solver, ...)), and the copy to the readback buffer; submits,
  /// waits, checks the solver's divergence flags (ErrorCode::diverged), returns the frame.
  /// `before_steps`, when set, records the caller's own commands first (e.g. record_hold_particle).
  Result<Image> render(gpu::GpuSolver& solver, const ClothRenderer& renderer, const Camera& camera,
                       std::uint32_t steps = 0,
                       const std::function<void(VkCommandBuffer)>& before_steps = {});
  /// Draws `buffers` as they are (no steps, no barrier: e.g. HostClothBuffers::upload()'s, filled
  /// by the host before this call), with the colliders of the renderer's last set_colliders(),
  /// submits, waits, returns the frame.
  Result<Image> render(const gpu::InstanceBuffers& buffers, const ClothRenderer& renderer,
                       const Camera& camera);

  struct Impl; ///< internal (engine/src/render)

private:
  explicit OffscreenTarget(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
};

} // namespace vkcloth::render
