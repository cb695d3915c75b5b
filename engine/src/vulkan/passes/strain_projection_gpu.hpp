// SPDX-License-Identifier: MIT
// Stretch control by fast projection on Vulkan (internal to SolverBatch): CpuSolver::project_strain
// as strain_project.comp, recorded after the tethers of a substep's stretch control. One workgroup
// per instance runs the whole projection (Newton iterations of a CG over the links); llvmpipe's cap
// on an invocation's loop iterations splits it into dispatches of at most `phases per dispatch`
// phases each, one barrier between them (barriers::implicit_pass), enough of them for the worst case
// (every Newton iteration, every CG iteration): indirect dispatches, whose group count the last
// instance to finish sets to zero (ProjArgsHead, reset by the host before the substep's first).
#pragma once

#include <cstdint>
#include <memory>
#include <span>
#include <vector>

#include "internal/pipelines.hpp"
#include "internal/resources.hpp"
#include "kernel/layout/strain_projection_shared.h"
#include "vkcloth/topology.hpp"

namespace vkcloth::gpu {

class StrainProjectionGpu {
public:
  /// For `instances` instances of `topology`'s particles and strain links. The caller uploads
  /// incidence_data() into incidence().
  static Result<std::unique_ptr<StrainProjectionGpu>> create(const std::shared_ptr<Context::Impl>& ctx,
                                                             const ClothTopology& topology,
                                                             std::uint32_t instances, bool allow_map);
  StrainProjectionGpu(const StrainProjectionGpu&) = delete;
  StrainProjectionGpu& operator=(const StrainProjectionGpu&) = delete;

  /// (Re)writes the two descriptor sets (position parity); call again when an input buffer changes.
  Result<void> write_sets(const OneSetInputs& in);
  Buffer& incidence() { return incidence_; }
  /// The topology's strain_incidence_offsets, then its strain_incidence (the shader's layout).
  static std::vector<std::uint32_t> incidence_data(const ClothTopology& topology);
  /// Records one substep's projection on positions[read ^ 1] (the positions being written), for
  /// at most `newton` Newton iterations (the most any instance asks for). Returns the dispatches.
  std::uint32_t record_substep(VkCommandBuffer cmd, std::uint32_t read, const shared::PushConstants& pc,
                               std::uint32_t newton);

private:
  StrainProjectionGpu() = default;
  std::shared_ptr<Context::Impl> ctx_;
  std::uint32_t count_ = 0, links_ = 0, instances_ = 0, cg_cap_ = 0, phases_per_dispatch_ = 1;
  Buffer incidence_, link_state_, gathered_, state_, args_;
  std::vector<std::uint32_t> args_reset_; // ProjArgsHead (1, 1, instances, 0), then no instance counted
  DescriptorPool pool_;
  VkDescriptorSet sets_[2] = {};
  VkPipelineLayout layout_ = VK_NULL_HANDLE; // the Context's (PipelineRegistry)
  VkPipeline pass_ = VK_NULL_HANDLE;

  Result<void> create_buffers(std::uint64_t incidence_words, bool allow_map);
  Result<void> create_sets();
};

} // namespace vkcloth::gpu
