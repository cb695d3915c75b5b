// SPDX-License-Identifier: MIT
// Stretch control by fast projection on the CPU (CpuSolver::project_strain; docs/model.md
// "Stretch control"): Newton iterations, each a Jacobi-preconditioned CG over the links in the
// solve, in the phases strain_project.comp runs (LINKS, then GATHER -> MATVEC -> UPDATE ->
// DIRECTION per CG iteration, then APPLY), each formula from cloth_kernel.h, and each sum in the
// order the shader's workgroup takes it (workgroup_sums), so that lavapipe gives the CPU's bits.
#include <algorithm>
#include <array>
#include <utility>

#include "internal/kernel.hpp"
#include "strain_projection.hpp"
#include "thread_pool.hpp"
#include "cpu_solver_impl.hpp"
#include "vkcloth/cpu_solver.hpp"

namespace vkcloth {
namespace {

// Two sums over `count` terms (term(i) gives the pair) as strain_project.comp's workgroup takes
// them: lane l adds terms l, l + W, l + 2 W, ... in turn, then a tree halves the lanes.
template <typename Real, typename Term> std::pair<Real, Real> workgroup_sums(std::size_t count, Term term) {
  constexpr std::size_t W = VKCLOTH_WORKGROUP_SIZE;
  std::array<Real, W> a{}, b{};
  for (std::size_t i = 0; i < count; ++i) {
    const auto [x, y] = term(i);
    a[i % W] = a[i % W] + x;
    b[i % W] = b[i % W] + y;
  }
  for (std::size_t s = W / 2; s > 0; s >>= 1)
    for (std::size_t l = 0; l < s; ++l) {
      a[l] = a[l] + a[l + s];
      b[l] = b[l] + b[l + s];
    }
  return {a[0], b[0]};
}

} // namespace

template <typename Real> void CpuSolver<Real>::Impl::project_strain(const Real h) {
  const StretchLimit& sl = params_.stretch_limit;
  const std::span<const StrainLink> links = topology_->strain_links();
  const std::span<const std::uint32_t> offsets = topology_->strain_incidence_offsets();
  const std::span<const std::uint32_t> incidence = topology_->strain_incidence();
  const std::size_t n = pos_.size(), m = links.size();
  const Real max_strain = Real(sl.max_strain); // set_params may change it: the bounds are not kept
  if (!projection_) {
    projection_ = std::make_unique<detail::StrainProjection<Real>>();
    auto& w = *projection_;
    w.g.resize(m);
    for (auto* v : {&w.c, &w.inv_diag, &w.lambda, &w.r, &w.d, &w.q, &w.z})
      v->assign(m, Real(0));
    w.u.resize(n);
    w.inv_mass.resize(n);
  }
  auto& w = *projection_;
  for (std::size_t p = 0; p < n; ++p) // as the GPU computes them (cloth_kernel.h inverse_mass)
    w.inv_mass[p] = kernel::inverse_mass(mass_[p], pinned_[p] != 0);
  const Real c_tolerance = kernel::projection_c_tolerance(max_strain);
  const std::uint32_t cg_cap = kernel::projection_cg_cap(m);
  // GATHER: each particle's grad C^T s over its links, s = d (the CG) or lambda (APPLY).
  auto gather = [&](const std::vector<Real>& s) {
    pool_->for_each(n, [&](std::size_t p) {
      Vec3 u(0);
      for (std::uint32_t k = offsets[p]; k < offsets[p + 1]; ++k)
        kernel::projection_gather(u, w.g[incidence[k] >> 1], s[incidence[k] >> 1], (incidence[k] & 1u) != 0);
      w.u[p] = u;
    });
  };
  for (std::uint32_t newton = 0; newton < sl.iterations; ++newton) {
    // LINKS: each link's constraint, whether it is in the solve, and the CG's start (lambda = 0).
    pool_->for_each(m, [&](std::size_t i) {
      const StrainLink& l = links[i];
      const Real bound = kernel::stretch_bound(Real(l.rest_length), max_strain);
      const Real c = kernel::projection_constraint(pos_[l.a], pos_[l.b], bound, w.g[i]);
      const bool kept = newton > 0 && w.lambda[i] > Real(0);
      w.inv_diag[i] = kernel::projection_inv_diag(c, kept, w.g[i], w.inv_mass[l.a], w.inv_mass[l.b]);
      w.r[i] = kernel::projection_rhs(c, w.inv_diag[i]);
      w.z[i] = w.d[i] = w.r[i] * w.inv_diag[i];
      w.lambda[i] = Real(0);
      w.c[i] = c;
    });
    const Real worst = m ? *std::max_element(w.c.begin(), w.c.end()) : Real(-1);
    auto [rz, rr] = workgroup_sums<Real>(
        m, [&](std::size_t i) { return std::pair<Real, Real>(w.r[i] * w.z[i], w.r[i] * w.r[i]); });
    if (!(worst > c_tolerance))
      break; // every link within the tolerance (or no link at all)
    const Real stop = Real(VKCLOTH_PROJECTION_CG_TOL2) * rr;
    for (std::uint32_t it = 0; it < cg_cap && rr > stop; ++it) {
      gather(w.d);
      pool_->for_each(m, [&](std::size_t i) { // MATVEC: q = A d
        const StrainLink& l = links[i];
        w.q[i] = kernel::projection_row(w.g[i], w.inv_mass[l.a], w.u[l.a], w.inv_mass[l.b], w.u[l.b],
                                        w.inv_diag[i]);
      });
      const Real dq = workgroup_sums<Real>(m, [&](std::size_t i) {
                        return std::pair<Real, Real>(w.d[i] * w.q[i], Real(0));
                      }).first;
      if (!(dq > Real(0)))
        break; // A is positive definite on the links in the solve: d = 0
      const Real alpha = rz / dq;
      pool_->for_each(m, [&](std::size_t i) { // UPDATE
        w.z[i] = kernel::projection_cg_update(w.lambda[i], w.r[i], w.d[i], w.q[i], alpha, w.inv_diag[i]);
      });
      const auto [rz_next, rr_next] = workgroup_sums<Real>(
          m, [&](std::size_t i) { return std::pair<Real, Real>(w.r[i] * w.z[i], w.r[i] * w.r[i]); });
      const Real beta = rz_next / rz;
      rr = rr_next;
      rz = rz_next;
      pool_->for_each(m, [&](std::size_t i) { w.d[i] = w.z[i] + beta * w.d[i]; }); // DIRECTION
    }
    gather(w.lambda); // APPLY: x -= W grad C^T lambda
    pool_->for_each(n, [&](std::size_t p) {
      if (!pinned_[p])
        kernel::apply_correction(pos_[p], vel_[p], kernel::projection_move(w.u[p], w.inv_mass[p]), h);
    });
  }
}

template void CpuSolver<float>::Impl::project_strain(float);
template void CpuSolver<double>::Impl::project_strain(double);

} // namespace vkcloth
