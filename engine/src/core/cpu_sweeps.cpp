// SPDX-License-Identifier: MIT
// CpuSolver's explicit Euler sweeps in SIMD: the grid's row kernel (a stencil) and the list kernel
// (meshes, chains), each one fork-join per substep with the finite check folded in. The kernels
// themselves: row_kernel.hpp; the per-particle reference they fall back to: cpu_solver.cpp.
#include <algorithm>
#include <cmath>
#include <memory>

#include "cpu_solver_impl.hpp"
#include "thread_pool.hpp"

namespace vkcloth {

using detail::bad_components;
using detail::RowArgs;

// The state and constants both SIMD kernels take.
template <typename Real>
void CpuSolver<Real>::Impl::step_args(detail::StepArgs<Real>& a, const Real h, const bool semi) {
  a.vel = &vel_[0].x;
  a.vel_out = &vel_[0].x;
  a.mass = mass_.data();
  a.pinned = pinned_.data();
  a.force_out = &force_[0].x;
  a.normal_out = &normal_[0].x;
  a.pos_next = &pos_next_[0].x;
  const Vec3 g{params_.gravity}, w{params_.wind.direction};
  a.gx = g.x;
  a.gy = g.y;
  a.gz = g.z;
  a.damping = Real(params_.damping);
  a.kw = Real(params_.wind.strength);
  a.wind = a.kw != Real(0);
  a.wx = w.x;
  a.wy = w.y;
  a.wz = w.z;
  a.dt = h;
  a.limit = Real(params_.divergence_limit);
  a.integrate = params_.colliders.empty(); // the SIMD kernels have no contact code
  a.semi = semi;
}

template <typename Real>
detail::RowArgs<Real> CpuSolver<Real>::Impl::row_args(const Real h, const bool semi) {
  const std::size_t n = pos_.size(), pad = soa_pad_, stride = n + 2 * pad;
  if (soa_.size() != 3 * stride) {
    soa_.assign(3 * stride, Real(0));
    soa_next_.assign(3 * stride, Real(0));
    soa_valid_ = false;
  }
  RowArgs<Real> ra{};
  ra.px = soa_.data() + pad;
  ra.py = ra.px + stride;
  ra.pz = ra.py + stride;
  if (!soa_valid_) { // first step, or pos_ changed outside the row sweep
    Real *sx = soa_.data() + pad, *sy = sx + stride, *sz = sy + stride;
    pool_->parallel_for(n, [&](std::size_t b, std::size_t e) {
      for (std::size_t p = b; p < e; ++p) {
        sx[p] = pos_[p].x;
        sy[p] = pos_[p].y;
        sz[p] = pos_[p].z;
      }
    });
  }
  ra.sx_next = soa_next_.data() + pad;
  ra.sy_next = ra.sx_next + stride;
  ra.sz_next = ra.sy_next + stride;
  ra.mask = stencil_->masks.empty() ? nullptr : stencil_->masks.data();
  ra.nx = topology_->grid()->nx;
  ra.off = stencil_offset_.data();
  ra.rest = stencil_rest_.data();
  ra.stiff = stencil_stiff_.data();
  step_args(ra, h, semi);
  return ra;
}

// Grid stencil: the vectorised row kernel takes every particle (masks for the border), or, when
// some gather list is irregular (no masks), the interior runs of each row while the border
// particles take the per-particle reference. It reads positions from the SoA copy and writes the
// next one; one fork-join per substep (sweep + finite check).
template <typename Real> void CpuSolver<Real>::Impl::row_sweep(const Real h, const bool semi) {
  const RowArgs<Real> ra = row_args(h, semi);
  // With colliders, none of them a mesh: the kernel's forces go through the SIMD finish (contacts,
  // update, projection: row_kernel_simd.inl simd_finish), the remainders through euler_finish.
  detail::FinishArgs<Real> fa{};
  const bool simd_finish = !ra.integrate && simd_ != 0 && !contacts_->finish.empty();
  if (simd_finish) {
    fa.px = ra.px;
    fa.py = ra.py;
    fa.pz = ra.pz;
    fa.vel = &vel_[0].x;
    fa.force = &force_[0].x;
    fa.mass = mass_.data();
    fa.pinned = pinned_.data();
    fa.pos_next = &pos_next_[0].x;
    fa.sx_next = ra.sx_next;
    fa.sy_next = ra.sy_next;
    fa.sz_next = ra.sz_next;
    fa.shapes = contacts_->finish.data();
    fa.shape_count = static_cast<std::uint32_t>(contacts_->finish.size());
    fa.band = Real(2) * Real(params_.contact_epsilon); // contact_at's band and project_at's eps
    fa.eps = Real(params_.contact_epsilon);
    fa.dt = h;
    fa.both = !params_.contact_inward_only;
    fa.semi = semi;
  }
  const std::int64_t gnx = ra.nx, gny = topology_->grid()->ny;
  Real* const pn = &pos_next_[0].x;
  Real* const vn = &vel_[0].x;
  // The reference's update of particle q, and its entry in the next SoA copy.
  auto finish = [&](std::int64_t q, Vec3 f) {
    euler_finish(std::size_t(q), f, h, semi);
    const Vec3 x = pos_next_[std::size_t(q)];
    ra.sx_next[q] = x.x;
    ra.sy_next[q] = x.y;
    ra.sz_next[q] = x.z;
  };
  // Whole vectors in SIMD, a remainder shorter than one vector (or everything, without SIMD)
  // through the per-particle reference; then the finite check of what the SIMD kernel did not check.
  auto run = [&](std::int64_t q0, std::int64_t q1, unsigned& bad_here) {
    std::int64_t done = q0;
    bool simd_bad = false;
#if VKCLOTH_ROW_SIMD
    if (simd_ == 1)
      done = detail::row_kernel_avx2(ra, done, q1, simd_bad);
#if VKCLOTH_ROW_AVX512
    else if (simd_ == 2)
      done = detail::row_kernel_avx512(ra, done, q1, simd_bad);
#endif
#endif
    std::int64_t unchecked = done;
    if (!ra.integrate) { // the SIMD kernels' forces go through the contacts here
      std::int64_t finished = q0;
#if VKCLOTH_ROW_SIMD
      if (simd_finish)
#if VKCLOTH_ROW_AVX512
        finished = simd_ == 2 ? detail::finish_avx512(fa, q0, done) : detail::finish_avx2(fa, q0, done);
#else
        finished = detail::finish_avx2(fa, q0, done);
#endif
#endif
      for (std::int64_t q = finished; q < done; ++q)
        finish(q, force_[std::size_t(q)]);
      unchecked = q0;
    }
    for (std::int64_t q = done; q < q1; ++q)
      finish(q, normal_force_at(pos_, vel_, std::size_t(q)));
    bad_here |= unsigned(simd_bad) | bad_components(pn + 3 * unchecked, vn + 3 * unchecked,
                                                    std::size_t(3 * (q1 - unchecked)), ra.limit);
  };
  std::atomic<bool> bad{false};
  // Claimed in blocks of ~2048 particles by whichever thread is free (a thread the OS delays holds
  // up at most one block); within one, pieces of ~1024: finish() and the check read what the
  // kernel just wrote.
  pool_->parallel_blocks(pos_.size(), 2048, [&](std::size_t b, std::size_t e) {
    constexpr std::size_t block = 1024;
    unsigned bad_here = 0;
    for (std::size_t b0 = b; b0 < e;) {
      const std::size_t b1 = e - b0 < 2 * block ? e : b0 + block;
      if (ra.mask) {
        run(std::int64_t(b0), std::int64_t(b1), bad_here);
      } else {
        for (std::size_t p = b0; p < b1;) {
          const std::int64_t j = std::int64_t(p) / gnx, i = std::int64_t(p) % gnx;
          if (j >= 2 && j + 2 < gny && i >= 2 && i + 2 < gnx) { // an interior run of row j
            const std::size_t run_end = std::min<std::size_t>(b1, std::size_t(j * gnx + gnx - 2));
            run(std::int64_t(p), std::int64_t(run_end), bad_here);
            p = run_end;
            continue;
          }
          finish(std::int64_t(p), normal_force_at(pos_, vel_, p));
          bad_here |= bad_components(pn + 3 * p, vn + 3 * p, 3, ra.limit);
          ++p;
        }
      }
      b0 = b1;
    }
    if (bad_here)
      bad.store(true, std::memory_order_relaxed);
  });
  std::swap(pos_, pos_next_);
  std::swap(soa_, soa_next_);
  soa_valid_ = true;
  swept_finite_ = !bad.load(std::memory_order_relaxed);
}

namespace {
// The gather lists padded for vectors of `width` particles (row_kernel.hpp ListArgs): the
// particles that fill whole vectors only; the rest take the per-particle reference.
template <typename Real, typename Edge>
std::unique_ptr<detail::PaddedLists<Real>>
pad_lists(std::size_t width, std::span<const std::uint32_t> edge_offsets,
          std::span<const std::uint32_t> fan_ends, const std::vector<Edge>& edges) {
  auto lists = std::make_unique<detail::PaddedLists<Real>>();
  lists->width = width;
  const std::size_t vectors = (edge_offsets.size() - 1) / width;
  std::vector<std::uint32_t> particles(width);
  for (std::size_t b = 0; b < vectors; ++b) {
    for (std::size_t l = 0; l < width; ++l)
      particles[l] = std::uint32_t(b * width + l);
    detail::pad_vector(*lists, std::span<const std::uint32_t>(particles), edge_offsets, fan_ends, edges);
  }
  return lists;
}
} // namespace

// Without a stencil (meshes): the list kernel takes whole vectors of particles, the last few the
// per-particle reference; with colliders the kernel's forces go through euler_finish. One
// fork-join per substep (sweep + finite check), as in row_sweep.
template <typename Real> void CpuSolver<Real>::Impl::list_sweep(const Real h, const bool semi) {
  const std::size_t n = pos_.size(), width = (simd_ == 2 ? 64 : 32) / sizeof(Real);
  if (!lists_ || lists_->width != width)
    lists_ = pad_lists<Real>(width, edge_offsets_, topology_->fan_ends(), edges_);
  const detail::PaddedLists<Real>& l = *lists_;
  detail::ListArgs<Real> la{};
  step_args(la, h, semi);
  la.pos = &pos_[0].x;
  la.spring_begin = l.spring_begin.data();
  la.other = l.other.data();
  la.rest = l.rest.data();
  la.stiff = l.stiff.data();
  la.ring = l.ring.data();
  la.ring_end = l.ring_end.data();
  la.reads_last = l.reads_last.data();
  const std::size_t vectors = n / width;
  Real* const pn = &pos_next_[0].x;
  Real* const vn = &vel_[0].x;
  std::atomic<bool> bad{false};
  // Work in units of one vector (the last unit: the particles after the last whole vector).
  pool_->parallel_blocks(
      vectors + (n % width != 0), std::max<std::size_t>(1, 2048 / width), [&](std::size_t b, std::size_t e) {
        const std::size_t q0 = b * width, qv = std::min(e, vectors) * width, q1 = std::min(e * width, n);
        bool simd_bad = false;
#if VKCLOTH_ROW_SIMD
        if (qv > q0)
#if VKCLOTH_ROW_AVX512
          (void)(simd_ == 2 ? detail::list_kernel_avx512(la, b, qv / width, simd_bad)
                            : detail::list_kernel_avx2(la, b, qv / width, simd_bad));
#else
          (void)detail::list_kernel_avx2(la, b, qv / width, simd_bad);
#endif
#endif
        std::size_t unchecked = qv;
        if (!la.integrate) { // the forces through the contacts, update, projection
          for (std::size_t q = q0; q < qv; ++q)
            euler_finish(q, force_[q], h, semi);
          unchecked = q0;
        }
        for (std::size_t q = std::max(q0, qv); q < q1; ++q)
          euler_finish(q, normal_force_at(pos_, vel_, q), h, semi);
        if (simd_bad || bad_components(pn + 3 * unchecked, vn + 3 * unchecked,
                                       3 * (q1 - std::min(unchecked, q1)), la.limit))
          bad.store(true, std::memory_order_relaxed);
      });
  std::swap(pos_, pos_next_);
  swept_finite_ = !bad.load(std::memory_order_relaxed);
}

template void CpuSolver<float>::Impl::step_args(detail::StepArgs<float>&, float, bool);
template void CpuSolver<double>::Impl::step_args(detail::StepArgs<double>&, double, bool);
template detail::RowArgs<float> CpuSolver<float>::Impl::row_args(float, bool);
template detail::RowArgs<double> CpuSolver<double>::Impl::row_args(double, bool);
template void CpuSolver<float>::Impl::row_sweep(float, bool);
template void CpuSolver<double>::Impl::row_sweep(double, bool);
template void CpuSolver<float>::Impl::list_sweep(float, bool);
template void CpuSolver<double>::Impl::list_sweep(double, bool);

} // namespace vkcloth
