// SPDX-License-Identifier: MIT
// CpuSolver's implicit Euler substep (the method: implicit_euler.hpp). Float expressions are
// written in the order shaders/implicit_*.comp use.
#include "implicit_euler.hpp"

#include <algorithm>
#include <cmath>

#include "thread_pool.hpp"
#include "cpu_solver_impl.hpp"
#include "vkcloth/cpu_solver.hpp"

namespace vkcloth {
namespace {

template <typename Real, typename V> Real dot_all(const std::vector<V>& a, const std::vector<V>& b) {
  Real s = Real(0);
  for (std::size_t p = 0; p < a.size(); ++p)
    s += kernel::dot3(a[p], b[p]); // particle order: deterministic
  return s;
}

} // namespace

// The phases of one implicit substep (the method: implicit_euler.hpp). Each parallel sweep writes
// only particle p's entries; the dot products are sequential, in particle order.
template <typename Real> void CpuSolver<Real>::Impl::implicit_substep(const Real h) {
  const std::size_t n = pos_.size();
  if (!implicit_)
    implicit_ = std::make_unique<detail::ImplicitWorkspace<Real>>();
  auto& w = *implicit_;
  if (w.x.size() != n) {
    w.ks.assign(edges_.size(), {});
    w.block_inv.assign(n, {});
    for (auto* v : {&w.vf, &w.fc, &w.x, &w.b, &w.axis, &w.r, &w.z, &w.d, &w.q})
      v->assign(n, Vec3(0)); // x = 0: the first solve starts cold
  }
  // 1. Forces and contact filtering as in the explicit step.
  pool_->for_each(pos_.size(), [&](std::size_t p) {
    Vec3 f = normal_force_at(pos_, vel_, p);
    const Vec3 unfiltered = f;
    Vec3 v = vel_[p];
    if (!pinned_[p]) // friction once, on the new velocity (implicit_update)
      contact_at(p, pos_[p], v, f, h / mass_[p], false);
    force_[p] = f;
    w.vf[p] = v;
    w.fc[p] = unfiltered - f;
    w.axis[p] = pinned_[p] ? Vec3(0) : kernel::contact_axis(vel_[p] - v, w.fc[p], h / mass_[p]);
    w.x[p] = kernel::constrain_to(w.x[p], w.axis[p]); // the warm start within the constraint
  });
  implicit_system(h);
  implicit_cg(h);
  implicit_update(h);
}

// 2. Per-entry K_s, the block-Jacobi preconditioner, b = h (f - h L v) filtered, and the warm
// start's residual r = b - S A x0 (x0: the previous dv, read-only here); z = P^-1 r, d = z.
template <typename Real> void CpuSolver<Real>::Impl::implicit_system(const Real h) {
  auto& w = *implicit_;
  const Real mu_h = Real(1) + h * Real(params_.damping); // M - h D = (1 + h mu) M
  const Real h2 = h * h;
  pool_->for_each(pos_.size(), [&](std::size_t p) {
    const Vec3 x = pos_[p];
    const Vec3 vp = w.vf[p];
    const Vec3 x0 = w.x[p];
    Vec3 lv(0);
    Vec3 lx(0);
    kernel::SpringBlock<Real> ksum{Vec3(0), Vec3(0)};
    for (std::uint32_t e = edge_offsets_[p]; e < edge_offsets_[p + 1]; ++e) {
      const Edge& s = edges_[e];
      const auto k = kernel::spring_block(pos_[s.other] - x, s.rest_length, s.stiffness);
      w.ks[e] = k;
      lv += kernel::apply_block(k, vp - w.vf[s.other]);
      lx += kernel::apply_block(k, x0 - w.x[s.other]);
      kernel::add_block(ksum, k);
    }
    if (pinned_[p]) {
      w.block_inv[p] = {Vec3(0), Vec3(0)};
      w.b[p] = w.r[p] = w.z[p] = w.d[p] = Vec3(0);
      return;
    }
    const Vec3 a = w.axis[p];
    w.block_inv[p] = kernel::invert_block(kernel::implicit_diagonal_block(mu_h, mass_[p], ksum, h2));
    w.b[p] = kernel::constrain_to(kernel::implicit_rhs(force_[p], lv, h), a);
    w.r[p] = kernel::constrain_to(
        kernel::residual_of(w.b[p], kernel::implicit_row(x0, mu_h, mass_[p], lx, h2)), a);
    w.z[p] = kernel::constrain_to(kernel::apply_block(w.block_inv[p], w.r[p]), a);
    w.d[p] = w.z[p];
  });
}

// 3. Preconditioned CG on the filtered system; records the iterations and residual in solve_.
template <typename Real> void CpuSolver<Real>::Impl::implicit_cg(const Real h) {
  auto& w = *implicit_;
  const Real mu_h = Real(1) + h * Real(params_.damping);
  const Real h2 = h * h;
  const Real bb = dot_all<Real>(w.b, w.b);
  const Vec3 g{params_.gravity};
  Real ww = Real(0); // |S h M g|^2, summed in particle order
  for (std::size_t p = 0; p < pos_.size(); ++p)
    if (!pinned_[p])
      ww += kernel::weight_impulse2(h, mass_[p], g);
  const Real ref2 = std::max(bb, ww);
  Real rr = dot_all<Real>(w.r, w.r);
  if (!(rr <= bb)) { // the warm start is worse than none (or not finite): start from dv = 0
    pool_->for_each(pos_.size(), [&](std::size_t p) {
      w.x[p] = Vec3(0);
      w.r[p] = w.b[p];
      w.z[p] = w.d[p] = kernel::constrain_to(kernel::apply_block(w.block_inv[p], w.b[p]), w.axis[p]);
    });
    rr = bb;
  }
  Real rz = dot_all<Real>(w.r, w.z);
  const Real tol2 = Real(params_.cg_tolerance) * Real(params_.cg_tolerance);
  std::uint32_t it = 0;
  while (it < params_.cg_max_iterations && !(rr <= tol2 * ref2)) {
    pool_->for_each(pos_.size(), [&](std::size_t p) { // q = S A d
      if (pinned_[p]) {
        w.q[p] = Vec3(0);
        return;
      }
      const Vec3 dp = w.d[p];
      Vec3 s(0);
      for (std::uint32_t e = edge_offsets_[p]; e < edge_offsets_[p + 1]; ++e)
        s += kernel::apply_block(w.ks[e], dp - w.d[edges_[e].other]);
      w.q[p] = kernel::constrain_to(kernel::implicit_row(dp, mu_h, mass_[p], s, h2), w.axis[p]);
    });
    const Real dq = dot_all<Real>(w.d, w.q);
    if (!(dq > Real(0)))
      break;
    const Real alpha = rz / dq;
    pool_->for_each(pos_.size(), [&](std::size_t p) {
      w.x[p] += w.d[p] * alpha;
      w.r[p] -= w.q[p] * alpha;
      w.z[p] = kernel::constrain_to(kernel::apply_block(w.block_inv[p], w.r[p]), w.axis[p]);
    });
    const Real rz_new = dot_all<Real>(w.r, w.z);
    rr = dot_all<Real>(w.r, w.r);
    const Real beta = rz_new / rz;
    rz = rz_new;
    ++it;
    if (rr <= tol2 * ref2)
      break; // converged: d is not needed any more
    pool_->for_each(pos_.size(), [&](std::size_t p) { w.d[p] = w.z[p] + w.d[p] * beta; });
  }
  solve_.iterations = it;
  solve_.residual = ref2 > Real(0) ? std::sqrt(double(rr) / double(ref2)) : 0.0;
  solve_.total_iterations += it;
  ++solve_.solves;
}

// 4. v' = v + dv, the inward part removed in contact; x' = x + h v', projected. Only particle p's
// own state is read here, so the update is in place.
template <typename Real> void CpuSolver<Real>::Impl::implicit_update(const Real h) {
  auto& w = *implicit_;
  pool_->for_each(pos_.size(), [&](std::size_t p) {
    if (pinned_[p])
      return; // stays put, velocity zero
    Vec3 v = w.vf[p] + w.x[p];
    // The inward normal part of v' (the whole part if !inward_only) and friction, whose normal
    // impulse also counts the force the filter removed before the solve (w.fc: e.g. the weight of
    // a cloth resting on a table, which the solve never saw).
    Vec3 removed = w.fc[p];
    contact_at(p, pos_[p], v, removed, h / mass_[p]);
    Vec3 x = pos_[p] + v * h;
    project_at(p, pos_[p], x, v);
    pos_[p] = x;
    vel_[p] = v;
  });
}

template void CpuSolver<float>::Impl::implicit_substep(float);
template void CpuSolver<double>::Impl::implicit_substep(double);
template void CpuSolver<float>::Impl::implicit_system(float);
template void CpuSolver<double>::Impl::implicit_system(double);
template void CpuSolver<float>::Impl::implicit_cg(float);
template void CpuSolver<double>::Impl::implicit_cg(double);
template void CpuSolver<float>::Impl::implicit_update(float);
template void CpuSolver<double>::Impl::implicit_update(double);

} // namespace vkcloth
