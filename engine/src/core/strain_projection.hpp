// SPDX-License-Identifier: MIT
// CpuSolver's fast-projection workspace (strain_projection.cpp).
#pragma once

#include <cstdint>
#include <vector>

#include <glm/vec3.hpp>

namespace vkcloth::detail {

/// Per link and per particle state of the fast projection (StretchLimit::Method::projection), made
/// by its first substep.
template <typename Real> struct StrainProjection {
  using Vec3 = glm::vec<3, Real>;
  std::vector<Real> inv_mass;                     // per particle, this substep's (0: pinned)
  std::vector<Vec3> g;                            // per link: dC/dxb
  std::vector<Real> c;                            // per link: its constraint C (kernel projection_constraint)
  std::vector<Real> inv_diag, lambda, r, d, q, z; // per link: the CG's (inv_diag 0: not in the solve)
  std::vector<Vec3> u;                            // per particle: the gather of d, or of lambda
};

} // namespace vkcloth::detail
