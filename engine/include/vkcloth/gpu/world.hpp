// SPDX-License-Identifier: MIT
// Many cloths on one Context: a shared, immutable topology (std::shared_ptr<const ClothTopology>,
// prepared once from a ParticleSystem: particles' rest state, masses, pins, gather lists, grid
// stencil, triangles) and instances with their own state (positions, velocities) and parameters
// (SimParams: integrator, dt, gravity, damping, wind, colliders, ...).
//
// Batching: instances that share a topology (the same shared_ptr), an integrator family
// (explicit and semi-implicit Euler together; RK4) and a substep count form one batch, stepped
// with ONE dispatch per pass for all of them (instance = gl_WorkGroupID.z): one fused dispatch
// per Euler step, two per two-pass Euler step, 8 per RK4 step, whatever the number of instances.
// Their state lives in shared buffers, instance after instance (InstanceBuffers::offset), the
// topology buffers once per batch; each instance has its own parameters (dt, gravity, damping,
// wind, colliders, contact mode, divergence limit) and divergence flags. Same shaders, same bits
// as a standalone GpuSolver and, on lavapipe, as CpuSolver<float> (tested). Implicit-Euler
// instances are batches of one (their CG reductions are per instance).
// add() / remove() / an integrator change in set_params() rebuild the batch concerned: new
// buffers and descriptor sets; the other instances' state is copied on the GPU (one submission,
// waited for, which also waits for the earlier work on the Context's queue). Other set_params()
// changes are recorded into the next recording's command buffer: per frame, frames in flight. No call
// re-creates a pipeline: every pipeline (per shader and specialisation: grid stencil, fused
// variants) is made once per Context, when a batch first needs it, and shared by all batches.
//
// Thread safety: none; one thread drives a world (as a GpuSolver).
//
// vkcloth::CpuWorld (cpu_world.hpp) has the same add / remove / set_params / simulate / positions
// members on the CPU solver: a host that only steps and reads back switches by changing the type.
#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>
#include <optional>
#include <span>
#include <vector>

#include <glm/vec3.hpp>
#include <vulkan/vulkan_core.h>

#include "vkcloth/gpu/context.hpp"
#include "vkcloth/gpu/gpu_solver.hpp"
#include "vkcloth/params.hpp"
#include "vkcloth/result.hpp"
#include "vkcloth/system.hpp"
#include "vkcloth/topology.hpp"
#include "vkcloth/world_types.hpp"

namespace vkcloth::gpu {

/// Two counter-clockwise triangles (a, b, d), (a, d, c) per grid quad, particle (i, j) = j*nx + i:
/// a grid topology's ClothTopology::triangles(), the index list ClothRenderer draws; upload it as
/// a VK_INDEX_TYPE_UINT32 index buffer.
std::vector<std::uint32_t> grid_triangle_indices(std::uint32_t nx, std::uint32_t ny);

/// The restart index of grid_triangle_strip_indices (VK_INDEX_TYPE_UINT32's).
inline constexpr std::uint32_t strip_restart_index = 0xFFFFFFFFu;

/// The same triangles as grid_triangle_indices, with the same winding, as one triangle strip per
/// row of quads separated by strip_restart_index: (ny - 1) (2 nx + 1) - 1 indices instead of
/// 6 (nx - 1)(ny - 1). Draw with VK_PRIMITIVE_TOPOLOGY_TRIANGLE_STRIP and primitiveRestartEnable.
/// For a host whose pipeline uses strips; upload it as its own index buffer (InstanceBuffers::
/// indices is the list).
std::vector<std::uint32_t> grid_triangle_strip_indices(std::uint32_t nx, std::uint32_t ny);

struct WorldOptions {
  /// Options of every instance's solver (fused, staging, sharing_queue_families, ...).
  GpuSolverOptions solver;
};

/// The backend-neutral names (world_types.hpp), also under gpu:: as before.
using vkcloth::InitialState;
using vkcloth::InstanceId;

class ClothWorld {
public:
  /// An empty world on `context` (borrowed: the world keeps its internals alive).
  static Result<ClothWorld> create(Context& context, WorldOptions options = {});

  ClothWorld(ClothWorld&&) noexcept;
  ClothWorld& operator=(ClothWorld&&) noexcept;
  ClothWorld(const ClothWorld&) = delete;
  ClothWorld& operator=(const ClothWorld&) = delete;
  /// Frees every instance; work the caller recorded must have finished executing.
  ~ClothWorld();

  /// Adds a cloth of `topology` (ClothTopology::create; instances of the same pointer share a
  /// batch) with `params`; validated as GpuSolver::create (errors name the parameter). Takes
  /// effect from the next recording. Rebuilding the batch first waits for every earlier
  /// submission on the Context's queue (recorded work submitted elsewhere: wait for it yourself);
  /// command buffers recorded but not yet submitted must not be submitted after it.
  Result<InstanceId> add(std::shared_ptr<const ClothTopology> topology, SimParams params,
                         const InitialState& initial = {});
  /// Removes an instance (its batch's buffers are replaced or freed now, after waiting for every
  /// earlier submission on the Context's queue, as add()); the others keep their state.
  /// ErrorCode::invalid_argument for an unknown id.
  Result<void> remove(InstanceId id);
  /// New parameters from the next recorded step. The values travel in that recording's command
  /// buffer (vkCmdUpdateBuffer), so changing them every frame with frames in flight is race-free.
  /// An integrator family or substep change moves the instance to another batch (a rebuild, see
  /// the header note), as do more colliders than the batch has room for or the first tethers:
  /// those first wait for every earlier submission on the Context's queue. No pipeline is
  /// re-created.
  Result<void> set_params(InstanceId id, SimParams params);
  /// set_params(id, step.applied_to(params(id))): the per-frame fields (dt, gravity, wind, colliders).
  Result<void> set_step_params(InstanceId id, const StepParams& step);
  /// The per-frame pose of ONE animated collider, without resending its shape and friction:
  /// set_params(id, with_collider_pose(params(id), collider, pose)), `collider` its index in
  /// params(id).colliders (ColliderPose says what the pose sets). The same rule as set_step_params
  /// (from the next step; frames in flight allowed); the errors name an unknown id, an index past
  /// the list or the pose's field, and leave the parameters as they were.
  Result<void> set_collider_pose(InstanceId id, std::size_t collider, const ColliderPose& pose);
  /// The host's per-frame targets of the instance's particles for the next recorded step
  /// (PinTarget; recorded with it by vkCmdUpdateBuffer, substep by substep: frames in flight
  /// allowed). The errors (targets unchanged) name an unknown id or the target (CpuSolver::
  /// set_pin_targets). The first targets of a batch make its targets buffer, which first waits for
  /// every earlier submission on the Context's queue.
  Result<void> set_pin_targets(InstanceId id, std::span<const PinTarget> targets);
  /// Moves the instance's whole cloth by `jump` at the start of the next recorded step, unfelt
  /// (CpuSolver::teleport); the first of a batch makes its frames buffer (a wait, as above).
  Result<void> teleport(InstanceId id, const RigidJump& jump);
  Result<SimParams> params(InstanceId id) const;

  /// Records one step of every instance into the host's command buffer (see GpuSolver::record_steps
  /// for the state the buffers are left in: compute writes not yet visible to later stages).
  void record_step(VkCommandBuffer cmd);
  /// Records `steps` steps of every instance (batch by batch; one dispatch per pass and batch).
  void record_steps(VkCommandBuffer cmd, std::uint32_t steps);
  /// One barrier making every instance's last writes visible to `dst_stage` / `dst_access`.
  void record_barrier_to(VkCommandBuffer cmd, VkPipelineStageFlags dst_stage, VkAccessFlags dst_access) const;
  /// The two halves of a queue-family ownership transfer of every instance's drawn buffers
  /// (current positions, normals, uvs; QueueTransfer in gpu_solver.hpp).
  void record_release(VkCommandBuffer cmd, const QueueTransfer& transfer) const;
  void record_acquire(VkCommandBuffer cmd, const QueueTransfer& transfer) const;

  /// Records, submits and waits for `steps` steps of every instance (on the Context's queue),
  /// `steps_per_submit` per submission; then checks each instance's divergence flags
  /// (ErrorCode::diverged names the instance and the step).
  Result<void> simulate(std::uint64_t steps, std::uint32_t steps_per_submit = 64);
  /// Reads the divergence flags of every instance after the host's own submissions completed.
  Result<void> check_divergence();

  /// Readbacks of one instance (submit, wait, copy).
  Result<std::vector<glm::vec3>> positions(InstanceId id);
  Result<std::vector<glm::vec3>> velocities(InstanceId id);
  Result<std::vector<glm::vec3>> normals(InstanceId id);
  /// Buffers for drawing (render::ClothRenderer::record_draw, or the host's own pipeline): valid
  /// until the next add(), remove() or set_params(); `positions` alternates with every step, so
  /// query them after the last record_steps().
  Result<InstanceBuffers> buffers(InstanceId id) const;
  /// Completed steps of the instance since its add() (the bad one when it diverged; 0 for an
  /// unknown id). Recorded steps count as completed, as GpuSolver::step_index().
  std::uint64_t step_index(InstanceId id) const;
  /// Batches (one dispatch per pass each) and the dispatches record_steps() recorded so far.
  std::size_t batch_count() const;
  std::uint64_t dispatches_recorded() const;
  /// The instance's shared topology (null for an unknown id).
  std::shared_ptr<const ClothTopology> topology(InstanceId id) const;

  /// Live instances in id (= recording) order.
  std::vector<InstanceId> instances() const;
  std::size_t size() const;

  struct Impl; ///< internal (engine/src/vulkan/world_impl.hpp)

private:
  friend struct detail::Access;
  explicit ClothWorld(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
};

} // namespace vkcloth::gpu
