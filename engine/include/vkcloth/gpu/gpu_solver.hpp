// SPDX-License-Identifier: MIT
// The Vulkan compute solver: the CPU reference's step (cpu_solver.hpp) as two compute passes per
// particle, force.comp and integrate.comp, with the same float expression order, so on a driver
// without FMA contraction it reproduces CpuSolver<float> (lavapipe: bit for bit).
//
// Per step (Euler):      fused(positions[read] -> positions[write]) -> swap   (GpuSolverOptions::fused)
//                   or   force(positions[read]) -> integrate(-> positions[write]) -> swap
// Per step (RK4):        4 x (force(stage input) -> integrate(stage k)); the last writes positions[write]
// Per step (implicit):   force -> system -> cg_max_iterations x (matvec -> update -> direction,
//                        indirect: empty once converged; the sums in each pass's last workgroup),
//                        or a few one-workgroup CG dispatches (GpuSolverOptions::cg_dispatch)
//                        -> finish (passes/implicit_gpu.hpp); every scheme repeats its passes `substeps`
//                        times
//
// Buffers (device-local storage buffers, vec4 per particle, w unused; positions have w = 1):
// positions[2] (ping-pong), velocities, forces, normals (unit, zero for chains; fused Euler
// stores forces and normals in the last step of a recording), uvs (ClothTopology::uvs: i/(nx-1),
// j/(ny-1) for grids, a mesh's own, zero for chains), the topology's triangle indices, plus internal
// scratch. Normals come from the grid fan (grids) or the topology's fan lists (meshes). A GpuSolver is a
// gpu::ClothWorld of one instance (world.hpp: many cloths of one topology, same shaders, one
// dispatch per pass), with the single-cloth conveniences below.
//
// Thread safety: none; one thread drives a solver. Known limitation: the step counter of the
// divergence flags is 32-bit (about 4e9 steps per solver).
#pragma once

#include <cstdint>
#include <memory>
#include <span>
#include <vector>

#include <glm/vec2.hpp>
#include <glm/vec3.hpp>
#include <vulkan/vulkan_core.h>

#include "vkcloth/gpu/context.hpp"
#include "vkcloth/gpu/layout.hpp"
#include "vkcloth/params.hpp"
#include "vkcloth/result.hpp"
#include "vkcloth/system.hpp"
#include "vkcloth/topology.hpp"

namespace vkcloth::gpu {

struct GpuSolverOptions {
  /// Euler integrators: one fused dispatch per step (fused.comp: normal, spring gather, contacts,
  /// integration and projection in one invocation) instead of force.comp + integrate.comp. Same
  /// arithmetic in the same order, so the results are identical; fewer bytes moved and one barrier
  /// per step instead of two. RK4 always uses the two-pass layout (its stages need every
  /// particle's stage state before the next force evaluation).
  bool fused = true;
  /// Queue families (besides the Context's, which is always added) that use the per-particle and
  /// topology buffers, e.g. the host's graphics family when it differs from the compute family.
  /// Two or more distinct families create the buffers VK_SHARING_MODE_CONCURRENT, so the host
  /// needs no queue-family ownership transfer (it still needs a semaphore between the compute
  /// and the graphics submissions). Empty: VK_SHARING_MODE_EXCLUSIVE (see record_steps()).
  std::vector<std::uint32_t> sharing_queue_families;
  /// The side the stored normals point to. Default (false): the side from which the triangles of
  /// InstanceBuffers::indices wind counter-clockwise (right-hand rule; on a grid the direction of
  /// cross(x(i+1,j) - x(i,j), x(i,j+1) - x(i,j)): +z for make_cloth's horizontal grid at rest, -y
  /// for its vertical one). true: the opposite side (a host whose lit side is the other one).
  /// Only the normals buffer changes; the physics does not (docs/embedding.md "Normals").
  bool flip_normals = false;
  /// Also write InstanceBuffers::vertices: one interleaved vertex per particle (32 bytes: position
  /// xyz at byte 0, normal xyz at 12, uv at 24; formats R32G32B32 / R32G32B32 / R32G32_SFLOAT),
  /// for a host pipeline with one vertex binding. One extra dispatch at the end of every
  /// recording; the buffer holds the state after it (zero before the first recording).
  bool interleaved_vertices = false;
  /// How the shaders read positions, velocities, particle constants, instance parameters and the
  /// topology's lists (layout.hpp): `automatic` (default) takes the device's choice
  /// (device_layout(): texel views on a CPU device such as lavapipe, storage buffers on a GPU);
  /// texel_views / storage_buffers force one. Same bits either way; only the speed differs.
  BufferAccess buffer_access = BufferAccess::automatic;
  /// Invocations per workgroup of the per-particle passes; 0 (default): the device's choice
  /// (DeviceLayout::workgroup_size: 64 on lavapipe, a multiple of the subgroup size on a GPU).
  /// At most maxComputeWorkGroupSize[0] and maxComputeWorkGroupInvocations (else
  /// ErrorCode::unsupported). Implicit Euler always uses 64 (its reductions are sized for it).
  /// Same bits for any size: every particle is computed by one invocation alone.
  std::uint32_t workgroup_size = 0;
  /// implicit_euler: where the CG iterations run. `one_workgroup`: one workgroup runs dozens of
  /// iterations per dispatch (a few dispatches per substep instead of 3 + 5 per iteration; each
  /// iteration costs more, since one workgroup does all the work); an error (unsupported) for a
  /// cloth too large for one workgroup. `per_iteration`: every iteration's passes over all
  /// particles. `automatic`: one_workgroup on a CPU-type device (lavapipe) up to
  /// implicit_one_workgroup_max_particles particles, per_iteration otherwise
  /// (docs/performance.md "Implicit Euler").
  enum class CgDispatch { automatic, one_workgroup, per_iteration };
  CgDispatch cg_dispatch = CgDispatch::automatic;
};

/// CgDispatch::automatic's limit for one_workgroup, measured on lavapipe (docs/performance.md):
/// 1.3x faster than per_iteration at 16 x 16, even at 32 x 32, slower from 48 x 48 on (idle).
inline constexpr std::uint32_t implicit_one_workgroup_max_particles = 1024;

/// Where an instance's per-particle data lives, for the host's own drawing: vec4 per particle
/// (w = 1 for positions), `stride` bytes apart, `count` particles from byte `offset` of each buffer.
/// `positions` is the CURRENT positions buffer: query it again after every record_steps().
/// Instances of a ClothWorld batch share the buffers at different offsets.
struct InstanceBuffers {
  VkBuffer positions = VK_NULL_HANDLE;
  /// Unit normals pointing to the side from which `indices`' triangles wind counter-clockwise
  /// (GpuSolverOptions::flip_normals: the other side); zero for chains.
  VkBuffer normals = VK_NULL_HANDLE;
  /// Texture coordinates (vec4: u, v, 0, 0): ClothTopology::uvs() (a grid's: ClothDesc::uvs or
  /// uv_transform; a mesh's: its file's).
  VkBuffer uvs = VK_NULL_HANDLE;
  VkDeviceSize offset = 0;
  /// Byte stride of positions, normals and uvs (GpuSolver::stride). Like vertex_stride a layout
  /// constant, static so that a pipeline's VkVertexInputBindingDescription can name it before any
  /// buffer exists (`InstanceBuffers::stride`); `b.stride` reads the same value.
  static constexpr VkDeviceSize stride = 16;
  std::uint32_t count = 0;
  std::uint32_t nx = 0, ny = 0; ///< grid size (0 for chains and meshes)
  /// ClothTopology::triangles() on the device (VK_INDEX_TYPE_UINT32, index_count entries; a grid's
  /// are grid_triangle_indices(nx, ny)), indices relative to the instance's first particle: bind
  /// the vertex buffers at `offset`. Empty (index_count 0) for chains.
  VkBuffer indices = VK_NULL_HANDLE;
  std::uint32_t index_count = 0;
  /// GpuSolverOptions::interleaved_vertices: the instance's interleaved vertices from byte
  /// `vertex_offset`, `vertex_stride` apart (VK_NULL_HANDLE otherwise).
  VkBuffer vertices = VK_NULL_HANDLE;
  VkDeviceSize vertex_offset = 0;
  static constexpr VkDeviceSize vertex_stride = 32; ///< bytes per interleaved vertex
};

/// One half of a queue-family ownership transfer of the buffers a host draws from (current
/// positions, normals, uvs), for compute and graphics queues of different families with
/// EXCLUSIVE buffers (docs/embedding.md section 6 records a whole frame). Per frame, four halves:
/// (1) compute cmd, before record_steps: acquire {graphics, compute, COMPUTE_SHADER, SHADER_READ |
/// SHADER_WRITE}, skipped in the first frame (the buffers start on the Context's family);
/// (2) compute cmd, after record_steps: release {compute, graphics, COMPUTE_SHADER, SHADER_WRITE};
/// (3) graphics cmd, before drawing: acquire {compute, graphics, VERTEX_INPUT,
/// VERTEX_ATTRIBUTE_READ}; (4) graphics cmd, after drawing: release {graphics, compute,
/// VERTEX_INPUT, 0}. Each acquire's submission waits on a semaphore that its release's signals.
struct QueueTransfer {
  std::uint32_t src_family = 0;
  std::uint32_t dst_family = 0;
  /// Release: the last use on src_family. Acquire: the next use on dst_family.
  VkPipelineStageFlags stage = 0;
  VkAccessFlags access = 0;
};

class GpuSolver {
public:
  /// Validates `params` as CpuSolver::create does, checks the device limits BEFORE allocating
  /// (ErrorCode::unsupported naming the buffer and the limit), uploads the state. `topology`
  /// (ClothTopology::create, shared and immutable) must not be null.
  static Result<GpuSolver> create(Context& context, std::shared_ptr<const ClothTopology> topology,
                                  SimParams params, const GpuSolverOptions& options = {});
  /// Convenience: prepares the topology of `system` first (ClothTopology::create validates it).
  static Result<GpuSolver> create(Context& context, const ParticleSystem& system, SimParams params,
                                  const GpuSolverOptions& options = {});

  GpuSolver(GpuSolver&&) noexcept;
  GpuSolver& operator=(GpuSolver&&) noexcept;
  GpuSolver(const GpuSolver&) = delete;
  GpuSolver& operator=(const GpuSolver&) = delete;
  /// Frees the solver's objects. Its own submissions are always complete; command buffers the
  /// caller recorded with record_steps() must have finished executing (or never be submitted).
  ~GpuSolver();

  /// Replaces the parameters (validated) from the next recorded step. The values are recorded into
  /// that command buffer (vkCmdUpdateBuffer), never written to memory that pending work reads: a
  /// host with frames in flight may change them every frame. A new integrator family or substep
  /// count rebuilds the solver's buffers (the state is copied on the GPU, bit for bit;
  /// current_position_index() restarts at 0); more colliders than the solver has room for, or the
  /// first tethers, replace a buffer. Those three first wait for every earlier submission on the
  /// Context's queue (submit your recordings there, or wait for them yourself). No pipeline is
  /// re-created.
  Result<void> set_params(SimParams params);
  const SimParams& params() const;
  /// The host's per-frame pin targets for the next recorded step (ClothWorld::set_pin_targets).
  Result<void> set_pin_targets(std::span<const PinTarget> targets);
  /// The whole cloth moved by `jump` at the next recorded step, unfelt (ClothWorld::teleport).
  Result<void> teleport(const RigidJump& jump);

  /// Records `steps` steps into the caller's command buffer (recording state, compute-capable
  /// queue family of the Context). Host-side counters (step_index, current_position_index)
  /// advance now: submit the command buffer exactly once, in recording order.
  /// Synchronisation: the recording starts with one barrier ordering all earlier commands and
  /// their memory writes before the first dispatch. It ends right after the last dispatch: the
  /// buffers are left as compute-shader writes NOT yet visible to any later stage. Before reading
  /// them (drawing the current positions and normals, copying), record the caller's barrier or
  /// call record_barrier_to(cmd, dst_stage, dst_access).
  ///
  /// Different queue families for compute and graphics: with EXCLUSIVE buffers (the default) the
  /// drawn buffers change owner every frame (record_release / record_acquire, QueueTransfer); with
  /// GpuSolverOptions::sharing_queue_families (CONCURRENT buffers) only semaphores are needed.
  /// docs/embedding.md section 6 records a whole frame of each.
  void record_steps(VkCommandBuffer cmd, std::uint32_t steps);
  /// set_params(step.applied_to(params())), then record_steps(cmd, steps): this recording and the
  /// next ones step with the frame's dt, gravity, wind and colliders (race-free with frames in
  /// flight). Invalid values: the error names the field, nothing is recorded.
  Result<void> record_steps(VkCommandBuffer cmd, std::uint32_t steps, const StepParams& step);
  /// record_steps(cmd, 1): one step (the whole step: all substeps, RK4 stages or CG passes).
  void record_step(VkCommandBuffer cmd);
  /// Records the barrier that makes the last record_steps() writes visible to `dst_stage` /
  /// `dst_access` (e.g. VK_PIPELINE_STAGE_VERTEX_INPUT_BIT / VK_ACCESS_VERTEX_ATTRIBUTE_READ_BIT).
  void record_barrier_to(VkCommandBuffer cmd, VkPipelineStageFlags dst_stage, VkAccessFlags dst_access) const;
  /// The two halves of a queue-family ownership transfer of the drawn buffers (QueueTransfer).
  void record_release(VkCommandBuffer cmd, const QueueTransfer& transfer) const;
  void record_acquire(VkCommandBuffer cmd, const QueueTransfer& transfer) const;

  /// Records, submits and waits for `steps` steps, `steps_per_submit` per command buffer; sums the
  /// GPU time of the submissions (last_gpu_ms). Checks the divergence flags after each submission:
  /// ErrorCode::diverged names the exact first bad step; the state is left as after that step
  /// (later steps of the batch leave it unchanged), and step_index() is that step.
  Result<void> simulate(std::uint64_t steps, std::uint32_t steps_per_submit = 64);
  /// Reads the divergence flags after the caller's own submissions of record_steps() completed.
  Result<void> check_divergence();

  /// Readbacks (submit, wait, copy). Values are those of the last completed step.
  Result<std::vector<glm::vec3>> positions();
  Result<std::vector<glm::vec3>> velocities();
  /// Unit normals of the last force evaluation (zero for chains and degenerate fans).
  /// Fused Euler (the default) writes forces and normals only in the last substep of each recorded
  /// batch (each submission of simulate(), each record_steps() call), so after a divergence inside
  /// a batch they are those of the last batch end before it, not the bad step's.
  Result<std::vector<glm::vec3>> normals();
  /// Forces of the last evaluation after contacts (for RK4 the first stage's), as on the CPU.
  Result<std::vector<glm::vec3>> forces();
  /// Texture coordinates as uploaded.
  const std::vector<glm::vec2>& uvs() const;
  /// The prepared topology the solver steps (for ClothRenderer::create).
  const std::shared_ptr<const ClothTopology>& topology() const;

  std::uint64_t step_index() const;
  /// Simulated time: the sum of the recorded steps' dt.
  double time() const;
  std::uint32_t particle_count() const;

  /// Index (0 or 1) of the positions buffer holding the current positions: 0 at creation (and
  /// after a set_params() that changed the integrator family or substeps), flipped by every
  /// recorded substep (so (step_index() * substeps) % 2, unless a step diverged).
  std::uint32_t current_position_index() const;
  VkBuffer position_buffer(std::uint32_t index) const;
  VkBuffer current_position_buffer() const;
  VkBuffer velocity_buffer() const;
  VkBuffer normal_buffer() const;
  VkBuffer uv_buffer() const;
  /// Byte stride of every per-particle buffer above (vec4).
  static constexpr VkDeviceSize stride = 16;
  /// The buffers above for drawing (offset 0); query again after every record_steps().
  InstanceBuffers buffers() const;

  /// implicit_euler: CG iterations and relative residual of the last completed substep's solve,
  /// and the iterations and solves since creation (read from host-visible memory: valid once the
  /// recorded work has finished).
  SolveStats last_solve() const;
  /// implicit_euler: whether the CG iterations run in one workgroup (GpuSolverOptions::cg_dispatch);
  /// chosen when the solver is made (or its integrator becomes implicit_euler); false for the others.
  bool implicit_one_workgroup() const;

  /// GPU time of the last simulate() (sum over its submissions, timestamps), in milliseconds;
  /// negative when the queue has no timestamp support.
  double last_gpu_ms() const;
  /// True when bulk buffers go through staging (not host-visible, or testing::SolverKnobs::force_staging).
  bool uses_staging() const;

  struct Impl; ///< internal (engine/src/vulkan)

private:
  friend struct detail::Access;
  explicit GpuSolver(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
};

static_assert(InstanceBuffers::stride == GpuSolver::stride,
              "one vec4 per particle in every per-particle buffer");

} // namespace vkcloth::gpu
