// SPDX-License-Identifier: MIT
// Draws a GpuSolver's cloth (or chain) and its colliders with Vulkan graphics, straight from the
// solver's buffers: positions[current], normals and uvs are bound as vertex buffers (vec4, stride
// 16); nothing goes through the CPU. Each collider is drawn where it is at record time (its pose
// is pushed with its draw), so a moving collider moves with the cloth. (A CPU solver's state is drawn the
// same way from HostClothBuffers, host_buffers.hpp.) It records into the caller's command buffer, inside the
// caller's render pass (a VkRenderPass subpass with one colour and one depth attachment), so an
// engine can embed it, or ignore it and bind the same buffers itself.
//
// The cloth is any ClothTopology surface (a grid or a mesh: its triangles, boundaries and holes as
// they are) drawn two-sided (no culling; the back face tinted); a chain is masses and springs.
//
// Synchronisation (the caller's, once per frame): after GpuSolver::record_steps() and BEFORE the
// render pass, call
//   solver.record_barrier_to(cmd, VK_PIPELINE_STAGE_VERTEX_INPUT_BIT, VK_ACCESS_VERTEX_ATTRIBUTE_READ_BIT);
// so the compute writes of positions and normals are visible to the vertex fetch. The next
// record_steps() starts with a barrier from ALL_COMMANDS, which orders these vertex reads before
// the next compute writes (write-after-read).
//
// Thread safety: none; one thread records. create() submits one upload to the Context's queue
// (texture), so it must not race other submissions on that queue.
#pragma once

#include <cstdint>
#include <memory>
#include <optional>
#include <span>

#include <glm/vec3.hpp>
#include <vulkan/vulkan_core.h>

#include "vkcloth/gpu/context.hpp"
#include "vkcloth/gpu/gpu_solver.hpp"
#include "vkcloth/mesh.hpp"
#include "vkcloth/params.hpp"
#include "vkcloth/render/camera.hpp"
#include "vkcloth/render/image.hpp"
#include "vkcloth/result.hpp"
#include "vkcloth/system.hpp"
#include "vkcloth/topology.hpp"

namespace vkcloth::render {

struct RendererOptions {
  /// The render pass and subpass the pipelines are used in (one colour + one depth attachment).
  VkRenderPass render_pass = VK_NULL_HANDLE;
  std::uint32_t subpass = 0;
  VkSampleCountFlagBits samples = VK_SAMPLE_COUNT_1_BIT;
  /// The cloth's texture; empty (0 x 0): `encoded_texture`, else the built-in fabric
  /// (default_fabric_texture()).
  Image texture;
  /// The cloth's texture as a file's bytes (PNG / JPEG: a mesh's vkcloth::MeshTexture, e.g.
  /// Scene::texture), decoded by create() with decode_image(); corrupt bytes fail create() with
  /// ErrorCode::io naming MeshTexture::source. Setting both this and `texture` is
  /// ErrorCode::invalid_argument.
  std::optional<MeshTexture> encoded_texture;
  /// Where the floor plane is drawn (a square of this half-size around the scene's bounds
  /// centre projected onto the plane); 0: from the scene's bounds.
  float floor_half_size = 0.0f;
  /// Radius of the spheres drawn at a chain's masses; 0: from the spring rest lengths.
  float mass_radius = 0.0f;
};

/// Colours the renderer uses (linear RGB), public so tests and hosts can reason about them.
struct Palette {
  glm::vec3 background{0.62f, 0.72f, 0.84f}; ///< clear colour suggested to callers
  glm::vec3 sphere{0.85f, 0.25f, 0.18f};     ///< sphere colliders: brick red
  glm::vec3 capsule{0.18f, 0.60f, 0.48f};    ///< capsule colliders: teal
  glm::vec3 box{0.88f, 0.62f, 0.16f};        ///< box colliders: ochre
  glm::vec3 mesh{0.52f, 0.36f, 0.78f};       ///< mesh colliders: violet
  glm::vec3 floor{0.80f, 0.80f, 0.74f};      ///< floor checker: light cells (dark = 0.55x)
  glm::vec3 back_tint{0.55f, 0.62f, 0.95f};  ///< multiplies the texture on the cloth's back side
  glm::vec3 chain{0.20f, 0.20f, 0.22f};      ///< chain springs (lines) and masses
  glm::vec3 light_dir{0.35f, -0.45f, 0.82f}; ///< towards the light (normalised on use)
  float ambient = 0.35f;
};

class ClothRenderer {
public:
  /// Builds the pipelines for `options.render_pass`, the index buffer (the topology's triangles,
  /// or a chain's springs as lines), the collider meshes (from solver.params().colliders: each
  /// shape once, in its own frame; a mesh collider's triangles with face normals) and the texture
  /// (decoded first when `options.encoded_texture` is set). `topology` must be the solver's
  /// (solver.topology()). The Context's queue family must support graphics
  /// (ContextOptions::require_graphics): ErrorCode::unsupported otherwise.
  static Result<ClothRenderer> create(gpu::Context& context, const gpu::GpuSolver& solver,
                                      const ClothTopology& topology, RendererOptions options);
  /// The same for a ClothWorld instance: `params` gives the colliders to draw (world.params(id)),
  /// `topology` its topology (world.topology(id)).
  static Result<ClothRenderer> create(gpu::Context& context, const SimParams& params,
                                      const ClothTopology& topology, RendererOptions options);

  ClothRenderer(ClothRenderer&&) noexcept;
  ClothRenderer& operator=(ClothRenderer&&) noexcept;
  ClothRenderer(const ClothRenderer&) = delete;
  ClothRenderer& operator=(const ClothRenderer&) = delete;
  /// Command buffers that recorded draws must have finished executing.
  ~ClothRenderer();

  /// Records the draws (colliders, then the cloth or chain) inside the caller's render pass,
  /// with viewport and scissor set to `extent`. The solver's barrier (see the header comment)
  /// must already be recorded. The colliders are drawn at solver.params().colliders, their pose
  /// now (after the steps recorded so far). The renderer draws the colliders create() saw: one
  /// whose type (or mesh) at its index is no longer that, or that is no longer in the list, is
  /// not drawn; one added since is not either (create a renderer for the new list).
  void record_draw(VkCommandBuffer cmd, const gpu::GpuSolver& solver, const Camera& camera,
                   VkExtent2D extent) const;
  /// The same from an instance's buffers (ClothWorld::buffers(id), GpuSolver::buffers(),
  /// HostClothBuffers::upload()): query them after the last record_steps() (the current positions
  /// buffer alternates). The colliders are drawn at the poses of the last set_colliders() (at
  /// first, those create() was given).
  void record_draw(VkCommandBuffer cmd, const gpu::InstanceBuffers& buffers, const Camera& camera,
                   VkExtent2D extent) const;
  /// The colliders' poses for the next record_draw(cmd, buffers, ...) recordings: call it every
  /// frame with the solver's current colliders (world.params(id)->colliders,
  /// CpuSolver::params().colliders) when they move. The poses go into each recording's push
  /// constants, so command buffers already recorded (frames in flight) keep theirs. `colliders`
  /// must be the create()-time list re-posed: the same count, each of the same type (a mesh
  /// collider with the same ColliderMesh); sizes may change (radius, capsule ends,
  /// half_extents). ErrorCode::invalid_argument naming the index otherwise, nothing changed.
  Result<void> set_colliders(std::span<const Collider> colliders);

  const Palette& palette() const;
  /// True when the topology has a surface (a cloth is drawn); false: masses and springs.
  bool draws_cloth() const;

  struct Impl; ///< internal (engine/src/render)

private:
  explicit ClothRenderer(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
};

} // namespace vkcloth::render
