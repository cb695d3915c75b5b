// SPDX-License-Identifier: MIT
// Self-collision on Vulkan (internal to SolverBatch): CpuSolver::self_collide as compute passes of
// self_collision.comp, recorded after a substep's update and stretch control:
//
//   COUNT -> SCAN_BLOCKS -> SCAN_TOP -> SCAN_ADD -> SCATTER -> SORT -> iterations x [ COLLIDE -> APPLY ]
//
// one barrier between consecutive passes (barriers::dispatch_to_dispatch). The spatial hash (one
// table per instance, kernel.hpp self_table_size buckets) is rebuilt every substep; the counts
// go back to zero as SCATTER hands out the slots, so no clearing pass is needed.
#pragma once

#include <cstdint>
#include <memory>
#include <span>
#include <vector>

#include <glm/vec3.hpp>

#include "pipelines.hpp"
#include "resources.hpp"
#include "self_collision_shared.h"
#include "vkcloth/params.hpp"

namespace vkcloth::gpu {

class SelfCollisionGpu {
public:
  /// For `instances` instances of `count` particles; `groups_max_x`: the device's
  /// maxComputeWorkGroupCount[0]. The caller uploads rest_positions() (xyz, w: kernel inverse_mass)
  /// and zeroes counts().
  static Result<std::unique_ptr<SelfCollisionGpu>> create(const std::shared_ptr<Context::Impl>& ctx,
                                                          std::uint32_t count, std::uint32_t instances,
                                                          std::uint32_t groups_max_x, bool allow_map);
  SelfCollisionGpu(const SelfCollisionGpu&) = delete;
  SelfCollisionGpu& operator=(const SelfCollisionGpu&) = delete;

  /// (Re)writes the two descriptor sets (position parity); call again when an input buffer changes.
  Result<void> write_sets(const OneSetInputs& in);
  Buffer& rest_positions() { return rest_; }
  Buffer& counts() { return counts_; }
  /// The per-instance parameters (host-visible; written by the caller at creation, then by
  /// vkCmdUpdateBuffer with the instance parameters).
  const Buffer& params() const { return params_; }
  /// Each instance's parameters as the shader takes them (as CpuSolver<float> converts them).
  static std::vector<shared::SelfParams> packed(std::span<const SimParams* const> params);
  /// Records one substep's self-collision on positions[read ^ 1] (the positions being written):
  /// `iterations`, the most any instance asks for. Returns the number of dispatches recorded.
  std::uint32_t record_substep(VkCommandBuffer cmd, std::uint32_t read, shared::PushConstants pc,
                               std::uint32_t iterations);

private:
  SelfCollisionGpu() = default;
  std::shared_ptr<Context::Impl> ctx_;
  std::uint32_t count_ = 0, instances_ = 0, table_ = 0, groups_max_x_ = 1;
  Buffer params_, rest_, counts_, starts_, blocks_, keys_, sorted_, delta_;
  DescriptorPool pool_;
  VkDescriptorSet sets_[2] = {};
  // The Context's (PipelineRegistry), shared by every batch.
  VkPipelineLayout layout_ = VK_NULL_HANDLE;
  VkPipeline pass_ = VK_NULL_HANDLE;

  Result<void> create_buffers(bool allow_map);
  Result<void> create_sets();
};

} // namespace vkcloth::gpu
