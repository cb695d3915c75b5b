// SPDX-License-Identifier: MIT
// Self-collision on the CPU (CpuSolver::self_collide; docs/model.md "Self-collision"): the spatial
// hash as a counting sort of the particles by bucket (in index order, so each bucket's particles
// come in increasing index, the order the GPU's sort pass gives), then Jacobi passes of
// cloth_kernel.h self_collide, the walk the GPU's COLLIDE pass runs too (self_collision.comp).
#include <algorithm>

#include "kernel.hpp"
#include "self_collision.hpp"
#include "thread_pool.hpp"
#include "cpu_solver_impl.hpp"
#include "vkcloth/cpu_solver.hpp"

namespace vkcloth {

template <typename Real> void CpuSolver<Real>::Impl::self_collide() {
  const SelfCollision& sc = params_.self_collision;
  const std::size_t n = pos_.size();
  if (!self_) {
    self_ = std::make_unique<detail::SelfCollisionGrid<Real>>();
    const ParticleSystem& system = topology_->system();
    for (std::size_t p = 0; p < n; ++p) {
      self_->rest.push_back(Vec3(system.particles[p].position));
      self_->inv_mass.push_back(kernel::inverse_mass(mass_[p], pinned_[p] != 0));
    }
  }
  auto& g = *self_;
  const std::uint32_t table = kernel::self_table_size(static_cast<std::uint32_t>(n)), mask = table - 1;
  // The same conversions as the GPU's host side (SelfCollisionGpu::packed).
  const Real thickness = Real(sc.thickness), inv_cell = Real(1.0 / sc.thickness), mu = Real(sc.friction);

  // The table: count per bucket, exclusive prefix sums, then the particles in index order.
  g.start.assign(std::size_t(table) + 1, 0);
  g.key.resize(n);
  g.sorted.resize(n);
  g.dx.resize(n);
  g.dv.resize(n);
  for (std::size_t p = 0; p < n; ++p) {
    g.key[p] = kernel::self_key(pos_[p], inv_cell); // self_bucket takes no real: either precision
    ++g.start[std::size_t(kernel::f32::self_bucket(g.key[p], mask)) + 1];
  }
  for (std::size_t b = 0; b < table; ++b)
    g.start[b + 1] += g.start[b];
  g.fill.assign(g.start.begin(), g.start.end() - 1);
  for (std::size_t p = 0; p < n; ++p)
    g.sorted[g.fill[kernel::f32::self_bucket(g.key[p], mask)]++] = static_cast<std::uint32_t>(p);

  for (std::uint32_t it = 0; it < sc.iterations; ++it) {
    const kernel::SelfDataT<Real> data{g.start.data(), g.sorted.data(),   g.key.data(), pos_.data(),
                                       vel_.data(),    g.inv_mass.data(), g.rest.data()};
    pool_->for_each(n, [&](std::size_t p) {
      if (pinned_[p])
        g.dx[p] = g.dv[p] = Vec3(0);
      else
        kernel::self_collide(data, static_cast<std::uint32_t>(p), pos_[p], vel_[p], g.inv_mass[p], g.rest[p],
                             thickness, inv_cell, mask, mu, g.dx[p], g.dv[p]);
    });
    pool_->for_each(n, [&](std::size_t p) {
      if (!pinned_[p])
        kernel::self_apply(pos_[p], vel_[p], g.dx[p], g.dv[p]);
    });
  }
  if (!params_.colliders.empty()) // a move may have pushed a particle into a collider
    pool_->for_each(n, [&](std::size_t p) {
      if (!pinned_[p])
        project_at(p, pos_[p], pos_[p], vel_[p]);
    });
  soa_valid_ = false;
  swept_finite_ = false; // checked with the rest of the state (check_finite)
}

template void CpuSolver<float>::Impl::self_collide();
template void CpuSolver<double>::Impl::self_collide();

} // namespace vkcloth
