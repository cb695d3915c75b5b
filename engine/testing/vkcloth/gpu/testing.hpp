// SPDX-License-Identifier: MIT
// Test-only knobs and hooks of the Vulkan backend: not part of the stable API. Tests, benchmarks
// and diagnostics include this header; applications have no reason to.
#pragma once

#include <cstddef>
#include <cstdint>
#include <functional>
#include <vector>

#include "vkcloth/gpu/context.hpp"
#include "vkcloth/gpu/gpu_solver.hpp"
#include "vkcloth/gpu/world.hpp"
#include "vkcloth/params.hpp"
#include "vkcloth/result.hpp"
#include "vkcloth/system.hpp"
#include "vkcloth/topology.hpp"

namespace vkcloth::gpu::testing {

/// Force code paths a test device would not take by itself. Defaults: the device's own choices.
struct SolverKnobs {
  /// Keep every bulk buffer in device-local memory and go through staging buffers for uploads
  /// and readbacks even when the device-local memory is host-visible (as on lavapipe or UMA).
  bool force_staging = false;
  /// Lower the per-buffer size limit below the device's maxStorageBufferRange (0: the device's).
  std::uint64_t max_storage_buffer_bytes = 0;
  /// Lower the workgroups per dispatch row below maxComputeWorkGroupCount[0] (0: the device's);
  /// larger systems then dispatch a second grid dimension.
  std::uint32_t max_workgroups_x = 0;
  /// Cloth grids: interior particles whose gather lists are all the same up to translation sum
  /// their springs from a compile-time stencil (specialisation constants) instead of the CSR
  /// lists; same terms in the same order, so the same bits. `true` keeps the CSR gather for every
  /// particle (comparison).
  bool csr_only = false;
};

/// GpuSolver::create with knobs.
Result<GpuSolver> create_solver(Context& context, std::shared_ptr<const ClothTopology> topology,
                                SimParams params, const GpuSolverOptions& options = {},
                                const SolverKnobs& knobs = {});
Result<GpuSolver> create_solver(Context& context, const ParticleSystem& system, SimParams params,
                                const GpuSolverOptions& options = {}, const SolverKnobs& knobs = {});
/// ClothWorld::create with knobs for every batch of the world.
Result<ClothWorld> create_world(Context& context, WorldOptions options, const SolverKnobs& knobs);

/// The solver's interleaved vertices (GpuSolverOptions::interleaved_vertices), 8 floats per
/// particle as on the device (position xyz, normal xyz, uv), read back (submit, wait, copy).
Result<std::vector<float>> read_vertices(GpuSolver& solver);

/// Compute pipelines made so far on `context`: one per shader and specialisation (grid stencil,
/// fused variant), shared by every solver and world batch of the Context.
std::size_t pipeline_count(const Context& context);

/// Called before every device memory allocation vkcloth makes on `context` (solvers, worlds,
/// renderers, offscreen targets); returning true makes that allocation fail with
/// VK_ERROR_OUT_OF_DEVICE_MEMORY without calling the driver. Lets tests walk every allocation of
/// an object's creation and check that the failure is reported and everything before it is
/// released. An empty function removes the hook (then an allocation costs one branch more).
void set_allocation_failure_hook(Context& context, std::function<bool()> hook);

} // namespace vkcloth::gpu::testing
