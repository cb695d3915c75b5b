// Many cloths on one Context: a shared, immutable topology (a ParticleSystem held by
// std::shared_ptr<const ParticleSystem>: particles' rest state, masses, pins, springs, rest
// lengths, CSR gather lists, grid) and instances with their own state (positions, velocities)
// and parameters (SimParams: integrator, dt, gravity, damping, wind, colliders, ...).
//
// Each instance is a GpuSolver (the one physics implementation: same shaders, same bits as a
// standalone GpuSolver and, on lavapipe, as CpuSolver<float>). record_steps() records every
// instance's passes into the host's command buffer, one after the other.
//
// Known limitations (this version): instances are NOT batched into one dispatch per pass; each
// instance dispatches its own passes (one fused dispatch per Euler step, two per two-pass step,
// 8 per RK4 step, the CG passes for implicit Euler), and each keeps its own copy of the topology
// buffers on the GPU (the CPU-side topology is shared). Pipelines are created per instance at
// add(); set_params() never re-creates them (except the CG pipelines the first time an instance
// switches to implicit_euler).
//
// Thread safety: none; one thread drives a world (as a GpuSolver).
#pragma once

#include <cstdint>
#include <memory>
#include <optional>
#include <vector>

#include <glm/vec3.hpp>
#include <vulkan/vulkan_core.h>

#include "vkcloth/gpu/context.hpp"
#include "vkcloth/gpu/gpu_solver.hpp"
#include "vkcloth/params.hpp"
#include "vkcloth/result.hpp"
#include "vkcloth/system.hpp"

namespace vkcloth::gpu {

/// Two counter-clockwise triangles (a, b, d), (a, d, c) per grid quad, particle (i, j) = j*nx + i:
/// the index list ClothRenderer draws; upload it as a VK_INDEX_TYPE_UINT32 index buffer.
std::vector<std::uint32_t> grid_triangle_indices(std::uint32_t nx, std::uint32_t ny);

struct WorldOptions {
  /// Options of every instance's solver (fused, staging, sharing_queue_families, ...).
  GpuSolverOptions solver;
};

/// An instance's handle; never reused within one world.
using InstanceId = std::uint64_t;

/// Optional initial state of an instance (instead of the topology's particle positions and
/// velocities); each vector is empty (topology's value) or has one entry per particle.
struct InitialState {
  std::vector<glm::dvec3> positions;
  std::vector<glm::dvec3> velocities;
};

/// Where an instance's per-particle data lives, for the host's own drawing: vec4 per particle
/// (w = 1 for positions), `stride` bytes apart, `count` particles from byte `offset` of each buffer.
/// `positions` is the CURRENT positions buffer: query it again after every record_steps().
struct InstanceBuffers {
  VkBuffer positions = VK_NULL_HANDLE;
  VkBuffer normals = VK_NULL_HANDLE;
  VkBuffer uvs = VK_NULL_HANDLE;
  VkDeviceSize offset = 0;
  VkDeviceSize stride = GpuSolver::stride;
  std::uint32_t count = 0;
  std::uint32_t nx = 0, ny = 0; ///< grid size (0 for chains): grid_triangle_indices(nx, ny)
};

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

  /// Adds a cloth of `topology` (shared, must not change while the world holds it) with `params`;
  /// validated as GpuSolver::create (errors name the parameter). Takes effect from the next
  /// recording; no recorded work of this world may be pending.
  Result<InstanceId> add(std::shared_ptr<const ParticleSystem> topology, SimParams params,
                         const InitialState& initial = {});
  /// Removes an instance (its buffers are freed now: no recorded work of the world may be
  /// pending); the others keep their state. ErrorCode::invalid_argument for an unknown id.
  Result<void> remove(InstanceId id);
  /// New parameters from the next recorded step (no pipeline is re-created; see the header note).
  Result<void> set_params(InstanceId id, SimParams params);
  Result<SimParams> params(InstanceId id) const;

  /// Records one step of every instance into the host's command buffer (see GpuSolver::record_steps
  /// for the state the buffers are left in: compute writes not yet visible to later stages).
  void record_step(VkCommandBuffer cmd);
  /// Records `steps` steps of every instance (instance by instance, in id order).
  void record_steps(VkCommandBuffer cmd, std::uint32_t steps);
  /// One barrier making every instance's last writes visible to `dst_stage` / `dst_access`.
  void record_barrier_to(VkCommandBuffer cmd, VkPipelineStageFlags dst_stage, VkAccessFlags dst_access) const;

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
  /// Buffers for drawing (valid until the instance is removed).
  Result<InstanceBuffers> buffers(InstanceId id) const;
  /// The instance's solver, e.g. for render::ClothRenderer (null for an unknown id).
  GpuSolver* solver(InstanceId id);
  const GpuSolver* solver(InstanceId id) const;
  /// The instance's shared topology (null for an unknown id).
  std::shared_ptr<const ParticleSystem> topology(InstanceId id) const;

  /// Live instances in id (= recording) order.
  std::vector<InstanceId> instances() const;
  std::size_t size() const;

  struct Impl; ///< internal (engine/src/vulkan/world.cpp)

private:
  explicit ClothWorld(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
};

} // namespace vkcloth::gpu
