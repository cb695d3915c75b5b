// SPDX-License-Identifier: MIT
// Per-particle buffers for ClothRenderer filled by the host: a simulation that runs on the CPU
// (CpuSolver) drawn with the same renderer as the GpuSolver. upload() writes positions and normals
// into host-visible, host-coherent vertex buffers and returns them as gpu::InstanceBuffers, the
// layout of the GPU solver's (vec4, stride 16; uvs and triangle indices written once).
//
// Synchronisation: none to record. Host writes to host-coherent memory made before vkQueueSubmit
// are visible to every command of that submission (the submission's implicit host-write
// ordering), so the draws read this frame's values. What the caller must do: never upload into a
// slot that a submitted, unfinished command buffer draws from; with one frame in flight any slot
// is free after waiting for the last frame; with k frames in flight use k slots, slot = frame % k.
//
// Thread safety: none; one thread uploads and records.
#pragma once

#include <cstdint>
#include <memory>
#include <span>

#include <glm/vec3.hpp>

#include "vkcloth/gpu/context.hpp"
#include "vkcloth/gpu/gpu_solver.hpp"
#include "vkcloth/result.hpp"
#include "vkcloth/topology.hpp"

namespace vkcloth::render {

class HostClothBuffers {
public:
  /// `slots` sets of positions + normals (1..8) for `topology`'s particles, its uvs and triangles.
  static Result<HostClothBuffers> create(gpu::Context& context, const ClothTopology& topology,
                                         std::uint32_t slots = 2);

  HostClothBuffers(HostClothBuffers&&) noexcept;
  HostClothBuffers& operator=(HostClothBuffers&&) noexcept;
  HostClothBuffers(const HostClothBuffers&) = delete;
  HostClothBuffers& operator=(const HostClothBuffers&) = delete;
  /// Command buffers that drew from these buffers must have finished executing.
  ~HostClothBuffers();

  /// Writes `positions` (w = 1) and `normals` (w = 0), one per particle each, into slot
  /// `slot % slots()` and returns its buffers for ClothRenderer::record_draw.
  /// ErrorCode::invalid_argument (nothing written) when a span's size is not the particle count.
  Result<gpu::InstanceBuffers> upload(std::uint32_t slot, std::span<const glm::vec3> positions,
                                      std::span<const glm::vec3> normals);
  std::uint32_t slots() const;
  std::uint32_t particle_count() const;

  struct Impl; ///< internal (engine/src/render)

private:
  explicit HostClothBuffers(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
};

} // namespace vkcloth::render
