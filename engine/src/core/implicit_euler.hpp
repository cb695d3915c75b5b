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
// direction; the preconditioner is the diagonal of A (Jacobi).
//
// Matrix-free: A y is a gather over SpringAdjacency in the force order, with the per-entry K_s
// computed once per step. Dot products are summed sequentially in particle order (deterministic;
// the GPU sums them in a fixed tree, so the two agree to rounding, not bit for bit).
//
// CG (x0 = 0):   r = S b, z = P^-1 r, d = z;  while |r|^2 > tol^2 |S b|^2 and it < max:
//                  q = S A d; alpha = r.z / d.q; x += alpha d; r -= alpha q; z = P^-1 r;
//                  beta = r.z_new / r.z; d = z + beta d
// (the loop also stops if d.q <= 0, which an SPD A only gives at d = 0).
// Contacts: f and v are contact-filtered as in the explicit step before b is built; after the
// solve the inward normal part of v' is removed for particles in contact (the outward part is
// kept unless contact_inward_only is false), then x' = x + h v' is projected as usual.
#pragma once

#include "kernel.hpp"

#include <array>
#include <vector>

#include <glm/vec3.hpp>

namespace vkcloth::detail {

template <typename Real> struct ImplicitWorkspace {
  using Vec3 = glm::vec<3, Real, glm::defaultp>;
  /// Per CSR entry: the spring's stiffness block K_s (cloth_kernel.h spring_block).
  std::vector<kernel::SpringBlock<Real>> ks;
  std::vector<Vec3> vf;       ///< contact-filtered velocity
  std::vector<Vec3> diag_inv; ///< 1 / diag(A), zero for pinned particles (the filter S)
  std::vector<Vec3> x, r, z, d, q;
};

} // namespace vkcloth::detail
