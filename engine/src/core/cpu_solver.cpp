// SPDX-License-Identifier: MIT
#include "vkcloth/cpu_solver.hpp"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <thread>

#include <fmt/format.h>
#include <glm/geometric.hpp>

#include "implicit_euler.hpp"
#include "kernel.hpp"
#include "row_kernel.hpp"
#include "self_collision.hpp"
#include "strain_projection.hpp"
#include "thread_pool.hpp"

// Every per-particle formula comes from shaders/include/cloth_kernel.h (kernel.hpp), the source
// the compute shaders include too; this file gathers the inputs, loops and schedules. The engine
// is built with -ffp-contract=off, so the compiler does not fuse the kernel's expressions.

namespace vkcloth {

namespace detail {
/// The colliders as the kernel takes them at this substep's pose, and their meshes; the same values
/// for the SIMD finish of the grid rows (row_kernel.hpp FinishShape), empty when a collider is a mesh.
template <typename Real> struct ContactShapes {
  std::vector<kernel::ColliderShape<Real>> shapes;
  std::vector<kernel::MeshData> meshes;
  std::vector<FinishShape<Real>> finish;
};
/// The padded lists the list kernel reads (row_kernel.hpp ListArgs), built once for vectors of
/// `width` particles by pad_lists.
template <typename Real> struct PaddedLists {
  std::size_t width = 0;
  std::vector<std::uint32_t> spring_begin, other, ring, ring_end;
  std::vector<std::uint8_t> reads_last; ///< per vector: some slot names the last particle
  std::vector<Real> rest, stiff;
};
} // namespace detail

namespace {

using detail::RowArgs;

/// check_finite's test, branch-free (vectorisable OR-reduction over flat arrays of n3 components):
/// nonzero when a component is not finite (c - c != 0 for inf and NaN) or a position has |x| > limit
/// (or is NaN). The row sweep runs it on each block it wrote, check_finite on the whole state.
template <typename Real> unsigned bad_components(const Real* x, const Real* v, std::size_t n3, Real limit) {
  unsigned bad = 0;
  for (std::size_t i = 0; i < n3; ++i)
    bad |= unsigned(!(std::abs(x[i]) <= limit)) | unsigned(!(x[i] - x[i] == Real(0))) |
           unsigned(!(v[i] - v[i] == Real(0)));
  return bad;
}

/// Row kernel ISA: 2 = AVX-512F, 1 = AVX2, 0 = scalar; the widest the CPU has, capped by the
/// environment variable VKCLOTH_CPU_SIMD = scalar | avx2 | avx512 (tests compare them bitwise).
int detect_simd() {
  int best = 0;
#if VKCLOTH_ROW_SIMD
  __builtin_cpu_init();
  if (__builtin_cpu_supports("avx2"))
    best = 1;
  if (__builtin_cpu_supports("avx512f"))
    best = 2;
#endif
  if (const char* env = std::getenv("VKCLOTH_CPU_SIMD")) {
    if (std::strcmp(env, "scalar") == 0)
      best = 0;
    else if (std::strcmp(env, "avx2") == 0)
      best = std::min(best, 1);
  }
  return best;
}

} // namespace

template <typename Real> CpuSolver<Real>::CpuSolver() = default;
template <typename Real> CpuSolver<Real>::CpuSolver(CpuSolver&&) noexcept = default;
template <typename Real> CpuSolver<Real>& CpuSolver<Real>::operator=(CpuSolver&&) noexcept = default;
template <typename Real> CpuSolver<Real>::~CpuSolver() = default;
template <typename Real> unsigned CpuSolver<Real>::threads() const {
  return pool_->size();
}

template <typename Real>
Result<CpuSolver<Real>> CpuSolver<Real>::create(const ParticleSystem& system, SimParams params,
                                                CpuSolverOptions options) {
  VKCLOTH_TRY(params.validate());
  auto topology = ClothTopology::create(system);
  if (!topology)
    return topology.error();
  return create(std::move(*topology), std::move(params), options);
}

template <typename Real>
Result<CpuSolver<Real>> CpuSolver<Real>::create(std::shared_ptr<const ClothTopology> topology,
                                                SimParams params, CpuSolverOptions options) {
  if (!topology)
    return make_error(ErrorCode::invalid_argument, "CpuSolver::create: the topology is null");
  VKCLOTH_TRY(params.validate());
  if (options.threads > 256)
    return make_error(ErrorCode::invalid_argument,
                      fmt::format("threads must be at most 256, got {}", options.threads));
  const ParticleSystem& system = topology->system();
  const std::size_t n = system.size();

  CpuSolver s;
  s.topology_ = std::move(topology);
  s.params_ = params;
  s.edge_offsets_ = s.topology_->edge_offsets();
  s.edges_.reserve(s.topology_->edges().size());
  for (const GatherEdge& e : s.topology_->edges())
    s.edges_.push_back(Edge{e.other, Real(e.rest_length), Real(e.stiffness), e.ring});
  s.mass_.resize(n);
  s.pinned_.resize(n);
  s.pos_.resize(n);
  s.vel_.resize(n);
  for (std::size_t p = 0; p < n; ++p) {
    const Particle& q = system.particles[p];
    s.mass_[p] = Real(q.mass);
    s.pinned_[p] = q.pinned;
    s.pos_[p] = Vec3(q.position);
    s.vel_[p] = q.pinned ? Vec3(0) : Vec3(q.velocity);
  }
  s.force_.assign(n, Vec3(0));
  s.normal_.assign(n, Vec3(0));
  s.pos_next_ = s.pos_;
  if ((s.stencil_ = s.topology_->stencil())) {
    for (std::size_t k = 0; k < 12; ++k) {
      s.stencil_offset_[k] = s.stencil_->offset[k];
      s.stencil_rest_[k] = Real(s.stencil_->rest_length[k]);
      s.stencil_stiff_[k] = Real(s.stencil_->stiffness[k]);
    }
    s.soa_pad_ = s.stencil_->reach;
  }
  // Below ~1000 particles per thread the fork-join costs more than it saves.
  const unsigned wanted =
      options.threads ? options.threads : std::max(1u, std::thread::hardware_concurrency());
  const auto useful = static_cast<unsigned>(std::max<std::size_t>(1, n / 1024));
  s.pool_ = std::make_unique<detail::ThreadPool>(std::min(wanted, useful));
  s.simd_ = detect_simd();
  return s;
}

template <typename Real> Result<void> CpuSolver<Real>::set_params(SimParams params) {
  VKCLOTH_TRY(params.validate());
  params_ = params;
  return {};
}

template <typename Real>
Result<void> CpuSolver<Real>::set_particle(std::uint32_t index, Vec3 position, Vec3 velocity) {
  if (index >= pos_.size())
    return make_error(ErrorCode::invalid_argument,
                      fmt::format("set_particle: index {} is out of range (the system has {} particles)",
                                  index, pos_.size()));
  for (int k = 0; k < 3; ++k)
    if (!std::isfinite(position[k]) || !std::isfinite(velocity[k]))
      return make_error(
          ErrorCode::invalid_argument,
          fmt::format(
              "set_particle: particle {} position ({}, {}, {}) and velocity ({}, {}, {}) must be finite",
              index, position.x, position.y, position.z, velocity.x, velocity.y, velocity.z));
  pos_[index] = position;
  vel_[index] = pinned_[index] ? Vec3(0) : velocity;
  soa_valid_ = false;
  return {};
}

template <typename Real>
typename CpuSolver<Real>::Vec3 CpuSolver<Real>::normal_force_at(std::span<const Vec3> pos,
                                                                std::span<const Vec3> vel, std::size_t p) {
  const Vec3 x = pos[p];
  Vec3 f(0);
  Vec3 fan(0); // an area-weighted vertex normal (zero without a surface)
  bool interior = false;
  if (stencil_) {
    const std::size_t nx = topology_->grid()->nx, ny = topology_->grid()->ny;
    const std::size_t i = p % nx, j = p / nx;
    interior = i >= 2 && i + 2 < nx && j >= 2 && j + 2 < ny;
  }
  if (!topology_->ring_normals()) { // the topology's fan around p, in order
    const std::span<const std::uint32_t> fan_offsets = topology_->fan_offsets();
    const std::span<const FanTriangle> fans = topology_->fans();
    for (std::uint32_t t = fan_offsets[p]; t < fan_offsets[p + 1]; ++t)
      kernel::add_fan_triangle(fan, pos[fans[t].a] - x, pos[fans[t].b] - x);
  }
  if (interior) {
    // Same terms, same order as the CSR loop below (the topology's stencil detection checked it).
    for (std::size_t k = 0; k < 12; ++k)
      kernel::add_spring(f, x, pos[std::size_t(std::int64_t(p) + stencil_offset_[k])], stencil_rest_[k],
                         stencil_stiff_[k]);
  } else {
    Vec3 prev(0), first(0);
    for (std::uint32_t e = edge_offsets_[p]; e < edge_offsets_[p + 1]; ++e) {
      const Edge& s = edges_[e];
      const Vec3 u = pos[s.other] - x;
      kernel::add_spring_edge(f, u, s.rest_length, s.stiffness);
      kernel::add_ring_term(fan, prev, first, u, s.ring);
    }
  }
  normal_[p] = kernel::unit_or_zero(fan);
  const Real kw = Real(params_.wind.strength);
  return kernel::add_body_forces(f, mass_[p], vel[p], Vec3{params_.gravity}, Real(params_.damping),
                                 kw != Real(0), normal_[p], Vec3{params_.wind.direction}, kw);
}

// The colliders at their pose for this substep, as the kernel takes them (kernel_shape: the
// conversion the GPU solver uses too); a mesh collider's hierarchy is walked in place.
template <typename Real> void CpuSolver<Real>::prepare_colliders() {
  if (!contacts_)
    contacts_ = std::make_unique<detail::ContactShapes<Real>>();
  auto& shapes = contacts_->shapes;
  auto& meshes = contacts_->meshes;
  auto& finish = contacts_->finish;
  shapes.clear();
  meshes.clear();
  finish.clear();
  bool any_mesh = false;
  for (const Collider& c : params_.colliders) {
    shapes.push_back(kernel::kernel_shape<Real>(c));
    kernel::MeshData m;
    if (c.mesh) {
      m.nodes = c.mesh->nodes().data();
      m.triangles = c.mesh->triangles().data();
    }
    meshes.push_back(m);
    any_mesh = any_mesh || c.type == Collider::Type::mesh;
  }
  for (std::size_t k = 0; !any_mesh && k < shapes.size(); ++k) {
    const kernel::ColliderShape<Real>& s = shapes[k];
    auto put = [](Real* out, glm::vec<3, Real> v) {
      out[0] = v.x;
      out[1] = v.y;
      out[2] = v.z;
    };
    detail::FinishShape<Real> f{};
    f.type = s.type;
    f.moving = s.moving;
    put(f.a, s.a);
    f.b = s.b;
    put(f.c, s.c);
    put(f.ax, s.ax);
    put(f.ay, s.ay);
    put(f.az, s.az);
    put(f.velocity, s.velocity);
    put(f.spin, s.spin);
    put(f.pivot, s.pivot);
    f.mu_k = s.mu_k;
    f.mu_s = s.mu_s;
    finish.push_back(f);
  }
}

// Moving colliders advance by the substep h (in double, as the GPU solver's host side does).
template <typename Real> void CpuSolver<Real>::advance_colliders(double h) {
  for (Collider& c : params_.colliders)
    if (c.moving())
      c = c.posed_at(h);
}

template <typename Real>
void CpuSolver<Real>::contact_at(Vec3 pos, Vec3& vel, Vec3& force, Real h_over_m, bool friction) const {
  const Real band = Real(2) * Real(params_.contact_epsilon);
  const bool both = !params_.contact_inward_only; // Figure 12's variant: outward parts go too
  const auto& shapes = contacts_->shapes;
  for (std::size_t k = 0; k < shapes.size(); ++k) {
    kernel::ColliderShape<Real> s = shapes[k];
    if (!friction)
      s.mu_k = s.mu_s = Real(0);
    Real distance;
    Vec3 normal;
    kernel::collider_contact(contacts_->meshes[k], s, pos, pos, band, distance, normal);
    kernel::contact_response(vel, force, s, pos, normal, distance, band, both, h_over_m);
  }
}

template <typename Real> void CpuSolver<Real>::project_at(Vec3 side, Vec3& pos, Vec3& vel) const {
  const Real eps = Real(params_.contact_epsilon);
  for (std::size_t k = 0; k < contacts_->shapes.size(); ++k)
    kernel::project_out(contacts_->meshes[k], contacts_->shapes[k], eps, side, pos, vel);
}

template <typename Real> Result<void> CpuSolver<Real>::check_finite() const {
  const Real limit = Real(params_.divergence_limit);
  // bad_components first (no early exit, vectorised); only when something is bad does the loop
  // below look for the first particle (kernel::diverged), for the message.
  if (pos_.empty() || !bad_components(&pos_[0].x, &vel_[0].x, 3 * pos_.size(), limit))
    return {};
  for (std::size_t p = 0; p < pos_.size(); ++p) {
    const Vec3 x = pos_[p], v = vel_[p];
    if (kernel::diverged(x, v, limit))
      return make_error(
          ErrorCode::diverged,
          fmt::format("simulation diverged at step {} (t = {:.4g} s): particle {} is at ({:.4g}, {:.4g}, "
                      "{:.4g}) with velocity ({:.4g}, {:.4g}, {:.4g}) (limit {:g}); try a smaller "
                      "integrator.dt, lower stiffness or more damping",
                      step_, time(), p, double(x.x), double(x.y), double(x.z), double(v.x), double(v.y),
                      double(v.z), params_.divergence_limit));
  }
  return {};
}

template <typename Real> Result<void> CpuSolver<Real>::step() {
  // integrator.substeps = k: k substeps of dt / k (bit-identical to k steps with dt / k).
  const std::uint32_t k = params_.substeps;
  const double h = k == 1 ? params_.dt : params_.dt / double(k);
  for (std::uint32_t s = 0; s < k; ++s) {
    advance_colliders(h); // a substep meets the colliders where they are at its end
    prepare_colliders();
    substep(Real(h));
  }
  ++step_;
  time_ += params_.dt;
  if (swept_finite_)
    return {}; // the last substep's row sweep already checked every particle
  return check_finite();
}

template <typename Real> void CpuSolver<Real>::substep(const Real h) {
  swept_finite_ = false;
  switch (params_.integrator) {
  case Integrator::explicit_euler:
    euler_substep(h, false);
    break;
  case Integrator::semi_implicit_euler:
    euler_substep(h, true);
    break;
  case Integrator::rk4:
    soa_valid_ = false;
    rk4_substep(h);
    break;
  case Integrator::implicit_euler:
    soa_valid_ = false;
    implicit_substep(h);
    break;
  }
  if (params_.stretch_limit.enabled())
    limit_stretch(h);
  if (params_.self_collision.enabled)
    self_collide();
}

// The tethers first (anchors are pinned: every particle's tethers are independent of the
// others'), then Provot's sweeps (one colour at a time: its links share no particle, so they are
// projected in parallel with the same result as in order), so that the structural springs get
// the last word; or, for method projection, the fast projection after the tethers
// (strain_projection.cpp);
// then the colliders' projection, since a correction may have pulled a particle into one. Each
// formula: cloth_kernel.h; the GPU: strain_finish.comp, strain_links.comp, strain_project.comp.
template <typename Real> void CpuSolver<Real>::limit_stretch(const Real h) {
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
  const std::span<const std::uint32_t> colours = topology_->strain_colour_offsets();
  for (std::uint32_t it = 0; sl.provot() && it < sl.iterations; ++it)
    for (std::size_t c = 0; c + 1 < colours.size(); ++c)
      pool_->for_each(colours[c + 1] - colours[c], [&](std::size_t k) {
        const Link& l = strain_links_[colours[c] + k];
        Vec3 da, db;
        if (!kernel::provot_link(pos_[l.a], pos_[l.b], pinned_[l.a] != 0, pinned_[l.b] != 0,
                                 kernel::stretch_bound(l.rest_length, max_strain), da, db))
          return;
        kernel::apply_correction(pos_[l.a], vel_[l.a], da, h);
        kernel::apply_correction(pos_[l.b], vel_[l.b], db, h);
        moved(l.a);
        moved(l.b);
      });
  if (sl.projection()) {
    project_strain(h);
    soa_valid_ = false; // the next row sweep transposes the moved positions
  }
  if (!params_.colliders.empty())
    pool_->for_each(pos_.size(), [&](std::size_t p) {
      if (!pinned_[p]) {
        project_at(pos_[p], pos_[p], vel_[p]);
        moved(p);
      }
    });
  swept_finite_ = false; // the moves are checked with the rest of the state (check_finite)
}

template <typename Real>
void CpuSolver<Real>::euler_finish(std::size_t p, Vec3 f, const Real h, const bool semi) {
  if (pinned_[p]) {
    force_[p] = f;
    pos_next_[p] = pos_[p];
    return;
  }
  Vec3 v = vel_[p];
  contact_at(pos_[p], v, f, h / mass_[p]);
  force_[p] = f;
  Vec3 x = pos_[p];
  kernel::euler_update(semi, x, v, f, mass_[p], h);
  project_at(pos_[p], x, v);
  pos_next_[p] = x;
  vel_[p] = v; // only particle p reads its own velocity: updating in place is safe
}

template <typename Real> void CpuSolver<Real>::euler_substep(const Real h, const bool semi) {
  if (stencil_) {
    row_sweep(h, semi);
    return;
  }
#if VKCLOTH_ROW_SIMD
  if (simd_ != 0 && (topology_->ring_normals() || !topology_->has_surface())) {
    list_sweep(h, semi); // meshes and chains (a grid without a stencil takes the reference)
    return;
  }
#endif
  // One sweep: p's normal and force read positions only (read-only here) and p's own velocity.
  pool_->for_each(pos_.size(),
                  [&](std::size_t p) { euler_finish(p, normal_force_at(pos_, vel_, p), h, semi); });
  std::swap(pos_, pos_next_);
}

// The state and constants both SIMD kernels take.
template <typename Real>
void CpuSolver<Real>::step_args(detail::StepArgs<Real>& a, const Real h, const bool semi) {
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

template <typename Real> detail::RowArgs<Real> CpuSolver<Real>::row_args(const Real h, const bool semi) {
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
template <typename Real> void CpuSolver<Real>::row_sweep(const Real h, const bool semi) {
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
    if (simd_ == 2)
      done = detail::row_kernel_avx512(ra, done, q1, simd_bad);
    else if (simd_ == 1)
      done = detail::row_kernel_avx2(ra, done, q1, simd_bad);
#endif
    std::int64_t unchecked = done;
    if (!ra.integrate) { // the SIMD kernels' forces go through the contacts here
      std::int64_t finished = q0;
#if VKCLOTH_ROW_SIMD
      if (simd_finish)
        finished = simd_ == 2 ? detail::finish_avx512(fa, q0, done) : detail::finish_avx2(fa, q0, done);
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
  detail::PaddedLists<Real>& l = *lists;
  l.width = width;
  const std::size_t n = edge_offsets.size() - 1, vectors = n / width;
  l.spring_begin.push_back(0);
  for (std::size_t b = 0; b < vectors; ++b) {
    std::uint32_t slots = 0, ring_slots = 0;
    for (std::size_t p = b * width; p < (b + 1) * width; ++p) {
      slots = std::max(slots, edge_offsets[p + 1] - edge_offsets[p]);
      ring_slots = std::max(ring_slots, fan_ends[p] - edge_offsets[p]);
    }
    for (std::uint32_t k = 0; k < slots; ++k)
      for (std::size_t p = b * width; p < (b + 1) * width; ++p) {
        const bool has = k < edge_offsets[p + 1] - edge_offsets[p];
        const Edge e = has ? edges[edge_offsets[p] + k] : Edge{std::uint32_t(p), Real(0), Real(0), 0};
        l.other.push_back(e.other);
        l.rest.push_back(e.rest_length);
        l.stiff.push_back(e.stiffness);
        l.ring.push_back(e.ring);
      }
    l.ring_end.push_back(l.spring_begin.back() + ring_slots * std::uint32_t(width));
    l.reads_last.push_back(std::find(l.other.begin() + l.spring_begin.back(), l.other.end(), n - 1) !=
                           l.other.end());
    l.spring_begin.push_back(std::uint32_t(l.other.size()));
  }
  return lists;
}
} // namespace

// Without a stencil (meshes): the list kernel takes whole vectors of particles, the last few the
// per-particle reference; with colliders the kernel's forces go through euler_finish. One
// fork-join per substep (sweep + finite check), as in row_sweep.
template <typename Real> void CpuSolver<Real>::list_sweep(const Real h, const bool semi) {
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
          (void)(simd_ == 2 ? detail::list_kernel_avx512(la, b, qv / width, simd_bad)
                            : detail::list_kernel_avx2(la, b, qv / width, simd_bad));
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

// Stage s evaluates (v, F/m) at y_s = y0 + c_s k_{s-1}; contacts filter each stage.
template <typename Real> void CpuSolver<Real>::rk4_substep(const Real h) {
  const std::size_t n = pos_.size();
  if (stage_pos_.size() != n) {
    for (auto& k : k_pos_)
      k.resize(n);
    for (auto& k : k_vel_)
      k.resize(n);
    stage_pos_.resize(n);
    stage_vel_.resize(n);
  }
  for (std::uint32_t st = 0; st < 4; ++st) {
    if (st == 0) {
      stage_pos_ = pos_;
      stage_vel_ = vel_;
    } else {
      const Real c = kernel::rk4_c(st, h);
      pool_->for_each(pos_.size(), [&](std::size_t p) {
        stage_pos_[p] = kernel::rk4_stage_point(pos_[p], k_pos_[st - 1][p], c);
        stage_vel_[p] = kernel::rk4_stage_point(vel_[p], k_vel_[st - 1][p], c);
      });
    }
    pool_->for_each(pos_.size(), [&](std::size_t p) {
      Vec3 f = normal_force_at(stage_pos_, stage_vel_, p);
      if (!pinned_[p])
        contact_at(stage_pos_[p], stage_vel_[p], f, h / mass_[p]);
      if (st == 0)
        force_[p] = f;
      kernel::rk4_derivative(pinned_[p] != 0, stage_vel_[p], f, mass_[p], k_pos_[st][p], k_vel_[st][p]);
    });
  }
  const Real w = h / Real(6);
  pool_->for_each(pos_.size(), [&](std::size_t p) {
    if (pinned_[p])
      return;
    Vec3 dp(0), dv(0);
    for (std::uint32_t st = 0; st < 4; ++st) {
      dp = kernel::rk4_accumulate(st, dp, k_pos_[st][p]);
      dv = kernel::rk4_accumulate(st, dv, k_vel_[st][p]);
    }
    const Vec3 start = pos_[p];
    pos_[p] = kernel::rk4_finish(pos_[p], dp, w);
    vel_[p] = kernel::rk4_finish(vel_[p], dv, w);
    project_at(start, pos_[p], vel_[p]);
  });
}

template <typename Real> Result<void> CpuSolver<Real>::run(std::uint64_t steps) {
  for (std::uint64_t s = 0; s < steps; ++s)
    VKCLOTH_TRY(step());
  return {};
}

template <typename Real> typename CpuSolver<Real>::Energy CpuSolver<Real>::energy() const {
  Energy e;
  for (std::size_t p = 0; p < pos_.size(); ++p) {
    const glm::dvec3 v{vel_[p]}, x{pos_[p]};
    if (!pinned_[p]) {
      e.kinetic += 0.5 * double(mass_[p]) * glm::dot(v, v);
      e.gravity -= double(mass_[p]) * glm::dot(params_.gravity, x);
    }
  }
  for (const Spring& s : system().springs) {
    const double stretch = glm::length(glm::dvec3{pos_[s.b]} - glm::dvec3{pos_[s.a]}) - s.rest_length;
    e.spring += 0.5 * s.stiffness * stretch * stretch;
  }
  return e;
}

template class CpuSolver<float>;
template class CpuSolver<double>;

} // namespace vkcloth
