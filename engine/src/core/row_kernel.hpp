// SPDX-License-Identifier: MIT
// The CPU solver's SIMD kernels (the grid row kernel, the list kernel for meshes, the contacts'
// finish, a vbd colour): their arguments and the per-ISA entry points.
// The reference is the shared kernel (engine/kernel/cloth_kernel.h, per particle in
// cpu_solver.cpp); row_kernel_avx2.cpp and row_kernel_avx512.cpp run the same kernel functions on
// 8 / 16 (float) particles per vector (row_kernel_simd.inl), each file compiled with its own -m flags
// and only called after __builtin_cpu_supports said yes.
#pragma once

#include <cstddef>
#include <cstdint>

#include "internal/kernel.hpp"
#include "kernel/constants.h" // VKCLOTH_RING_*

namespace vkcloth::detail {

/// A gather-list entry in the solver's precision (ClothTopology::edges() converted once).
template <typename Real> struct SolverEdge {
  std::uint32_t other;
  Real rest_length;
  Real stiffness;
  std::uint32_t ring; // VKCLOTH_RING_*
};

/// What the row and list kernels share: the state of the particles they update, and the body
/// forces' and the integration's constants.
template <typename Real> struct StepArgs {
  const Real* vel; // velocities, AoS (x, y, z) per particle; written when integrating
  Real* vel_out;   // == vel storage (in-place update), may be null when !integrate
  const Real* mass;
  const std::uint8_t* pinned;
  Real* force_out;  // AoS
  Real* normal_out; // AoS
  Real* pos_next;   // AoS, written when integrating
  Real gx, gy, gz, damping, kw, wx, wy, wz, dt;
  Real limit; // divergence limit (the SIMD kernels' finite check)
  bool wind, integrate, semi;
};

/// A grid's rows: the 12 stencil springs at constant offsets.
template <typename Real> struct RowArgs : StepArgs<Real> {
  const Real *px, *py, *pz;          // positions, SoA
  Real *sx_next, *sy_next, *sz_next; // next positions, SoA, written when integrating
  // Per-particle masks (null: every particle in [q0, q1) is interior): bit k (0..11) = stencil
  // spring k is in the particle's gather list, bit 12 + k (0..3) = normal fan term k is present.
  // Absent terms are skipped by the same select as `len > 0`, so a border particle gets the CSR
  // path's bits; its absent neighbours may lie outside [0, n): px, py, pz are padded.
  const std::uint16_t* mask;
  std::int64_t nx;
  const std::int64_t* off; // 12 stencil offsets
  const Real* rest;        // 12
  const Real* stiff;       // 12
};

/// Any other cloth (a mesh, a grid without a stencil): the gather lists, padded so that a vector of
/// W particles walks them together. Vector b holds particles [b W, b W + W); its spring slots are
/// [spring_begin[b], spring_begin[b + 1]), slot k of lane l at spring_begin[b] + k W + l, in the
/// particle's gather order. A lane with fewer springs than the longest list of its vector points
/// the rest at itself: a zero-length spring adds nothing (add_spring's `len > 0`), and its ring
/// bits are zero. The lists carry the normal fans (ClothTopology::ring_normals, `ring` per slot):
/// no lane has ring bits at or after slot ring_end[b]. Positions are read as they are stored (AoS);
/// reads_last[b] is set when some slot of vector b names the last particle.
template <typename Real> struct ListArgs : StepArgs<Real> {
  const Real* pos;
  const std::uint32_t* spring_begin;
  const std::uint32_t* other;
  const Real* rest;
  const Real* stiff;
  const std::uint32_t* ring;
  const std::uint32_t* ring_end;
  const std::uint8_t* reads_last;
};

/// The most colliders the SIMD finish takes (it converts them once per call into an array of this size).
inline constexpr std::uint32_t finish_max_shapes = 16;

/// A collider as the SIMD finish takes it: kernel::ColliderShape<Real>'s values, copied as they are
/// (cpu_solver.cpp), at most finish_max_shapes of them (more: the per-particle reference). A mesh
/// collider's lanes read their search entries and, where those miss, search lane by lane with the
/// scalar kernel: `mesh` and `scalar` are its hierarchy and its shape as that kernel takes them.
template <typename Real> struct FinishShape {
  std::uint32_t type;
  bool moving;
  Real a[3], b, c[3], ax[3], ay[3], az[3], velocity[3], spin[3], pivot[3], mu_k, mu_s;
  const kernel::MeshData* mesh;              // a mesh collider's; null for the other shapes
  const kernel::ColliderShape<Real>* scalar; // the same collider as the scalar kernel takes it
};

/// The rest of a grid substep after the row kernel's forces when there are colliders (the kernel
/// ran without integrating): CpuSolver::euler_finish for W particles at a time, i.e. each
/// collider's contact response on the velocity and the force (cloth_kernel.h collider_contact,
/// contact_response), the Euler update, then each collider's projection (project_out).
template <typename Real> struct FinishArgs {
  const Real *px, *py, *pz; // positions at the start of the substep, SoA
  Real* vel;                // velocities, AoS, updated in place
  Real* force;              // AoS: the kernel's forces in, the forces after contacts out
  const Real* mass;
  const std::uint8_t* pinned;
  Real* pos_next;                    // AoS
  Real *sx_next, *sy_next, *sz_next; // SoA
  const FinishShape<Real>* shapes;
  std::uint32_t shape_count;
  Real band, eps, dt; // 2 contact_epsilon, contact_epsilon, the substep
  bool both, semi;    // !contact_inward_only; semi-implicit Euler
};

/// One colour of a vbd sweep (CpuSolver::vbd_solve_colour), W of its particles per vector: each
/// takes vbd_step on its springs, walked in its gather list's order (a lane with fewer than the
/// longest list of its vector walks the rest as zero-length springs to itself, which add nothing:
/// vbd_add_spring's `len > 0`), then each collider's vbd_friction and project_out. Positions are read and
/// written in place: no two particles of a colour share a spring. Pinned particles are left as they are.
template <typename Real> struct VbdArgs {
  const std::uint32_t* order; // the colour's particles
  std::uint32_t particles;    // all of them (the last one's index: T::gather3 reads past it)
  Real* pos;                  // AoS, the iterate, updated in place
  Real* push;                 // AoS, out: the projection's move
  const Real* target;         // AoS, the inertia targets y
  const Real* start;          // AoS, the positions at the substep's start x0
  const Real* mass;
  const std::uint8_t* pinned;
  // The colour's gather lists padded per vector (as ListArgs'): vector v = vector0 + k / W holds
  // the particles order[k .. k + W), its slots [spring_begin[v], spring_begin[v + 1]).
  std::uint32_t vector0;
  const std::uint32_t* spring_begin;
  const std::uint32_t* other;
  const Real* rest;
  const Real* stiff;
  const std::uint8_t* reads_last;
  const FinishShape<Real>* shapes; // every collider at most finish_max_shapes
  std::uint32_t shape_count;
  Real eps, h, mu; // contact_epsilon, the substep, the damping
  // Self-contact's force and stiffness block per particle (AoS), added after the springs; null: none.
  const Real* contact_f = nullptr;
  const Real* contact_diag = nullptr;
  const Real* contact_off = nullptr;
};

/// The start of a vbd substep (CpuSolver::vbd_begin), W consecutive particles per vector: the normal
/// from the fan triangles (padded per vector like ListArgs' springs: a slot past a particle's fan has
/// fan_on 0 and adds nothing), the external force, the inertia target and the first guess projected
/// out of the colliders; a pinned particle's target and position are its start. Grids only (the
/// topology's fans; ring-ordered normals take the per-particle reference).
template <typename Real> struct VbdBeginArgs {
  const Real* start; // AoS: the positions at the substep's start x0
  const Real* vel;   // AoS: v0
  const Real* mass;
  const std::uint8_t* pinned;
  const std::uint32_t* fan_begin; // per vector: its slots [fan_begin[v], fan_begin[v + 1])
  const std::uint32_t* fan_a;     // per slot and lane: the triangle's corners
  const std::uint32_t* fan_b;
  const Real* fan_on;                 // 1 for a triangle, 0 for padding
  const std::uint8_t* fan_reads_last; // per vector: some slot names the last particle
  Real* normal;                       // AoS, out
  Real* target;                       // AoS, out: y
  Real* pos;                          // AoS, out: the first guess, projected
  const FinishShape<Real>* shapes;    // every collider at most finish_max_shapes
  std::uint32_t shape_count;
  Real gravity[3], wind_dir[3], kw, eps, h;
};

/// The end of a vbd substep (CpuSolver::vbd_finish), W consecutive particles per vector: each free
/// particle keeps the last sweep's position, takes vbd_velocity less its inward part (each collider's
/// contact_response without friction), is projected (project_out) and gets vbd_net_force; a pinned
/// one keeps its position and velocity, with no force.
template <typename Real> struct VbdFinishArgs {
  Real* pos;         // AoS: the last sweep's positions in, the step's out
  const Real* push;  // AoS: the last sweep's projection moves
  const Real* start; // AoS: the positions at the substep's start x0
  Real* vel;         // AoS: v0 in, v out
  Real* force;       // AoS, out
  const Real* mass;
  const std::uint8_t* pinned;
  const FinishShape<Real>* shapes; // every collider at most finish_max_shapes
  std::uint32_t shape_count;
  Real band, eps, h; // 2 contact_epsilon, contact_epsilon, the substep
  bool both;         // !contact_inward_only
};

// Each processes whole vectors from q0 and returns where it stopped (q1 minus the remainder, which
// the caller finishes through the per-particle reference). No finite check (the caller's).
std::int64_t finish_avx512(const FinishArgs<float>& a, std::int64_t q0, std::int64_t q1);
std::int64_t finish_avx512(const FinishArgs<double>& a, std::int64_t q0, std::int64_t q1);
std::int64_t finish_avx2(const FinishArgs<float>& a, std::int64_t q0, std::int64_t q1);
std::int64_t finish_avx2(const FinishArgs<double>& a, std::int64_t q0, std::int64_t q1);

// Each processes whole vectors from q0 and returns where it stopped (q1 minus the remainder,
// fewer than one vector, which the caller runs through the per-particle reference). When integrating, each
// also applies check_finite's test to the positions and velocities it wrote and sets `bad` if one
// fails (it never clears it); without integrating the caller checks after finishing the particles.
std::int64_t row_kernel_avx512(const RowArgs<float>& a, std::int64_t q0, std::int64_t q1, bool& bad);
std::int64_t row_kernel_avx512(const RowArgs<double>& a, std::int64_t q0, std::int64_t q1, bool& bad);
std::int64_t row_kernel_avx2(const RowArgs<float>& a, std::int64_t q0, std::int64_t q1, bool& bad);
std::int64_t row_kernel_avx2(const RowArgs<double>& a, std::int64_t q0, std::int64_t q1, bool& bad);

// Each runs the vectors [v0, v1) of ListArgs (particles [v0 W, v1 W)), with the same finite check.
std::int64_t list_kernel_avx512(const ListArgs<float>& a, std::int64_t v0, std::int64_t v1, bool& bad);
std::int64_t list_kernel_avx512(const ListArgs<double>& a, std::int64_t v0, std::int64_t v1, bool& bad);
std::int64_t list_kernel_avx2(const ListArgs<float>& a, std::int64_t v0, std::int64_t v1, bool& bad);
std::int64_t list_kernel_avx2(const ListArgs<double>& a, std::int64_t v0, std::int64_t v1, bool& bad);

// Each runs the colour's particles [k0, k1) in whole vectors and returns where it stopped (k1 minus
// the remainder, which the caller steps through the per-particle reference).
std::int64_t vbd_colour_avx512(const VbdArgs<float>& a, std::int64_t k0, std::int64_t k1);
std::int64_t vbd_colour_avx512(const VbdArgs<double>& a, std::int64_t k0, std::int64_t k1);
std::int64_t vbd_colour_avx2(const VbdArgs<float>& a, std::int64_t k0, std::int64_t k1);
std::int64_t vbd_colour_avx2(const VbdArgs<double>& a, std::int64_t k0, std::int64_t k1);
// Each begins the whole vectors of particles [q0, q1) (q0 a multiple of W) and returns where it stopped.
std::int64_t vbd_begin_avx512(const VbdBeginArgs<float>& a, std::int64_t q0, std::int64_t q1);
std::int64_t vbd_begin_avx512(const VbdBeginArgs<double>& a, std::int64_t q0, std::int64_t q1);
std::int64_t vbd_begin_avx2(const VbdBeginArgs<float>& a, std::int64_t q0, std::int64_t q1);
std::int64_t vbd_begin_avx2(const VbdBeginArgs<double>& a, std::int64_t q0, std::int64_t q1);
// Each finishes the whole vectors of particles [q0, q1) and returns where it stopped.
std::int64_t vbd_finish_avx512(const VbdFinishArgs<float>& a, std::int64_t q0, std::int64_t q1);
std::int64_t vbd_finish_avx512(const VbdFinishArgs<double>& a, std::int64_t q0, std::int64_t q1);
std::int64_t vbd_finish_avx2(const VbdFinishArgs<float>& a, std::int64_t q0, std::int64_t q1);
std::int64_t vbd_finish_avx2(const VbdFinishArgs<double>& a, std::int64_t q0, std::int64_t q1);

} // namespace vkcloth::detail
