// SPDX-License-Identifier: MIT
// ClothWorld::Impl: the world's instances and the batches (SolverBatch) that step them. Internal
// to engine/src/vulkan; GpuSolver (a world of one instance) reaches its batch through it.
#pragma once

#include <map>
#include <memory>
#include <vector>

#include "internal/resources.hpp"
#include "solver_batch.hpp"
#include "vkcloth/gpu/testing.hpp"
#include "vkcloth/gpu/world.hpp"

namespace vkcloth::gpu {

// Instances are grouped into batches (SolverBatch, solver_batch.hpp) by topology, integrator
// family and substep count; each batch steps all its instances with one dispatch per pass.
// Adding, removing or moving an instance rebuilds its batch: new buffers, the surviving
// instances' state copied over on the GPU (positions, velocities, normals, forces).
struct ClothWorld::Impl {
  using Batch = SolverBatch;
  struct Instance {
    std::shared_ptr<const ClothTopology> topology;
    SimParams params;
    Batch* batch = nullptr;
    std::uint32_t slot = 0;
  };
  /// What instances must agree on to share a batch (and so its dispatches).
  struct BatchKey {
    const ClothTopology* topology = nullptr;
    int family = 0; // 0: explicit / semi-implicit Euler, 1: RK4, 2: implicit Euler (one instance per batch),
                    // 3: vbd
    std::uint32_t substeps = 1;
    std::uint32_t iterations = 0; // vbd: its sweeps (the batch's dispatches)
    InstanceId only = 0;          // implicit Euler: the instance (its CG reductions are per batch)
    auto operator<=>(const BatchKey&) const = default;
  };
  struct BatchEntry {
    std::unique_ptr<Batch> solver;
    std::vector<InstanceId> members; // slot order
  };

  std::shared_ptr<Context::Impl> ctx; // first: outlives everything below
  WorldOptions options;
  testing::SolverKnobs knobs;
  CommandContext commands; // batch uploads, readbacks and rebuilds (copies), simulate()
  QueryPool queries;       // two timestamps around each simulate() submission (when supported)
  double last_ms = -1.0;   // GPU time of the last simulate(); negative without timestamps
  std::map<InstanceId, Instance> instances; // ordered by id
  std::map<BatchKey, BatchEntry> batches;   // destroyed before `commands`, which they borrow
  InstanceId next = 1;
  std::uint64_t dispatches = 0; // recorded by record_steps(), all batches

  static Result<std::unique_ptr<Impl>> create(const std::shared_ptr<Context::Impl>& ctx, WorldOptions options,
                                              const testing::SolverKnobs& knobs);
  static BatchKey key_of(const Instance& inst, InstanceId id);
  Result<Instance*> find(InstanceId id);

  /// Rebuilds the batch `key` with `members` (slot order; may be empty: the batch goes away).
  /// Members already in a batch keep their state (copied on the GPU); `fresh` ones start from
  /// their InitialState. On failure nothing changes.
  Result<void> rebuild(const BatchKey& key, const std::vector<InstanceId>& members,
                       const std::map<InstanceId, const InitialState*>& fresh);
  void record_steps(VkCommandBuffer cmd, std::uint32_t steps);
  /// One half of a queue-family transfer of every batch's drawn buffers (QueueTransfer).
  void record_queue_transfer(VkCommandBuffer cmd, const QueueTransfer& transfer, bool release) const;
  /// Records, submits and waits for `steps` steps, timed; then reads every batch's flags.
  Result<void> simulate(std::uint64_t steps, std::uint32_t steps_per_submit);
  /// Reads every batch's flags after the host's own submissions completed.
  Result<void> check_divergence();
  /// Reads every batch's flags (their work must be complete and visible to the host).
  Result<void> divergence();
};

} // namespace vkcloth::gpu
