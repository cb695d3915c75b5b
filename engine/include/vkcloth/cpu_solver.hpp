// SPDX-License-Identifier: MIT
// The CPU reference solver: deterministic (same input -> bit-identical output), float by default,
// double for accuracy studies. The Vulkan solver is checked against it.
//
// One step, in this order (the GPU passes do the same per particle; every formula comes from
// shaders/include/cloth_kernel.h, which both compile; docs/model.md has the equations):
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

#include <array>
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

namespace detail {
class ThreadPool;
template <typename Real> struct ImplicitWorkspace;
template <typename Real> struct RowArgs;
template <typename Real> struct ContactShapes;
template <typename Real> struct SelfCollisionGrid;
template <typename Real> struct StrainProjection;
template <typename Real> struct PaddedLists;
template <typename Real> struct StepArgs;
} // namespace detail

struct CpuSolverOptions {
  /// Threads that share a step (including the caller's); 0 = the host's hardware threads.
  /// Small systems use fewer (one per ~1000 particles).
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

  /// Replaces the parameters between steps (validated; the topology stays).
  Result<void> set_params(SimParams params);
  const SimParams& params() const { return params_; }

  std::span<const Vec3> positions() const { return pos_; }
  std::span<const Vec3> velocities() const { return vel_; }
  /// Forces of the last evaluation (after contact filtering); for RK4 the first stage's.
  std::span<const Vec3> forces() const { return force_; }
  /// Unit normals of the last evaluation (zero for chains and degenerate fans).
  std::span<const Vec3> normals() const { return normal_; }

  /// implicit_euler: CG iterations and relative residual of the last substep's solve.
  const SolveStats& last_solve() const { return solve_; }

  std::uint64_t step_index() const { return step_; }
  /// Simulated time: the sum of the steps' dt (dt may change between steps, StepParams).
  double time() const { return time_; }
  const ParticleSystem& system() const { return topology_->system(); }
  const std::shared_ptr<const ClothTopology>& topology() const { return topology_; }

  /// Moves one particle (a "hand"): sets its position and velocity for the next step.
  /// ErrorCode::invalid_argument (state unchanged) when `index` >= the particle count or a
  /// component is NaN/inf.
  Result<void> set_particle(std::uint32_t index, Vec3 position, Vec3 velocity);

  /// Kinetic energy sum 1/2 m v^2, gravitational and spring potential energies (for studies).
  struct Energy {
    double kinetic = 0, gravity = 0, spring = 0;
    double total() const { return kinetic + gravity + spring; }
  };
  Energy energy() const;

private:
  CpuSolver();
  // Per-particle kernels (each formula from shaders/include/cloth_kernel.h): each reads shared
  // inputs and writes only particle p's outputs.
  /// Particle p's normal and force: writes normal_[p] (from the grid fan, or from the gather
  /// list's ring terms with ClothTopology::ring_normals), returns the force.
  Vec3 normal_force_at(std::span<const Vec3> pos, std::span<const Vec3> vel, std::size_t p);
  // Contacts (cloth_kernel.h contact_response / project_out) with every collider at this substep's
  // pose; h_over_m: substep / mass (friction's impulse); side: where the particle came from.
  void contact_at(Vec3 pos, Vec3& vel, Vec3& force, Real h_over_m, bool friction = true) const;
  void project_at(Vec3 side, Vec3& pos, Vec3& vel) const;
  void prepare_colliders();
  void advance_colliders(double h);
  Result<void> check_finite() const;
  void substep(Real h);
  // Explicit / semi-implicit Euler: contacts, update and projection of particle p with force f
  // (writes force_[p], pos_next_[p], vel_[p]).
  void euler_finish(std::size_t p, Vec3 f, Real h, bool semi);
  void euler_substep(Real h, bool semi);
  void row_sweep(Real h, bool semi);  // euler_substep on a grid stencil (row_kernel.hpp)
  void list_sweep(Real h, bool semi); // euler_substep without a stencil, in SIMD (row_kernel.hpp)
  void step_args(detail::StepArgs<Real>& a, Real h, bool semi);
  detail::RowArgs<Real> row_args(Real h, bool semi);
  void rk4_substep(Real h);
  // Implicit Euler (implicit_euler.cpp): forces, then the linear system, CG, and the update.
  void implicit_substep(Real h);
  void implicit_system(Real h);
  void implicit_cg(Real h);
  void implicit_update(Real h);
  // Stretch control after a substep (docs/model.md "Stretch control").
  void limit_stretch(Real h);
  // Self-collision after that (self_collision.cpp; docs/model.md "Self-collision").
  void self_collide();
  void project_strain(Real h);

  /// A gather-list entry in the solver's precision (ClothTopology::edges() converted once).
  struct Edge {
    std::uint32_t other;
    Real rest_length;
    Real stiffness;
    std::uint32_t ring; // VKCLOTH_RING_*
  };

  std::shared_ptr<const ClothTopology> topology_;
  SimParams params_;
  std::span<const std::uint32_t> edge_offsets_; // the topology's
  std::vector<Edge> edges_;
  std::vector<Real> mass_;
  std::vector<std::uint8_t> pinned_;
  std::vector<Vec3> pos_, vel_, force_, normal_;
  std::vector<Vec3> pos_next_;                     // integration writes here while forces still read pos_
  std::array<std::vector<Vec3>, 4> k_pos_, k_vel_; // RK4 stage derivatives
  std::vector<Vec3> stage_pos_, stage_vel_;
  // The topology's grid stencil (null: none): interior particles' springs from these constants
  // instead of the CSR lists, same terms in the same order, so the same bits.
  const GridStencil* stencil_ = nullptr;
  std::array<std::int64_t, 12> stencil_offset_{};
  std::array<Real, 12> stencil_rest_{}, stencil_stiff_{};
  // Positions as SoA for the row kernel: x, y, z blocks of n + 2 soa_pad_ each, particle p of a
  // block at soa_pad_ + p (the pads let masked border lanes read absent neighbours). The row sweep
  // writes the next step's copy (soa_next_) as it integrates; soa_valid_ is false after anything
  // else changed pos_ (set_particle, RK4, implicit Euler), and the next row sweep transposes.
  std::vector<Real> soa_, soa_next_;
  std::size_t soa_pad_ = 0;
  bool soa_valid_ = false;
  bool swept_finite_ = false; // the last substep's row sweep found every position/velocity finite
  int simd_ = 0;              // row kernel ISA: 0 none, 1 AVX2, 2 AVX-512F (cpu_solver.cpp)
  // Stretch control in the solver's precision (converted from the topology when first needed).
  struct Link {
    std::uint32_t a, b;
    Real rest_length;
  };
  struct TetherSlot {
    std::uint32_t anchor;
    Real rest_length;
  };
  std::vector<Link> strain_links_;
  std::vector<TetherSlot> tethers_;
  StretchLimit::TetherDistance tether_kind_ = StretchLimit::TetherDistance::euclidean;
  std::uint64_t step_ = 0;
  double time_ = 0.0;
  std::unique_ptr<detail::ThreadPool> pool_;
  std::unique_ptr<detail::ImplicitWorkspace<Real>> implicit_;  // created by the first implicit step
  std::unique_ptr<detail::ContactShapes<Real>> contacts_;      // this substep's colliders (prepare_colliders)
  std::unique_ptr<detail::SelfCollisionGrid<Real>> self_;      // created by the first self-collision substep
  std::unique_ptr<detail::StrainProjection<Real>> projection_; // created by the first fast-projection substep
  std::unique_ptr<detail::PaddedLists<Real>> lists_;           // created by the first list sweep
  SolveStats solve_;
};

extern template class CpuSolver<float>;
extern template class CpuSolver<double>;

} // namespace vkcloth
