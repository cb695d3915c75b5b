// SPDX-License-Identifier: MIT
// The implicit-Euler step on Vulkan (internal to GpuSolver): the CPU reference's linearised
// backward Euler + PCG (engine/src/core/implicit_euler.hpp) as compute passes, recorded without a
// CPU round trip per iteration. Per substep, either (per_iteration)
//
//   FORCE -> SYSTEM -> cg_max_iterations x [ MATVEC -> UPDATE -> DIRECTION ] -> FINISH
//
// where SYSTEM, MATVEC and UPDATE end with their reduction: the last workgroup to finish sums the
// partials (INIT, alpha, beta and the convergence test) and rewrites the indirect dispatch
// arguments of the CG passes (zero groups once converged, so the iterations left are empty
// dispatches): 3 dispatches per iteration, or (one_workgroup, small systems)
//
//   FORCE -> SYSTEM -> ceil(cg_max_iterations / K) x SOLVE -> FINISH
//
// where each SOLVE is one workgroup running up to K iterations (iteration_budget) and an empty
// one once converged; one barrier between consecutive passes (barriers::implicit_pass). Dot
// products: a fixed-shape tree per workgroup, then the partials in a fixed order (deterministic;
// not the CPU's sequential sum, hence results equal the CPU's to rounding, not bit for bit).
#pragma once

#include <cstdint>
#include <memory>
#include <span>

#include "internal/resources.hpp"
#include "vkcloth/params.hpp"
#include "kernel/layout/implicit_shared.h"
#include "kernel/layout/vkcloth_shared.h"

namespace vkcloth::gpu {

/// The solver's buffers the implicit passes share (same bindings as the main layout). The
/// implicit passes run batches of one instance (the CG reductions are per instance).
struct ImplicitInputs {
  VkBuffer pos[2], vel, force, normal, particle, offsets, edges, colliders, flags, instances, mesh_nodes,
      mesh_tris, mesh_cache;
};

class ImplicitGpu {
public:
  static Result<std::unique_ptr<ImplicitGpu>> create(const std::shared_ptr<Context::Impl>& ctx,
                                                     std::uint32_t count, std::uint64_t entries,
                                                     std::uint32_t groups_x, std::uint32_t groups_y,
                                                     std::uint32_t one_workgroup_budget, bool allow_map);
  /// CG iterations one workgroup may run in one dispatch for `count` particles of at most
  /// `max_degree` springs: about 30 000 loop iterations per invocation, half of llvmpipe's
  /// silent cap on one loop (65 535); 0 when even one iteration would not fit. 0 in create():
  /// the per-iteration passes instead.
  static std::uint32_t iteration_budget(std::uint32_t count, std::uint32_t max_degree);
  ImplicitGpu(const ImplicitGpu&) = delete;
  ImplicitGpu& operator=(const ImplicitGpu&) = delete;

  /// (Re)writes the two descriptor sets (position parity); call again when an input buffer changes.
  Result<void> write_sets(const ImplicitInputs& in);
  /// The FORCE and FINISH passes (the ones that meet colliders) for collider types `types`,
  /// specialised with `constants` (force_body.glsl's, SC_COLLIDER_TYPES = types); made once per
  /// types (passes/implicit_update.cpp prepare), before a substep with them is recorded.
  Result<void> ensure_collider_passes(std::uint32_t types, std::span<const std::uint32_t> constants);
  /// Records one substep reading positions[read], writing positions[read ^ 1]. `pc` is the main
  /// push-constant block (the substep's dt is in the InstanceParams); `types`: the batch's collider
  /// types (ensure_collider_passes made their FORCE and FINISH passes); `first`: no barrier needed
  /// before the first pass. Returns the number of dispatches recorded.
  std::uint32_t record_substep(VkCommandBuffer cmd, std::uint32_t read, const shared::PushConstants& pc,
                               const SimParams& params, std::uint32_t types, bool first);
  bool one_workgroup() const { return budget_ > 0; }
  /// The last completed solve (host-visible state; valid once the recorded work finished).
  SolveStats stats() const;

private:
  ImplicitGpu() = default;
  std::shared_ptr<Context::Impl> ctx_;
  std::uint32_t count_ = 0, groups_x_ = 1, groups_y_ = 1;
  std::uint32_t budget_ = 0; ///< CG iterations per SOLVE dispatch; 0: per-iteration passes
  Buffer vf_, ks_, block_inv_, x_, r_, z_, d_, q_, partials_, state_, args_;
  DescriptorPool pool_;
  VkDescriptorSet sets_[2] = {};
  // The Context's (PipelineRegistry), shared by every implicit batch.
  VkDescriptorSetLayout set_layout_ = VK_NULL_HANDLE;
  VkPipelineLayout layout_ = VK_NULL_HANDLE;
  // [mode]: implicit.comp specialised with it (SC_STAGE); FORCE and FINISH per collider types.
  VkPipeline passes_[VKCLOTH_IMPL_SOLVE + 1] = {};
  VkPipeline force_passes_[VKCLOTH_COLLIDER_ALL_TYPES + 1] = {};
  VkPipeline finish_passes_[VKCLOTH_COLLIDER_ALL_TYPES + 1] = {};

  Result<void> create_buffers(std::uint64_t entries, bool allow_map);
  Result<void> create_pipelines();
};

} // namespace vkcloth::gpu
