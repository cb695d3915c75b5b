// SPDX-License-Identifier: MIT
// CpuSolver's vertex block descent substep (docs/model.md "Vertex block descent"; each formula:
// engine/kernel/vbd.h). The GPU runs the same phases in the same order (shaders/vbd.comp):
//   begin:   normals and external forces at the substep's start, the inertia targets y, and the
//            first guess (vbd_first_guess: x0 + h v0) projected out of the colliders;
//   sweeps:  `vbd_iterations` times, the colours in order; each particle of a colour takes one Newton
//            step on its springs, its inertia and the colliders' friction, from its neighbours'
//            latest positions, and is projected out of the colliders (no two particles of a colour
//            share a spring, so a colour runs in parallel with the result of running it in order);
//   finish:  the last sweep's position x; v = (x - x0) / h from its position before the projection,
//            less its inward part (the contact response without friction).
#include <algorithm>

#include "cpu_solver_impl.hpp"
#include "thread_pool.hpp"

namespace vkcloth {

template <typename Real> void CpuSolver<Real>::Impl::vbd_substep(const Real h) {
  vbd_begin(h);
  const bool contact = self_energy(); // self-contact as an energy in the steps (self_collision.cpp)
  if (contact)
    self_energy_lists();
  const std::uint32_t colours = std::uint32_t(topology_->vertex_colour_offsets().size()) - 1;
  for (std::uint32_t it = 0; it < params_.vbd_iterations; ++it) {
    if (contact)
      self_energy_sweep(h);
    for (std::uint32_t c = 0; c < colours; ++c)
      vbd_solve_colour(c, h, contact);
  }
  vbd_finish(h);
  solve_.iterations = params_.vbd_iterations;
  solve_.residual = 0.0;
  solve_.total_iterations += params_.vbd_iterations;
  ++solve_.solves;
}

template <typename Real> void CpuSolver<Real>::Impl::vbd_begin(const Real h) {
  const std::size_t n = pos_.size();
  if (!vbd_)
    vbd_ = std::make_unique<detail::VbdWorkspace<Real>>();
  auto& w = *vbd_;
  w.x0 = pos_;
  w.y.resize(n);
  w.push.assign(n, Vec3(0));
  const Real kw = Real(params_.wind.strength);
  const Vec3 g{params_.gravity}, wind_dir{params_.wind.direction};
  auto begin_one = [&](std::size_t p) {
    normal_at(w.x0, p); // the normal at the start (wind; what a host observes)
    const Vec3 f_ext = kernel::add_body_forces(Vec3(0), mass_[p], Vec3(0), g, Real(0), kw != Real(0),
                                               normal_[p], wind_dir, kw);
    if (pinned_[p]) {
      w.y[p] = w.x0[p];
      return;
    }
    w.y[p] = kernel::vbd_inertia_target(w.x0[p], vel_[p], f_ext, mass_[p], h);
    Vec3 x = kernel::vbd_first_guess(w.x0[p], vel_[p], h), unused(0); // out of the colliders
    project_at(p, w.x0[p], x, unused);
    pos_[p] = x;
  };
  const std::size_t width = vbd_lane_width();
  if (width > 1 && !topology_->ring_normals() && w.fan_width != width)
    pad_vbd_fans(width);
  // One pass: the normals read the start (x0), so writing the first guesses into pos_ races nothing.
  pool_->parallel_for(n, [&](std::size_t begin, std::size_t end) {
    std::size_t p = begin;
    if (w.fan_width == width && width > 1) { // to a whole vector, then whole vectors on the lanes
      for (const std::size_t aligned = std::min(end, (begin + width - 1) / width * width); p < aligned; ++p)
        begin_one(p);
      p = vbd_begin_lanes(p, end, h);
    }
    for (; p < end; ++p)
      begin_one(p);
  });
}

template <typename Real> std::size_t CpuSolver<Real>::Impl::vbd_lane_width() const {
  if (simd_ == 0 || contacts_->finish.size() != contacts_->shapes.size())
    return 1;
  return (simd_ == 2 ? 64 : 32) / sizeof(Real);
}

// The begin's whole vectors of consecutive particles from q0 (a multiple of the width) on the lanes;
// returns where they stopped.
template <typename Real>
std::size_t CpuSolver<Real>::Impl::vbd_begin_lanes(const std::size_t q0, const std::size_t q1, const Real h) {
#if VKCLOTH_ROW_SIMD
  auto& w = *vbd_;
  const glm::dvec3 g = params_.gravity, wind = params_.wind.direction;
  const detail::VbdBeginArgs<Real> a{&w.x0[0].x,
                                     &vel_[0].x,
                                     mass_.data(),
                                     pinned_.data(),
                                     w.fan_begin.data(),
                                     w.fan_a.data(),
                                     w.fan_b.data(),
                                     w.fan_on.data(),
                                     w.fan_reads_last.data(),
                                     &normal_[0].x,
                                     &w.y[0].x,
                                     &pos_[0].x,
                                     contacts_->finish.data(),
                                     std::uint32_t(contacts_->finish.size()),
                                     {Real(g.x), Real(g.y), Real(g.z)},
                                     {Real(wind.x), Real(wind.y), Real(wind.z)},
                                     Real(params_.wind.strength),
                                     Real(params_.contact_epsilon),
                                     h};
#if VKCLOTH_ROW_AVX512
  if (simd_ == 2)
    return std::size_t(detail::vbd_begin_avx512(a, std::int64_t(q0), std::int64_t(q1)));
#endif
  return std::size_t(detail::vbd_begin_avx2(a, std::int64_t(q0), std::int64_t(q1)));
#else
  (void)q1;
  (void)h;
  return q0;
#endif
}

// The fan triangles of each whole vector of `width` consecutive particles, padded to the vector's
// largest fan (fan_on 0 past a particle's own).
template <typename Real> void CpuSolver<Real>::Impl::pad_vbd_fans(const std::size_t width) {
  auto& w = *vbd_;
  const auto offsets = topology_->fan_offsets();
  const auto fans = topology_->fans();
  const std::size_t n = pos_.size();
  w.fan_begin.assign(1, 0);
  w.fan_a.clear();
  w.fan_b.clear();
  w.fan_on.clear();
  w.fan_reads_last.clear();
  for (std::size_t q = 0; q + width <= n; q += width) {
    std::uint32_t slots = 0;
    for (std::size_t p = q; p < q + width; ++p)
      slots = std::max(slots, offsets[p + 1] - offsets[p]);
    bool reads_last = false;
    for (std::uint32_t k = 0; k < slots; ++k)
      for (std::size_t p = q; p < q + width; ++p) {
        const bool has = k < offsets[p + 1] - offsets[p];
        const FanTriangle t = has ? fans[offsets[p] + k] : FanTriangle{std::uint32_t(p), std::uint32_t(p)};
        w.fan_a.push_back(t.a);
        w.fan_b.push_back(t.b);
        w.fan_on.push_back(has ? Real(1) : Real(0));
        reads_last = reads_last || t.a == n - 1 || t.b == n - 1;
      }
    w.fan_reads_last.push_back(reads_last);
    w.fan_begin.push_back(std::uint32_t(w.fan_a.size()));
  }
  w.fan_width = width;
}

template <typename Real>
void CpuSolver<Real>::Impl::vbd_solve_colour(const std::uint32_t colour, const Real h, const bool contact) {
  auto& w = *vbd_;
  const auto order = topology_->vertex_order();
  const std::uint32_t first = topology_->vertex_colour_offsets()[colour];
  const std::uint32_t count = topology_->vertex_colour_offsets()[colour + 1] - first;
  const Real mu = Real(params_.damping), band = Real(2) * Real(params_.contact_epsilon);
  auto step = [&](std::size_t k) {
    const std::uint32_t p = order[first + k];
    if (pinned_[p])
      return;
    const Vec3 x = pos_[p];
    Vec3 f(0);
    kernel::SpringBlock<Real> hessian{Vec3(0), Vec3(0)};
    for (std::uint32_t e = edge_offsets_[p]; e < edge_offsets_[p + 1]; ++e) {
      const Edge& s = edges_[e];
      kernel::vbd_add_spring(f, hessian, pos_[s.other] - x, s.rest_length, s.stiffness);
    }
    if (contact)
      kernel::vbd_add_contact(f, hessian, w.contact_f[p], {w.contact_diag[p], w.contact_off[p]});
    Vec3 stepped = kernel::vbd_step(x, w.y[p], w.x0[p], f, hessian, mass_[p], h, mu);
    const Real inertia = kernel::vbd_inertia_weight(mass_[p], h, mu);
    for (std::size_t c = 0; c < contacts_->shapes.size(); ++c)
      kernel::vbd_friction(stepped, mesh_of(c, p), contacts_->shapes[c], x, w.x0[p], hessian, inertia, band,
                           h);
    Vec3 projected = stepped, unused(0);
    project_at(p, w.x0[p], projected, unused);
    w.push[p] = projected - stepped;
    pos_[p] = projected;
  };
  const std::size_t simd_end = vbd_colour_lanes(colour, order.subspan(first, count), h, contact);
  if (simd_end > 0) // fewer than one vector left: here, not another fork-join
    for (std::size_t k = simd_end; k < count; ++k)
      step(k);
  else
    pool_->for_each(count, step);
}

// Whole vectors of a colour on SIMD lanes (the kernel's functions on lanes), when the lanes take the
// colliders (at most detail::finish_max_shapes). The first call pads every colour's gather lists.
template <typename Real>
std::size_t CpuSolver<Real>::Impl::vbd_colour_lanes(std::uint32_t colour,
                                                    std::span<const std::uint32_t> particles, const Real h,
                                                    const bool contact) {
#if VKCLOTH_ROW_SIMD
  const std::size_t width = vbd_lane_width();
  if (width == 1)
    return 0;
  auto& w = *vbd_;
  if (!w.lists || w.lists->width != width)
    pad_vbd_lists(width);
  const detail::PaddedLists<Real>& l = *w.lists;
  const std::size_t end = particles.size() - particles.size() % width;
  detail::VbdArgs<Real> a{particles.data(),
                          std::uint32_t(pos_.size()),
                          &pos_[0].x,
                          &w.push[0].x,
                          &w.y[0].x,
                          &w.x0[0].x,
                          mass_.data(),
                          pinned_.data(),
                          w.colour_vector[colour],
                          l.spring_begin.data(),
                          l.other.data(),
                          l.rest.data(),
                          l.stiff.data(),
                          l.reads_last.data(),
                          contacts_->finish.data(),
                          std::uint32_t(contacts_->finish.size()),
                          Real(params_.contact_epsilon),
                          h,
                          Real(params_.damping)};
  if (contact) {
    a.contact_f = &w.contact_f[0].x;
    a.contact_diag = &w.contact_diag[0].x;
    a.contact_off = &w.contact_off[0].x;
  }
  pool_->for_each(end / width, [&](std::size_t b) {
    const std::int64_t k0 = std::int64_t(b * width), k1 = k0 + std::int64_t(width);
#if VKCLOTH_ROW_AVX512
    if (simd_ == 2) {
      (void)detail::vbd_colour_avx512(a, k0, k1);
      return;
    }
#endif
    (void)detail::vbd_colour_avx2(a, k0, k1);
  });
  return end;
#else
  (void)colour;
  (void)particles;
  (void)h;
  (void)contact;
  return 0;
#endif
}

// Each colour's whole vectors of `width` particles, in the colour's order, padded (pad_vector).
template <typename Real> void CpuSolver<Real>::Impl::pad_vbd_lists(const std::size_t width) {
  auto& w = *vbd_;
  w.lists = std::make_unique<detail::PaddedLists<Real>>();
  w.lists->width = width;
  w.colour_vector.clear();
  const auto order = topology_->vertex_order();
  const auto offsets = topology_->vertex_colour_offsets();
  for (std::size_t c = 0; c + 1 < offsets.size(); ++c) {
    w.colour_vector.push_back(std::uint32_t(w.lists->reads_last.size()));
    for (std::uint32_t k = offsets[c]; k + width <= offsets[c + 1]; k += std::uint32_t(width))
      detail::pad_vector(*w.lists, order.subspan(k, width), edge_offsets_, topology_->fan_ends(), edges_);
  }
}

template <typename Real> void CpuSolver<Real>::Impl::vbd_finish(const Real h) {
  auto& w = *vbd_;
  auto finish = [&](std::size_t p) {
    if (pinned_[p]) {
      force_[p] = Vec3(0);
      return; // stays put with its velocity
    }
    const Vec3 x0 = w.x0[p];
    Vec3 x = pos_[p]; // where the sweeps left it: out of the colliders, friction included
    Vec3 v = kernel::vbd_velocity(x, w.push[p], x0, h);
    Vec3 no_force(0);
    contact_at(p, x, v, no_force, h / mass_[p], false); // friction acted in the sweeps
    project_at(p, x0, x, v);
    force_[p] = kernel::vbd_net_force(v, vel_[p], mass_[p], h);
    pos_[p] = x;
    vel_[p] = v;
  };
  pool_->parallel_for(pos_.size(), [&](std::size_t begin, std::size_t end) {
    std::size_t p = begin;
#if VKCLOTH_ROW_SIMD
    if (vbd_lane_width() > 1) { // whole vectors on lanes
      const detail::VbdFinishArgs<Real> a{&pos_[0].x,
                                          &w.push[0].x,
                                          &w.x0[0].x,
                                          &vel_[0].x,
                                          &force_[0].x,
                                          mass_.data(),
                                          pinned_.data(),
                                          contacts_->finish.data(),
                                          std::uint32_t(contacts_->finish.size()),
                                          Real(2) * Real(params_.contact_epsilon),
                                          Real(params_.contact_epsilon),
                                          h,
                                          !params_.contact_inward_only};
#if VKCLOTH_ROW_AVX512
      if (simd_ == 2)
        p = std::size_t(detail::vbd_finish_avx512(a, std::int64_t(begin), std::int64_t(end)));
      else
#endif
        p = std::size_t(detail::vbd_finish_avx2(a, std::int64_t(begin), std::int64_t(end)));
    }
#endif
    for (; p < end; ++p)
      finish(p);
  });
}

template void CpuSolver<float>::Impl::vbd_substep(float);
template void CpuSolver<double>::Impl::vbd_substep(double);

} // namespace vkcloth
