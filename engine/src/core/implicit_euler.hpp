// SPDX-License-Identifier: MIT
// Implicit (backward) Euler for the CPU reference solver (Baraff & Witkin 1998, "Large steps in
// cloth simulation"), linearised once per (sub)step:
//
//   (M - h^2 J - h D) dv = h (f + h J v),   v' = v + dv,   x' = x + h v'
//
// J = df/dx of the springs, D = -mu M the fluid damping (so M - h D = (1 + h mu) M). Each spring's
// block uses only the positive semi-definite part of its stiffness matrix (the compressive term
// is dropped):  K_s = k [u u^T + max(0, 1 - L0/|u|) (I - u u^T)]  (u the unit spring direction),
// J_pp = -sum K_s, J_pq = +K_s, so A = (1 + h mu) M + h^2 L with L positive semi-definite: A is
// symmetric positive definite and CG converges. Pinned particles: Baraff-Witkin's filter S
// (S_p = 0 for a pinned p, I otherwise) applied to the right-hand side, every residual and search
// direction. Preconditioner: block Jacobi, P = the 3x3 diagonal blocks A_pp (cloth_kernel.h
// invert_block), which also sees the off-diagonal couplings of a spring at an angle.
//
// Matrix-free: A y is a gather over SpringAdjacency in the force order, with the per-entry K_s
// computed once per step. Dot products are summed sequentially in particle order (deterministic;
// the GPU sums them in a fixed tree, so the two agree to rounding, not bit for bit).
//
// CG, warm-started from the previous solve's dv (x0; zero on the first solve, and whenever the
// warm start's residual is larger than b itself, e.g. after an impact):
//                r = S (b - A x0), z = P^-1 r, d = z;  while |r|^2 > tol^2 ref^2 and it < max:
//                  q = S A d; alpha = r.z / d.q; x += alpha d; r -= alpha q; z = P^-1 r;
//                  beta = r.z_new / r.z; d = z + beta d
// (the loop also stops if d.q <= 0, which an SPD A only gives at d = 0).
// The tolerance is relative to ref = max(|S b|, |S h M g|): the right-hand side, or the weight
// impulse of the free particles when that is larger. Near equilibrium b tends to zero (forces
// balance, v -> 0), and a tolerance relative to b alone asks for ever more digits of a dv that
// is itself ~0: the stiff 48 x 48 cloth spent 200 iterations per step (the cap) on corrections
// below 1e-7 m. ref does not depend on x0, so a good warm start saves iterations instead of
// tightening the test.
// Contacts: f and v are contact-filtered as in the explicit step before b is built; after the
// solve the inward normal part of v' is removed for particles in contact (the outward part is
// kept unless contact_inward_only is false), then x' = x + h v' is projected as usual.
#pragma once

#include "internal/kernel.hpp"

#include <array>
#include <vector>

#include <glm/vec3.hpp>

namespace vkcloth::detail {

template <typename Real> struct ImplicitWorkspace {
  using Vec3 = glm::vec<3, Real, glm::defaultp>;
  /// Per CSR entry: the spring's stiffness block K_s (cloth_kernel.h spring_block).
  std::vector<kernel::SpringBlock<Real>> ks;
  std::vector<Vec3> vf; ///< contact-filtered velocity
  /// The force the contact filter removed (F - filtered F): friction's normal impulse after the solve.
  std::vector<Vec3> fc;
  /// P^-1: the inverse of A's diagonal block, zero for pinned particles (the filter S).
  std::vector<kernel::SpringBlock<Real>> block_inv;
  std::vector<Vec3> x; ///< dv: kept from one solve to the next (the warm start)
  std::vector<Vec3> b; ///< S b, for |S b| (the tolerance's reference) and a cold restart
  /// The contact axis each particle's unknowns lose (cloth_kernel.h contact_axis; zero: free).
  std::vector<Vec3> axis;
  std::vector<Vec3> r, z, d, q;
};

} // namespace vkcloth::detail
