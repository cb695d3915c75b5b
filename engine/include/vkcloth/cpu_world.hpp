// SPDX-License-Identifier: MIT
// Many cloths on the CPU, with the shape of gpu::ClothWorld (gpu/world.hpp): add / remove /
// set_params / set_step_params / simulate / positions under the same names and signatures, so a
// host that steps and reads back switches backends by changing one type:
//
//   vkcloth::CpuWorld world = vkcloth::CpuWorld::create().value();    // or
//   vkcloth::gpu::ClothWorld world = vkcloth::gpu::ClothWorld::create(context).value();
//   auto id = world.add(topology, params).value();
//   world.simulate(60);
//   auto positions = world.positions(id).value();                     // std::vector<glm::vec3>
//
// Each instance is a CpuSolver<float> of its own (the same bits as a standalone one, and, for the
// explicit integrators on lavapipe, as the GPU's), sharing the topology it was added with.
// simulate() steps the instances one after the other in id order, each on its solver's worker
// threads (CpuSolverOptions::threads; a small cloth uses one, see cpu_solver.hpp). There is no
// recording: simulate() runs the steps now and returns when they are done.
//
// Divergence, as on the GPU: an instance that blows up is frozen at its bad step (never stepped
// again, set_params included, until its remove()), the others finish their steps, and simulate() /
// check_divergence() return ErrorCode::diverged naming the first such instance (in id order), its
// step and time.
//
// Thread safety: none; one thread drives a world (as a CpuSolver).
#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>
#include <span>
#include <vector>

#include <glm/vec3.hpp>

#include "vkcloth/cpu_solver.hpp"
#include "vkcloth/params.hpp"
#include "vkcloth/result.hpp"
#include "vkcloth/topology.hpp"
#include "vkcloth/world_types.hpp"

namespace vkcloth {

struct CpuWorldOptions {
  /// Options of every instance's solver (threads).
  CpuSolverOptions solver;
};

class CpuWorld {
public:
  /// An empty world. ErrorCode::invalid_argument for invalid solver options (threads > 256).
  static Result<CpuWorld> create(CpuWorldOptions options = {});

  CpuWorld(CpuWorld&&) noexcept;
  CpuWorld& operator=(CpuWorld&&) noexcept;
  CpuWorld(const CpuWorld&) = delete;
  CpuWorld& operator=(const CpuWorld&) = delete;
  ~CpuWorld();

  /// Adds a cloth of `topology` (ClothTopology::create; shared, not copied) with `params`,
  /// validated as CpuSolver::create (errors name the parameter), starting from `initial` where
  /// given (sizes checked: the error names both counts; non-finite values are an error).
  Result<InstanceId> add(std::shared_ptr<const ClothTopology> topology, SimParams params,
                         const InitialState& initial = {});
  /// Removes an instance; the others keep their state. ErrorCode::invalid_argument for an unknown id.
  Result<void> remove(InstanceId id);
  /// New parameters from the next step (validated; on an error the old ones stay). Any change,
  /// the integrator's included, keeps the instance's state.
  Result<void> set_params(InstanceId id, SimParams params);
  /// set_params(id, step.applied_to(params(id))): the per-frame fields (dt, gravity, wind, colliders).
  Result<void> set_step_params(InstanceId id, const StepParams& step);
  /// The per-frame pose of ONE animated collider, without resending its shape and friction:
  /// set_params(id, with_collider_pose(params(id), collider, pose)), `collider` its index in
  /// params(id).colliders (ColliderPose says what the pose sets). The same rule as set_step_params
  /// (from the next step); the errors name an unknown id, an index past the list or the pose's
  /// field, and leave the parameters as they were.
  Result<void> set_collider_pose(InstanceId id, std::size_t collider, const ColliderPose& pose);
  /// The host's per-frame targets of the instance's particles for the next step (PinTarget;
  /// CpuSolver::set_pin_targets, whose errors these are, or an unknown id).
  Result<void> set_pin_targets(InstanceId id, std::span<const PinTarget> targets);
  /// The instance's whole cloth moved by `jump` at its next step, unfelt (CpuSolver::teleport).
  Result<void> teleport(InstanceId id, const RigidJump& jump);
  /// The instance's parameters; moving colliders where its steps left them.
  Result<SimParams> params(InstanceId id) const;

  /// Runs `steps` steps of every instance now (see the header note for a divergence).
  /// `steps_per_submit` is accepted for ClothWorld's signature and ignored: nothing is submitted.
  Result<void> simulate(std::uint64_t steps, std::uint32_t steps_per_submit = 64);
  /// The first diverged instance's error again (ErrorCode::diverged naming it), or success.
  Result<void> check_divergence();

  /// Copies of one instance's state (ClothWorld's readbacks; no wait on the CPU).
  Result<std::vector<glm::vec3>> positions(InstanceId id);
  Result<std::vector<glm::vec3>> velocities(InstanceId id);
  /// Unit normals of the last step (zero before the first step, for chains and degenerate fans).
  Result<std::vector<glm::vec3>> normals(InstanceId id);
  /// Completed steps of the instance since its add() (the bad one when it diverged; 0 for an
  /// unknown id).
  std::uint64_t step_index(InstanceId id) const;
  /// The instance's shared topology (null for an unknown id).
  std::shared_ptr<const ClothTopology> topology(InstanceId id) const;

  /// Live instances in id (= stepping) order.
  std::vector<InstanceId> instances() const;
  std::size_t size() const;

  // CPU only (the counterparts of ClothWorld::buffers and render::record_hold_particle).

  /// The instance's solver (null for an unknown id), to read without a copy: positions(),
  /// normals() for an upload, time(), energy(), last_solve(). Valid until the instance's
  /// remove(); step through the world, not through this.
  const CpuSolver<float>* solver(InstanceId id) const;
  /// Moves one particle of an instance (CpuSolver::set_particle: a "hand"); the errors name the
  /// instance or the particle.
  Result<void> set_particle(InstanceId id, std::uint32_t index, glm::vec3 position, glm::vec3 velocity);

  struct Impl; ///< internal (cpu_world.cpp)

private:
  explicit CpuWorld(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
};

} // namespace vkcloth
