// SPDX-License-Identifier: MIT
// Self-collision on the CPU (CpuSolver::self_collide; docs/model.md "Self-collision"): the spatial
// hash as a counting sort of the particles by bucket (in index order, so each bucket's particles
// come in increasing index, the order the GPU's sort pass gives), then Jacobi passes of
// cloth_kernel.h self_collide, the walk the GPU's COLLIDE pass runs too (self_collision.comp); with
// a skin, the neighbour lists (self_build_lists, when stale) and self_collide_listed; with vbd's
// energy, the lists before the sweeps and each sweep's contact forces (self_energy_*).
#include <algorithm>
#include <atomic>
#include <limits>

#include "internal/kernel.hpp"
#include "internal/self_collision.hpp"
#include "thread_pool.hpp"
#include "cpu_solver_impl.hpp"
#include "vkcloth/cpu_solver.hpp"

namespace vkcloth {

template <typename Real> void CpuSolver<Real>::Impl::self_collide() {
  const SelfCollision& sc = params_.self_collision;
  const std::size_t n = pos_.size();
  self_init();
  auto& g = *self_;
  const std::uint32_t mask = g.mask;
  const detail::SelfConstants<Real> k = detail::self_constants<Real>(sc);
  g.dx.resize(n);
  g.dv.resize(n);
  const bool lists = k.half_skin2 > Real(0); // the GPU's test (a skin so small it is 0 keeps none)
  kernel::SelfDataT<Real> data{};            // the table's arrays, once built
  auto collide = [&](std::size_t p) {
    if (pinned_[p])
      g.dx[p] = g.dv[p] = Vec3(0);
    else if (lists)
      kernel::self_collide_listed(data, std::uint32_t(p), g.listed[p], g.key[p], pos_[p], vel_[p],
                                  g.inv_mass[p], g.rest[p], k.thickness, mask, k.friction, g.dx[p], g.dv[p]);
    else
      kernel::self_collide(data, std::uint32_t(p), pos_[p], vel_[p], g.inv_mass[p], g.rest[p], k.thickness,
                           k.inv_cell, mask, k.friction, g.dx[p], g.dv[p]);
  };

  if (!lists)
    self_hash(k.inv_cell);
  for (std::uint32_t it = 0; it < sc.iterations; ++it) {
    if (lists && self_list_stale(k))
      self_build_lists(k);
    data = self_data();
    ++g.stats.passes;
    pool_->for_each(n, collide);
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

// The workspace, made by the first substep with self-collision on.
template <typename Real> void CpuSolver<Real>::Impl::self_init() {
  if (self_)
    return;
  const std::size_t n = pos_.size();
  self_ = std::make_unique<detail::SelfCollisionGrid<Real>>();
  const ParticleSystem& system = topology_->system();
  for (std::size_t p = 0; p < n; ++p) {
    self_->rest.push_back(Vec3(system.particles[p].position));
    self_->inv_mass.push_back(kernel::inverse_mass(mass_[p], pinned_[p] != 0));
  }
  self_->built.assign(n, Vec3(std::numeric_limits<Real>::quiet_NaN()));
  self_->listed.assign(n, 0);
  self_->list.assign(n * VKCLOTH_SELF_LIST_CAPACITY, 0);
  self_->mask = kernel::self_table_size(static_cast<std::uint32_t>(n)) - 1;
}

template <typename Real> bool CpuSolver<Real>::Impl::self_energy() const {
  return detail::self_contact_energy<Real>(params_);
}

// vbd's self-contact energy: the lists at the first guesses (built again when stale), before the sweeps.
template <typename Real> void CpuSolver<Real>::Impl::self_energy_lists() {
  self_init();
  const auto k = detail::self_constants<Real>(params_.self_collision);
  if (self_list_stale(k))
    self_build_lists(k);
}

// Each particle's self-contact force and stiffness from the positions the sweep starts from (a
// snapshot: a colour's steps do not see each other's moves through a contact, as through a spring),
// the GPU's CONTACT pass.
template <typename Real> void CpuSolver<Real>::Impl::self_energy_sweep(const Real h) {
  auto& g = *self_;
  auto& w = *vbd_;
  const std::size_t n = pos_.size();
  const auto k = detail::self_constants<Real>(params_.self_collision);
  w.contact_f.resize(n);
  w.contact_diag.resize(n);
  w.contact_off.resize(n);
  kernel::SelfDataT<Real> data = self_data();
  data.step_start = w.x0.data(); // the friction's slips
  pool_->for_each(n, [&](std::size_t p) {
    kernel::SpringBlock<Real> hc{Vec3(0), Vec3(0)};
    Vec3 fc(0);
    if (!pinned_[p])
      kernel::self_energy_listed(data, std::uint32_t(p), g.listed[p], g.key[p], pos_[p], pos_[p] - w.x0[p],
                                 g.rest[p], k.thickness, g.mask, k.stiffness, k.friction, h, fc, hc);
    w.contact_f[p] = fc;
    w.contact_diag[p] = hc.diag;
    w.contact_off[p] = hc.off;
  });
  ++g.stats.passes;
}

// What the kernel's walks read: the table, the lists and the particles' state, in place.
template <typename Real> kernel::SelfDataT<Real> CpuSolver<Real>::Impl::self_data() {
  auto& g = *self_;
  kernel::SelfDataT<Real> d{g.start.data(), g.sorted.data(),   g.key.data(),  pos_.data(),
                            vel_.data(),    g.inv_mass.data(), g.rest.data(), g.list.data()};
  d.sorted_key = g.sorted_key.data();
  return d;
}

// The hash table of the positions now, cells of 1 / inv_cell: count per bucket, exclusive prefix
// sums, then the particles in index order (the order the GPU's SORT pass gives each bucket).
template <typename Real> void CpuSolver<Real>::Impl::self_hash(const Real inv_cell) {
  auto& g = *self_;
  const std::size_t n = pos_.size();
  const std::uint32_t mask = g.mask, table = mask + 1;
  g.start.assign(std::size_t(table) + 1, 0);
  g.key.resize(n);
  g.sorted.resize(n);
  for (std::size_t p = 0; p < n; ++p) {
    g.key[p] = kernel::self_key(pos_[p], inv_cell); // self_bucket takes no real: either precision
    ++g.start[std::size_t(kernel::f32::self_bucket(g.key[p], mask)) + 1];
  }
  for (std::size_t b = 0; b < table; ++b)
    g.start[b + 1] += g.start[b];
  g.fill.assign(g.start.begin(), g.start.end() - 1);
  for (std::size_t p = 0; p < n; ++p)
    g.sorted[g.fill[kernel::f32::self_bucket(g.key[p], mask)]++] = static_cast<std::uint32_t>(p);
  g.sorted_key.resize(n);
  for (std::size_t i = 0; i < n; ++i)
    g.sorted_key[i] = g.key[g.sorted[i]];
}

// Whether some particle has moved more than half the skin since the lists were built (or they
// never were, or were built for another reach or thickness): the GPU's CHECK pass.
template <typename Real> bool CpuSolver<Real>::Impl::self_list_stale(const detail::SelfConstants<Real>& k) {
  const auto& g = *self_;
  if (!(g.built_reach2 == k.reach2 && g.built_thickness == k.thickness))
    return true;
  const Real half_skin2 = k.half_skin2;
  std::atomic<bool> stale{false};
  pool_->parallel_for(pos_.size(), [&](std::size_t begin, std::size_t end) {
    for (std::size_t p = begin; p < end; ++p)
      if (kernel::self_moved(pos_[p], g.built[p], half_skin2)) {
        stale.store(true, std::memory_order_relaxed);
        return;
      }
  });
  return stale.load();
}

// The hash of cells of the reach (thickness + skin), then each particle's list of the candidates
// within the reach (its 27 cells' walk), and where each particle is now: the GPU's COUNT .. LIST.
template <typename Real> void CpuSolver<Real>::Impl::self_build_lists(const detail::SelfConstants<Real>& k) {
  auto& g = *self_;
  self_hash(k.inv_cell);
  const std::size_t n = pos_.size();
  g.entry_pos.resize(n);
  g.entry_rest.resize(n);
  for (std::size_t i = 0; i < n; ++i) {
    g.entry_pos[i] = pos_[g.sorted[i]];
    g.entry_rest[i] = g.rest[g.sorted[i]];
  }
  kernel::SelfDataT<Real> data = self_data();
  data.entry_pos = g.entry_pos.data(); // the table's particles in its order, as it was built
  data.entry_rest = g.entry_rest.data();
  pool_->for_each(pos_.size(), [&](std::size_t p) {
    g.listed[p] = kernel::self_gather(data, std::uint32_t(p), g.key[p], pos_[p], g.rest[p], k.thickness,
                                      k.reach2, k.inv_cell, g.mask);
    g.built[p] = pos_[p];
  });
  g.built_reach2 = k.reach2;
  g.built_thickness = k.thickness;
  ++g.stats.builds;
  g.stats.candidates = g.stats.overflowed = 0;
  for (const std::uint32_t listed : g.listed) {
    g.stats.candidates += listed;
    g.stats.overflowed += listed > VKCLOTH_SELF_LIST_CAPACITY ? 1 : 0;
  }
}

template void CpuSolver<float>::Impl::self_collide();
template void CpuSolver<double>::Impl::self_collide();
template void CpuSolver<float>::Impl::self_init();
template void CpuSolver<double>::Impl::self_init();
template bool CpuSolver<float>::Impl::self_energy() const;
template bool CpuSolver<double>::Impl::self_energy() const;
template void CpuSolver<float>::Impl::self_energy_lists();
template void CpuSolver<double>::Impl::self_energy_lists();
template void CpuSolver<float>::Impl::self_energy_sweep(float);
template void CpuSolver<double>::Impl::self_energy_sweep(double);
template kernel::SelfDataT<float> CpuSolver<float>::Impl::self_data();
template kernel::SelfDataT<double> CpuSolver<double>::Impl::self_data();
template void CpuSolver<float>::Impl::self_hash(float);
template void CpuSolver<double>::Impl::self_hash(double);
template bool CpuSolver<float>::Impl::self_list_stale(const detail::SelfConstants<float>&);
template bool CpuSolver<double>::Impl::self_list_stale(const detail::SelfConstants<double>&);
template void CpuSolver<float>::Impl::self_build_lists(const detail::SelfConstants<float>&);
template void CpuSolver<double>::Impl::self_build_lists(const detail::SelfConstants<double>&);

} // namespace vkcloth
