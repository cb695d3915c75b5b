// SPDX-License-Identifier: MIT
// A solver pass: one feature of the step on Vulkan (the integrator's update, the tethers, Provot's
// sweeps, the fast projection, the contacts after a move, self-collision, the interleaved
// vertices). A pass owns its pipelines (its shaders and their binding table: pipelines.hpp
// ShaderSource, BindingTable), the buffers and descriptor sets only it uses, and records its own
// dispatches, each after the barrier that orders it (barriers.hpp). The batch (solver_batch.hpp)
// owns the state every pass reads and writes (positions, velocities, forces, normals, topology,
// colliders, instance parameters, flags: the state set, passes/state_set.hpp) and runs its passes
// in the order passes.cpp lists them. docs/architecture.md "Adding a pass" walks through one.
#pragma once

#include <cstdint>
#include <memory>
#include <vector>

#include "internal/resources.hpp"
#include "kernel/layout/vkcloth_shared.h"

namespace vkcloth::gpu {

class SolverBatch;

/// One substep (or the end of a recording) as its passes see it.
struct PassFrame {
  VkCommandBuffer cmd = VK_NULL_HANDLE;
  std::uint32_t read = 0; // positions[read]: the substep's input; positions[read ^ 1]: its output
  shared::PushConstants* pc = nullptr; // the common fields (count, grid, step); a pass may set `stage`
  bool first = false;                  // the recording's first dispatch: before_steps() ordered it already
  bool last = false;                   // the recording's last substep (the one whose forces are observed)
};

class Pass {
public:
  enum class When {
    substep,      ///< every substep, in list order
    recording_end ///< once, after the recording's last substep
  };
  virtual ~Pass() = default;
  Pass() = default;
  Pass(const Pass&) = delete;
  Pass& operator=(const Pass&) = delete;

  virtual const char* name() const = 0;
  virtual When when() const { return When::substep; }
  /// Whether the pass runs with the batch's current parameters.
  virtual bool active(const SolverBatch& batch) const = 0;
  /// Makes what the current parameters need (pipelines, buffers, descriptor sets): at the batch's
  /// creation and after each set_params; cheap when nothing is new. Work already recorded may
  /// still run: a pass never rewrites a set that work may use (it waits for it first, or makes new).
  virtual Result<void> prepare(SolverBatch& batch) = 0;
  /// The batch replaced a state buffer (more colliders, the tethers, new mesh colliders): rewrite
  /// the sets that hold it. The batch waited for the recorded work first.
  virtual Result<void> write_sets(const SolverBatch&) { return {}; }
  /// New instance parameters: into the pass's own parameter buffers, by vkCmdUpdateBuffer into `cmd`
  /// (after the batch's before_host_edit barrier), or straight into mapped memory when `cmd` is
  /// VK_NULL_HANDLE (at creation: nothing recorded yet).
  virtual void write_params(const SolverBatch&, VkCommandBuffer /*cmd*/) {}
  /// Records the pass; returns the number of dispatches recorded.
  virtual std::uint32_t record(const SolverBatch& batch, PassFrame& frame) = 0;
};

/// The solver's passes, in the order a substep runs them (passes.cpp: the one list).
std::vector<std::unique_ptr<Pass>> make_solver_passes();

} // namespace vkcloth::gpu
