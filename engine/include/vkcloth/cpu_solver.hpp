// SPDX-License-Identifier: MIT
// The CPU reference solver: deterministic (same input -> bit-identical output), float by default,
// double for accuracy studies. The Vulkan solver is checked against it.
//
// One step, in this order (the GPU passes do the same per particle; every formula comes from
// engine/kernel/cloth_kernel.h, which both compile; docs/model.md has the equations):
//   1. normals   n_p = normalize(sum of p's fan triangles' cross products)  [surfaces only]
//   2. force     F_p = sum over p's springs in gather order (ClothTopology::edges)
//                      + m g - mu m v + Kw <n, u_w> n
//   3. contact   for each collider the particle touches (distance < 2 eps): remove the normal
//                part of v and F only where it points into the collider (Figure 12)
//   4. integrate explicit / semi-implicit Euler, RK4 (steps 1-3 at each stage), or implicit Euler
//                (linearised backward Euler solved by PCG, implicit_euler.hpp; the new velocity's
//                inward part removed for particles in contact)
//   5. project   a particle inside a collider is put back at surface + eps, and its inward
//                velocity removed; pinned particles are left where they are
//   6. stretch   stretch_limit on: Provot sweeps over the strain links colour by colour, then the
//                tethers, then the projection again; the moves update the velocities (v += dx / h)
//   6b. self     self_collision on: the spatial hash, then Jacobi passes pushing apart particles
//                closer than the thickness and removing their approach, then the projection again
//   7. check     NaN/inf or |p| > divergence_limit -> Error{diverged} naming the step and time
#pragma once

#include <cstdint>
#include <memory>
#include <span>
#include <vector>

#include <glm/vec3.hpp>

#include "vkcloth/params.hpp"
#include "vkcloth/result.hpp"
#include "vkcloth/system.hpp"
#include "vkcloth/topology.hpp"

namespace vkcloth {

struct CpuSolverOptions {
  /// Threads that share a step (including the caller's); 0 = the cores this process may run on (its CPU
  /// affinity: taskset, a container's cpuset). Small systems use fewer (one per ~1000 particles).
  /// Every particle's arithmetic is independent of the others', so results are bit-identical
  /// for any thread count.
  unsigned threads = 0;
};

template <typename Real> class CpuSolver {
public:
  using Vec3 = glm::vec<3, Real, glm::defaultp>;

  /// A solver of `topology` (shared, immutable) with `params` (validated), starting from the
  /// topology's rest state.
  static Result<CpuSolver> create(std::shared_ptr<const ClothTopology> topology, SimParams params,
                                  CpuSolverOptions options = {});
  /// Convenience: prepares the topology of `system` first (ClothTopology::create).
  static Result<CpuSolver> create(const ParticleSystem& system, SimParams params,
                                  CpuSolverOptions options = {});

  CpuSolver(CpuSolver&&) noexcept;
  CpuSolver& operator=(CpuSolver&&) noexcept;
  ~CpuSolver();

  unsigned threads() const;

  /// Advances one time step (params().substeps substeps of dt / substeps). On a blow-up the state is left as
  /// it was after the bad step.
  Result<void> step();
  /// Advances `steps` steps, stopping at the first error.
  Result<void> run(std::uint64_t steps);

  /// Replaces the parameters between steps (validated; the topology stays; the attachments'
  /// particles are checked against the cloth and the host's pin targets).
  Result<void> set_params(SimParams params);
  const SimParams& params() const;

  /// The positions keep their address across step() and run() (the solver double-buffers them
  /// inside a step and puts the result back where it was): a host, or a numpy view, may keep the
  /// span. velocities(), forces() and normals() never move.
  std::span<const Vec3> positions() const;
  std::span<const Vec3> velocities() const;
  /// Forces of the last evaluation (after contact filtering); for RK4 the first stage's.
  std::span<const Vec3> forces() const;
  /// Unit normals of the last evaluation (zero for chains and degenerate fans).
  std::span<const Vec3> normals() const;

  /// implicit_euler: CG iterations and relative residual of the last substep's solve.
  const SolveStats& last_solve() const;
  /// Self-collision's passes and neighbour-list builds so far (all 0 before its first substep).
  SelfCollisionStats self_collision_stats() const;

  std::uint64_t step_index() const;
  /// Simulated time: the sum of the steps' dt (dt may change between steps, StepParams).
  double time() const;
  const ParticleSystem& system() const;
  const std::shared_ptr<const ClothTopology>& topology() const;

  /// Moves one particle (a "hand"): sets its position and velocity for the next step.
  /// ErrorCode::invalid_argument (state unchanged) when `index` >= the particle count or a
  /// component is NaN/inf.
  Result<void> set_particle(std::uint32_t index, Vec3 position, Vec3 velocity);

  /// The host's targets for the next step (PinTarget: reached at the step's end, interpolated
  /// across its substeps), replacing the previous ones; a particle left out is released. The
  /// errors (state unchanged) name the target: a particle past the cloth, one targeted twice (or
  /// also by params().attachments), a non-finite position, a negative max_distance.
  Result<void> set_pin_targets(std::span<const PinTarget> targets);
  /// Moves the whole cloth by `jump` at the start of the next step, unfelt: positions, velocities
  /// (turned) and the host's targets (docs/model.md "Inertia and teleport"). A host that moves
  /// the cloth's frame collider moves it too (set_params); a keyframe's `teleport` does both by
  /// itself. ErrorCode::invalid_argument (nothing changed) for non-finite values or a rotation
  /// that is not one.
  Result<void> teleport(const RigidJump& jump);

  /// Kinetic energy sum 1/2 m v^2, gravitational and spring potential energies (for studies).
  struct Energy {
    double kinetic = 0, gravity = 0, spring = 0;
    double total() const { return kinetic + gravity + spring; }
  };
  Energy energy() const;

  /// The solver's state and its per-particle loops (engine/src/core/cpu_solver_impl.hpp).
  struct Impl;

private:
  explicit CpuSolver(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
};

extern template class CpuSolver<float>;
extern template class CpuSolver<double>;

} // namespace vkcloth
