// SPDX-License-Identifier: MIT
// Self-collision on Vulkan (internal to SolverBatch): CpuSolver::self_collide as compute passes of
// self_collision.comp, recorded after a substep's update and stretch control:
//
//   COUNT -> SCAN_BLOCKS -> SCAN_TOP -> SCAN_ADD -> SCATTER -> SORT -> iterations x [ COLLIDE -> APPLY ]
//
// or, when an instance keeps neighbour lists (a skin), before every pass:
//
//   iterations x [ CHECK -> COUNT -> ... -> SORT -> LIST -> COLLIDE -> APPLY ]
//
// where COUNT .. LIST do nothing unless CHECK found a particle that moved more than half the skin.
// An instance whose vbd takes self-contact as an energy has no passes after the step: vbd's sweeps
// record CHECK .. LIST after their first guesses and CONTACT before each sweep (record_sweep_*).
// one barrier between consecutive passes (barriers::dispatch_to_dispatch). The spatial hash (one
// table per instance, kernel.hpp self_table_size buckets) is rebuilt every substep; the counts
// go back to zero as SCATTER hands out the slots, so no clearing pass is needed. In a batch whose
// shaders read through texel views (DeviceLayout), COLLIDE reads through its own set 1 of views
// (self_collision_texel), unless one would exceed maxTexelBufferElements (then the storage build).
#pragma once

#include <cstdint>
#include <memory>
#include <span>
#include <vector>

#include <glm/vec3.hpp>

#include "internal/pipelines.hpp"
#include "internal/resources.hpp"
#include "kernel/layout/self_collision_shared.h"
#include "vkcloth/params.hpp"

namespace vkcloth::gpu {

class SelfCollisionGpu {
public:
  /// For `instances` instances of `count` particles; `groups_max_x`: the device's
  /// maxComputeWorkGroupCount[0]; `access`: the batch's build (texel views or storage buffers).
  /// The caller uploads rest_positions() (xyz, w: kernel inverse_mass) and zeroes counts().
  static Result<std::unique_ptr<SelfCollisionGpu>> create(const std::shared_ptr<Context::Impl>& ctx,
                                                          std::uint32_t count, std::uint32_t instances,
                                                          std::uint32_t groups_max_x, bool allow_map,
                                                          BufferAccess access);
  SelfCollisionGpu(const SelfCollisionGpu&) = delete;
  SelfCollisionGpu& operator=(const SelfCollisionGpu&) = delete;

  /// (Re)writes the two descriptor sets (position parity), and the views of the texel build;
  /// call again when an input buffer changes.
  Result<void> write_sets(const OneSetInputs& in);
  Buffer& rest_positions() { return rest_; }
  Buffer& counts() { return counts_; }
  /// Where each particle was when its list was built: the caller fills it with NaN (never built),
  /// and zeroes stale().
  Buffer& built() { return built_; }
  Buffer& stale() { return stale_; }
  /// Whether some instance keeps neighbour lists (record_substep's pass sequence).
  void set_lists(bool lists) { lists_ = lists; }
  /// The per-instance parameters (host-visible; written by the caller at creation, then by
  /// vkCmdUpdateBuffer with the instance parameters).
  const Buffer& params() const { return params_; }
  /// Each instance's parameters as the shader takes them (as CpuSolver<float> converts them).
  static std::vector<shared::SelfParams> packed(std::span<const SimParams* const> params);
  /// Records one substep's self-collision on positions[read ^ 1] (the positions being written):
  /// `iterations`, the most any instance asks for. Returns the number of dispatches recorded.
  std::uint32_t record_substep(VkCommandBuffer cmd, std::uint32_t read, const shared::PushConstants& pc,
                               std::uint32_t iterations);
  /// vbd's sweeps, for the instances that take self-contact as an energy: the lists of the first
  /// guesses (CHECK .. LIST: built again when stale) before the sweeps, and each sweep's CONTACT
  /// (each particle's contact force and stiffness into ACC_POS, ACC_VEL, STAGE_VEL). They bind this
  /// pass's layout: the caller binds its own again. Return the number of dispatches recorded.
  std::uint32_t record_sweep_lists(VkCommandBuffer cmd, std::uint32_t read,
                                   const shared::PushConstants& pc) const;
  std::uint32_t record_sweep_contact(VkCommandBuffer cmd, std::uint32_t read,
                                     const shared::PushConstants& pc) const;

private:
  SelfCollisionGpu() = default;
  std::shared_ptr<Context::Impl> ctx_;
  std::uint32_t count_ = 0, instances_ = 0, table_ = 0, groups_max_x_ = 1;
  BufferAccess access_ = BufferAccess::storage_buffers; // the build that runs (never automatic)
  bool lists_ = false;
  Buffer params_, rest_, counts_, starts_, blocks_, keys_, sorted_, delta_, built_, listed_, list_, stale_;
  DescriptorPool pool_, texel_pool_;
  VkDescriptorSet sets_[2] = {}, texel_sets_[2] = {}; // [read]: set 0 and the texel build's set 1
  // The texel build's views: positions[0], positions[1] (the parity's POS_OUT), then velocities,
  // rest positions, bucket starts and the sorted table (VKCLOTH_SELF_TEXEL_* order from VEL on).
  BufferView pos_views_[2], vel_view_, rest_view_, starts_view_, sorted_view_;
  // The Context's (PipelineRegistry), shared by every batch.
  VkPipelineLayout layout_ = VK_NULL_HANDLE;
  static constexpr std::uint32_t kPasses = VKCLOTH_SELF_CONTACT + 1;
  VkPipeline passes_[kPasses] = {}; // [stage]: self_collision.comp specialised with its stage (SC_STAGE)

  Result<void> create_buffers(bool allow_map);
  void bind(VkCommandBuffer cmd, std::uint32_t read) const;
  void dispatch(VkCommandBuffer cmd, const shared::SelfPush& pc, std::uint64_t items) const;
  std::uint32_t record_build(VkCommandBuffer cmd, shared::SelfPush& pc, bool lists) const;
  shared::SelfPush begin_sweep_pass(VkCommandBuffer cmd, std::uint32_t read,
                                    const shared::PushConstants& pc) const;
  Result<void> create_sets();
  Result<void> write_texel_sets(const OneSetInputs& in);
};

} // namespace vkcloth::gpu
