// SPDX-License-Identifier: MIT
// CpuSolver's internals (the public header holds the API only): the state in the solver's
// precision and the per-particle loops of one substep. Defined in cpu_solver.cpp (Euler, RK4, the
// row and list sweeps), implicit_euler.cpp, vbd.cpp, self_collision.cpp and strain_projection.cpp.
#pragma once

#include <algorithm>
#include <array>
#include <cstdint>
#include <memory>
#include <span>
#include <vector>

#include "internal/cloth_frame.hpp"
#include "internal/kernel.hpp"
#include "internal/pin_targets.hpp"
#include "row_kernel.hpp"
#include "vkcloth/cpu_solver.hpp"

namespace vkcloth {

namespace detail {
class ThreadPool;
template <typename Real> struct ImplicitWorkspace;
template <typename Real> struct SelfCollisionGrid;
template <typename Real> struct SelfConstants;
template <typename Real> struct StrainProjection;
/// The colliders as the kernel takes them at this substep's pose, and their meshes; the same values
/// for the SIMD finish of the grid rows (row_kernel.hpp FinishShape), empty when there are more
/// than detail::finish_max_shapes.
template <typename Real> struct ContactShapes {
  std::vector<kernel::ColliderShape<Real>> shapes;
  std::vector<kernel::MeshData> meshes;
  std::vector<FinishShape<Real>> finish;
};
/// The padded lists the list kernel reads (row_kernel.hpp ListArgs), built once for vectors of
/// `width` particles by pad_lists.
template <typename Real> struct PaddedLists {
  std::size_t width = 0;
  std::vector<std::uint32_t> spring_begin{0}, other, ring, ring_end;
  std::vector<std::uint8_t> reads_last; ///< per vector: some slot names the last particle
  std::vector<Real> rest, stiff;
};

/// Appends one vector of particles (l.width of them) to padded gather lists: as many slots as the
/// longest list among them, slot k holding each particle's k-th edge, or a zero spring to itself
/// (which adds nothing) past its list's end.
template <typename Real, typename Edge>
void pad_vector(PaddedLists<Real>& l, std::span<const std::uint32_t> particles,
                std::span<const std::uint32_t> edge_offsets, std::span<const std::uint32_t> fan_ends,
                const std::vector<Edge>& edges) {
  const std::uint32_t last = std::uint32_t(edge_offsets.size() - 2);
  std::uint32_t slots = 0, ring_slots = 0;
  for (const std::uint32_t p : particles) {
    slots = std::max(slots, edge_offsets[p + 1] - edge_offsets[p]);
    ring_slots = std::max(ring_slots, fan_ends[p] - edge_offsets[p]);
  }
  bool reads_last = false;
  for (std::uint32_t k = 0; k < slots; ++k)
    for (const std::uint32_t p : particles) {
      const bool has = k < edge_offsets[p + 1] - edge_offsets[p];
      const Edge e = has ? edges[edge_offsets[p] + k] : Edge{p, Real(0), Real(0), 0};
      l.other.push_back(e.other);
      l.rest.push_back(e.rest_length);
      l.stiff.push_back(e.stiffness);
      l.ring.push_back(e.ring);
      reads_last = reads_last || e.other == last;
    }
  l.ring_end.push_back(l.spring_begin.back() + ring_slots * std::uint32_t(l.width));
  l.reads_last.push_back(reads_last);
  l.spring_begin.push_back(std::uint32_t(l.other.size()));
}

/// Vertex block descent's per-particle state of a substep (vbd.cpp).
template <typename Real> struct VbdWorkspace {
  using Vec3 = glm::vec<3, Real, glm::defaultp>;
  std::vector<Vec3> x0;   ///< positions at the substep's start
  std::vector<Vec3> y;    ///< inertia targets
  std::vector<Vec3> push; ///< the colliders' projection move of the last iteration
  /// Self-contact's force and stiffness block per particle, from the sweep's start (self_energy_sweep).
  std::vector<Vec3> contact_f, contact_diag, contact_off;
  /// The SIMD lanes' gather lists, padded per vector of each colour's whole vectors (pad_vector),
  /// and each colour's first vector in them; built by the first substep on lanes.
  std::unique_ptr<PaddedLists<Real>> lists;
  std::vector<std::uint32_t> colour_vector;
  /// The begin's fan triangles padded per vector of consecutive particles (VbdBeginArgs), for
  /// `fan_width` lanes (0: not built).
  std::size_t fan_width = 0;
  std::vector<std::uint32_t> fan_begin, fan_a, fan_b;
  std::vector<Real> fan_on;
  std::vector<std::uint8_t> fan_reads_last;
};

/// check_finite's test, branch-free (vectorisable OR-reduction over flat arrays of n3 components):
/// nonzero when a component is not finite (c - c != 0 for inf and NaN) or a position has |x| > limit
/// (or is NaN). The row sweep runs it on each block it wrote, check_finite on the whole state.
template <typename Real>
inline unsigned bad_components(const Real* x, const Real* v, std::size_t n3, Real limit) {
  unsigned bad = 0;
  for (std::size_t i = 0; i < n3; ++i)
    bad |= unsigned(!(std::abs(x[i]) <= limit)) | unsigned(!(x[i] - x[i] == Real(0))) |
           unsigned(!(v[i] - v[i] == Real(0)));
  return bad;
}
} // namespace detail

template <typename Real> struct CpuSolver<Real>::Impl {
  using Vec3 = typename CpuSolver<Real>::Vec3;
  using Energy = typename CpuSolver<Real>::Energy;

  Impl();
  ~Impl();

  // The API's work (CpuSolver forwards here).
  Result<void> step();
  /// Puts the positions back into the buffer at `home` when the step's swaps left them in the other.
  void keep_positions_at(const Vec3* home);
  Result<void> set_params(SimParams params);
  Result<void> set_particle(std::uint32_t index, Vec3 position, Vec3 velocity);
  // The targets of substep k (colliders already posed): pinned particles onto them before the
  // substep (drive_targets), free ones back within reach after it (hold_targets).
  void drive_targets(std::uint32_t k);
  void hold_targets();
  // The frame's jump (every particle, the host's targets) and its carry after a substep.
  void jump_cloth(const RigidJump& jump);
  void carry_cloth(const detail::FrameStep& frame);
  Energy energy() const;
  double time() const { return time_; }
  const ParticleSystem& system() const { return topology_->system(); }

  // Per-particle kernels (each formula from engine/kernel/cloth_kernel.h): each reads shared
  // inputs and writes only particle p's outputs.
  /// Particle p's normal and force: writes normal_[p] (from the grid fan, or from the gather
  /// list's ring terms with ClothTopology::ring_normals), returns the force.
  Vec3 normal_force_at(std::span<const Vec3> pos, std::span<const Vec3> vel, std::size_t p);
  /// Particle p's normal alone (normal_force_at's, the same terms in the same order): writes normal_[p].
  void normal_at(std::span<const Vec3> pos, std::size_t p);
  /// The area-weighted normal sum of the topology's fan around p, in its order (without ring normals).
  Vec3 fan_sum(std::span<const Vec3> pos, std::size_t p) const;
  // Contacts of particle p (cloth_kernel.h contact_response / project_out) with every collider at this
  // substep's pose; h_over_m: substep / mass (friction's impulse); side: where the particle came from.
  void contact_at(std::size_t p, Vec3 pos, Vec3& vel, Vec3& force, Real h_over_m, bool friction = true) const;
  void project_at(std::size_t p, Vec3 side, Vec3& pos, Vec3& vel) const;
  /// Collider k's mesh as the kernel reads it for particle p (its hierarchy and p's search entry).
  kernel::MeshData mesh_of(std::size_t k, std::size_t p) const {
    kernel::MeshData m = contacts_->meshes[k];
    m.particle = std::uint32_t(p);
    return m;
  }
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
  // Vertex block descent (vbd.cpp): the targets, the coloured sweeps, then velocities and friction.
  void vbd_substep(Real h);
  void vbd_begin(Real h);
  void vbd_solve_colour(std::uint32_t colour, Real h, bool contact);
  /// The whole SIMD vectors of a colour's particles (row_kernel.hpp VbdArgs); returns how many it
  /// stepped (0 without SIMD or with more colliders than the lanes take).
  std::size_t vbd_colour_lanes(std::uint32_t colour, std::span<const std::uint32_t> particles, Real h,
                               bool contact);
  void pad_vbd_lists(std::size_t width);
  void pad_vbd_fans(std::size_t width);
  /// The SIMD lanes' width in particles; 1 where they do not apply (no SIMD, or more than
  /// detail::finish_max_shapes colliders).
  std::size_t vbd_lane_width() const;
  std::size_t vbd_begin_lanes(std::size_t begin, std::size_t end, Real h);
  void vbd_finish(Real h);
  // Stretch control after a substep (docs/model.md "Stretch control").
  void limit_stretch(Real h);
  // Self-collision after that (self_collision.cpp; docs/model.md "Self-collision").
  void self_collide();
  void self_init();
  /// Whether vbd takes self-contact as an energy in its vertex steps (SelfCollision::stiffness).
  bool self_energy() const;
  void self_energy_lists();
  void self_energy_sweep(Real h);
  kernel::SelfDataT<Real> self_data();
  void self_hash(Real inv_cell);
  bool self_list_stale(const detail::SelfConstants<Real>& k);
  void self_build_lists(const detail::SelfConstants<Real>& k);
  void project_strain(Real h);

  using Edge = detail::SolverEdge<Real>;

  std::shared_ptr<const ClothTopology> topology_;
  SimParams params_;
  // Attachments and the host's targets (docs/model.md "Attachments"): each substep's in targets_now_.
  detail::PinTargets targets_;
  std::vector<detail::TargetEntry> targets_now_;
  // The cloth's frame (docs/model.md "Inertia and teleport"): the host's teleport for the next
  // step, and the positions at the substep's start while the frame carries the cloth.
  std::optional<RigidJump> host_jump_;
  std::vector<Vec3> frame_x0_;
  std::optional<Collider> frame_last_; // the frame as the last substep left it (frame_step's `before`)
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
  std::vector<Link> strain_chains_; // ClothTopology::strain_chains()
  std::vector<TetherSlot> tethers_;
  StretchLimit::TetherDistance tether_kind_ = StretchLimit::TetherDistance::euclidean;
  std::uint64_t step_ = 0;
  double time_ = 0.0;
  std::unique_ptr<detail::ThreadPool> pool_;
  std::unique_ptr<detail::ImplicitWorkspace<Real>> implicit_; // created by the first implicit step
  std::unique_ptr<detail::ContactShapes<Real>> contacts_;     // this substep's colliders (prepare_colliders)
  // Each particle's search entry per mesh collider (cloth_kernel.h mesh_contact, 8 reals; collider
  // ordinal-major), and the meshes they were found on (a different mesh empties them).
  std::vector<Real> mesh_cache_;
  std::vector<const ColliderMesh*> mesh_cache_meshes_;
  std::unique_ptr<detail::SelfCollisionGrid<Real>> self_;      // created by the first self-collision substep
  std::unique_ptr<detail::StrainProjection<Real>> projection_; // created by the first fast-projection substep
  std::unique_ptr<detail::PaddedLists<Real>> lists_;           // created by the first list sweep
  std::unique_ptr<detail::VbdWorkspace<Real>> vbd_;            // created by the first vbd substep
  SolveStats solve_;
};

} // namespace vkcloth
