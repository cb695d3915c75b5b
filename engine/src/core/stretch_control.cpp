// SPDX-License-Identifier: MIT
// CpuSolver's stretch control after each substep (docs/model.md "Stretch control"): the tethers,
// Provot's sweeps or the fast projection (strain_projection.cpp), then the colliders' projection.
#include <atomic>
#include <utility>

#include "cpu_solver_impl.hpp"
#include "internal/kernel.hpp"
#include "thread_pool.hpp"
#include "vkcloth/cpu_solver.hpp"

namespace vkcloth {

// The tethers first (anchors are pinned: every particle's tethers are independent of the
// others'), then Provot's sweeps (one colour at a time: its links share no particle, so they are
// projected in parallel with the same result as in order), so that the structural springs get
// the last word; or, for method projection, the fast projection after the tethers
// (strain_projection.cpp);
// then the colliders' projection, since a correction may have pulled a particle into one. Each
// formula: cloth_kernel.h; the GPU: strain_finish.comp, strain_links.comp, strain_project.comp.
template <typename Real> void CpuSolver<Real>::Impl::limit_stretch(const Real h) {
  const StretchLimit& sl = params_.stretch_limit;
  const Real max_strain = Real(sl.max_strain);
  // The row sweep's SoA copy of the positions (when valid) follows every move, so the next sweep
  // need not transpose the whole state again.
  const std::size_t stride = pos_.size() + 2 * soa_pad_;
  Real* const soa = soa_valid_ ? soa_.data() + soa_pad_ : nullptr;
  auto moved = [&](std::size_t q) {
    if (!soa)
      return;
    soa[q] = pos_[q].x;
    soa[stride + q] = pos_[q].y;
    soa[2 * stride + q] = pos_[q].z;
  };
  if (strain_links_.empty() && !topology_->strain_links().empty())
    for (const StrainLink& l : topology_->strain_links())
      strain_links_.push_back(Link{l.a, l.b, Real(l.rest_length)});
  if (sl.tethers()) {
    if (tethers_.empty() || tether_kind_ != sl.tether_distance) {
      tethers_.clear();
      for (const Tether& t : topology_->tethers(sl.tether_distance))
        tethers_.push_back(TetherSlot{t.anchor, Real(t.rest_length)});
      tether_kind_ = sl.tether_distance;
    }
    pool_->for_each(pos_.size(), [&](std::size_t p) {
      for (std::uint32_t k = 0; !pinned_[p] && k < tethers_per_particle; ++k) {
        const TetherSlot& t = tethers_[p * tethers_per_particle + k];
        if (t.anchor == no_tether)
          break;
        Vec3 d;
        if (kernel::tether_move(pos_[p], pos_[t.anchor], kernel::stretch_bound(t.rest_length, max_strain),
                                d)) {
          kernel::apply_correction(pos_[p], vel_[p], d, h);
          moved(p);
        }
      }
    });
  }
  // A sweep that moves no link leaves every link within its bound, so the sweeps after it would
  // move none either: stopping there gives the same bits as running them all (as the GPU does).
  std::atomic<bool> corrected{true};
  auto project = [&](const Link& l) { // Provot's correction of one link (strain_links.comp's)
    Vec3 da, db;
    if (!kernel::provot_link(pos_[l.a], pos_[l.b], pinned_[l.a] != 0, pinned_[l.b] != 0,
                             kernel::stretch_bound(l.rest_length, max_strain), da, db))
      return false;
    kernel::apply_correction(pos_[l.a], vel_[l.a], da, h);
    kernel::apply_correction(pos_[l.b], vel_[l.b], db, h);
    moved(l.a);
    moved(l.b);
    return true;
  };
  if (sl.chains() && strain_chains_.empty())
    for (const StrainLink& l : topology_->strain_chains())
      strain_chains_.push_back(Link{l.a, l.b, Real(l.rest_length)});
  const std::span<const std::uint32_t> colours = topology_->strain_colour_offsets();
  const StrainChainShape chains = topology_->strain_chain_shape();
  for (std::uint32_t it = 0; sl.provot() && it < sl.iterations && corrected.load(std::memory_order_relaxed);
       ++it) {
    corrected.store(false, std::memory_order_relaxed);
    if (sl.chains()) { // the rows, then the columns: each chain forward and back, in parallel
      const std::pair<std::uint32_t, std::uint32_t> families[] = {{chains.rows, chains.row_links},
                                                                  {chains.columns, chains.column_links}};
      // A task takes `block` chains and steps them together, link i of each before link i + 1 of
      // any: each chain's links keep their order (the same bits), and the chains' independent
      // corrections overlap in the core where one chain alone waits on each link's square root.
      constexpr std::size_t block = 8;
      std::size_t first = 0;
      for (const auto& [count, length] : families) {
        pool_->for_each((count + block - 1) / block, [&](std::size_t t) {
          const std::size_t k0 = t * block, k1 = std::min<std::size_t>(k0 + block, count);
          const Link* chains0 = strain_chains_.data() + first;
          bool any = false;
          for (std::uint32_t i = 0; i < length; ++i)
            for (std::size_t k = k0; k < k1; ++k)
              any = project(chains0[k * length + i]) || any;
          for (std::uint32_t i = length; i-- > 0;)
            for (std::size_t k = k0; k < k1; ++k)
              any = project(chains0[k * length + i]) || any;
          if (any)
            corrected.store(true, std::memory_order_relaxed);
        });
        first += std::size_t(count) * length;
      }
      continue;
    }
    for (std::size_t c = 0; c + 1 < colours.size(); ++c)
      pool_->for_each(colours[c + 1] - colours[c], [&](std::size_t k) {
        if (project(strain_links_[colours[c] + k]))
          corrected.store(true, std::memory_order_relaxed);
      });
  }
  if (sl.projection()) {
    project_strain(h);
    soa_valid_ = false; // the next row sweep transposes the moved positions
  }
  if (!params_.colliders.empty())
    pool_->for_each(pos_.size(), [&](std::size_t p) {
      if (!pinned_[p]) {
        project_at(p, pos_[p], pos_[p], vel_[p]);
        moved(p);
      }
    });
  swept_finite_ = false; // the moves are checked with the rest of the state (check_finite)
}

template void CpuSolver<float>::Impl::limit_stretch(float);
template void CpuSolver<double>::Impl::limit_stretch(double);

} // namespace vkcloth
