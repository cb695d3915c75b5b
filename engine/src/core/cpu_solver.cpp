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
#include "thread_pool.hpp"

// Every per-particle formula comes from shaders/include/cloth_kernel.h (kernel.hpp), the source
// the compute shaders include too; this file gathers the inputs, loops and schedules. The engine
// is built with -ffp-contract=off, so the compiler does not fuse the kernel's expressions.

namespace vkcloth {
namespace {

using detail::RowArgs;

/// A collider as cloth_kernel.h takes it: a plane as (normal, offset), a sphere as (centre, radius).
template <typename Real> struct KernelCollider {
  std::uint32_t type;
  glm::vec<3, Real> a;
  Real b;
};
template <typename Real> KernelCollider<Real> kernel_collider(const Collider& c) {
  using V = glm::vec<3, Real>;
  if (c.type == Collider::Type::plane)
    return {std::uint32_t(c.type), V{c.normal}, Real(c.offset)};
  return {std::uint32_t(c.type), V{c.center}, Real(c.radius)};
}

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
  VKCLOTH_TRY(system.validate());
  const std::size_t n = system.size();

  CpuSolver s;
  s.system_ = std::make_shared<const ParticleSystem>(system);
  s.params_ = params;
  s.edge_offsets_ = system.adjacency.offsets;
  s.edges_.reserve(system.adjacency.refs.size());
  for (const SpringRef& r : system.adjacency.refs) {
    const Spring& sp = system.springs[r.spring];
    s.edges_.push_back(Edge{r.other, Real(sp.rest_length), Real(sp.stiffness)});
  }
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
  if (options.threads > 256)
    return make_error(ErrorCode::invalid_argument,
                      fmt::format("threads must be at most 256, got {}", options.threads));
  // Below ~1000 particles per thread the fork-join costs more than it saves.
  const unsigned wanted =
      options.threads ? options.threads : std::max(1u, std::thread::hardware_concurrency());
  const auto useful = static_cast<unsigned>(std::max<std::size_t>(1, n / 1024));
  s.pool_ = std::make_unique<detail::ThreadPool>(std::min(wanted, useful));
  s.detect_stencil();
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
typename CpuSolver<Real>::Vec3 CpuSolver<Real>::normal_at(std::span<const Vec3> pos,
                                                          std::size_t index) const {
  const std::int64_t nx = system_->grid->nx, ny = system_->grid->ny;
  const std::int64_t i = std::int64_t(index) % nx, j = std::int64_t(index) / nx;
  const Vec3 p = pos[index];
  // Fan around p: right, up, left, down. Each present pair adds one triangle's
  // cross product (twice its area times its normal): an area-weighted vertex normal.
  const bool has[4] = {i + 1 < nx, j + 1 < ny, i > 0, j > 0};
  Vec3 e[4] = {};
  if (has[0])
    e[0] = pos[index + 1] - p;
  if (has[1])
    e[1] = pos[index + nx] - p;
  if (has[2])
    e[2] = pos[index - 1] - p;
  if (has[3])
    e[3] = pos[index - nx] - p;
  Vec3 sum(0);
  for (int k = 0; k < 4; ++k)
    if (has[k] && has[(k + 1) & 3])
      kernel::add_fan_triangle(sum, e[k], e[(k + 1) & 3]);
  return kernel::unit_or_zero(sum);
}

template <typename Real> void CpuSolver<Real>::detect_stencil() {
  stencil_ = false;
  if (!system_->grid)
    return;
  const std::int64_t nx = system_->grid->nx, ny = system_->grid->ny;
  if (nx < 5 || ny < 5)
    return;
  const std::int64_t first = 2 * nx + 2;
  if (edge_offsets_[first + 1] - edge_offsets_[first] != 12)
    return;
  for (int k = 0; k < 12; ++k) {
    const Edge& e = edges_[edge_offsets_[first] + k];
    stencil_offset_[k] = std::int64_t(e.other) - first;
    stencil_edge_[k] = e;
  }
  for (std::int64_t j = 2; j < ny - 2; ++j)
    for (std::int64_t i = 2; i < nx - 2; ++i) {
      const std::int64_t p = j * nx + i;
      if (edge_offsets_[p + 1] - edge_offsets_[p] != 12)
        return;
      for (int k = 0; k < 12; ++k) {
        const Edge& e = edges_[edge_offsets_[p] + k];
        if (std::int64_t(e.other) - p != stencil_offset_[k] ||
            e.rest_length != stencil_edge_[k].rest_length || e.stiffness != stencil_edge_[k].stiffness)
          return;
      }
    }
  stencil_ = true;
  // Pad of the SoA copies: the farthest neighbour a (masked) lane may read.
  std::int64_t reach = nx + 1;
  for (std::int64_t o : stencil_offset_)
    reach = std::max(reach, o < 0 ? -o : o);
  soa_pad_ = std::size_t(reach);
  // Masks: every particle's gather list must be the stencil's, in order, with some springs left
  // out (make_cloth's border particles are); the fan terms follow normal_at's `has`.
  const std::size_t n = pos_.size();
  mask_.assign(n, 0);
  for (std::size_t p = 0; p < n; ++p) {
    const std::int64_t i = std::int64_t(p) % nx, j = std::int64_t(p) / nx;
    const bool has[4] = {i + 1 < nx, j + 1 < ny, i > 0, j > 0};
    unsigned m = 0;
    for (int k = 0; k < 4; ++k)
      if (has[k] && has[(k + 1) & 3])
        m |= 1u << (12 + k);
    int k = 0;
    for (std::uint32_t e = edge_offsets_[p]; e < edge_offsets_[p + 1]; ++e, ++k) {
      const Edge& ed = edges_[e];
      while (k < 12 &&
             (std::int64_t(ed.other) - std::int64_t(p) != stencil_offset_[k] ||
              ed.rest_length != stencil_edge_[k].rest_length || ed.stiffness != stencil_edge_[k].stiffness))
        ++k;
      if (k == 12) {
        mask_.clear(); // irregular: border particles take the per-particle code
        return;
      }
      m |= 1u << k;
    }
    mask_[p] = std::uint16_t(m);
  }
}

template <typename Real>
typename CpuSolver<Real>::Vec3 CpuSolver<Real>::normal_force_at(std::span<const Vec3> pos,
                                                                std::span<const Vec3> vel, std::size_t p) {
  if (system_->grid)
    normal_[p] = normal_at(pos, p);
  return force_at(pos, vel, p);
}

template <typename Real>
typename CpuSolver<Real>::Vec3 CpuSolver<Real>::force_at(std::span<const Vec3> pos, std::span<const Vec3> vel,
                                                         std::size_t p) const {
  const Vec3 x = pos[p];
  Vec3 f(0);
  bool interior = false;
  if (stencil_) {
    const std::size_t nx = system_->grid->nx, ny = system_->grid->ny;
    const std::size_t i = p % nx, j = p / nx;
    interior = i >= 2 && i + 2 < nx && j >= 2 && j + 2 < ny;
  }
  if (interior) {
    // Same terms, same order as the CSR loop below (detect_stencil checked it).
    for (int k = 0; k < 12; ++k) {
      const Edge& s = stencil_edge_[k];
      kernel::add_spring(f, x, pos[std::size_t(std::int64_t(p) + stencil_offset_[k])], s.rest_length,
                         s.stiffness);
    }
  } else {
    for (std::uint32_t e = edge_offsets_[p]; e < edge_offsets_[p + 1]; ++e) {
      const Edge& s = edges_[e];
      kernel::add_spring(f, x, pos[s.other], s.rest_length, s.stiffness);
    }
  }
  const Real kw = Real(params_.wind.strength);
  return kernel::add_body_forces(f, mass_[p], vel[p], Vec3{params_.gravity}, Real(params_.damping),
                                 kw != Real(0), normal_[p], Vec3{params_.wind.direction}, kw);
}

template <typename Real> void CpuSolver<Real>::contact_at(Vec3 pos, Vec3& vel, Vec3& force) const {
  const Real band = Real(2) * Real(params_.contact_epsilon);
  const bool both = !params_.contact_inward_only; // Figure 12's variant: outward parts go too
  for (const Collider& c : params_.colliders) {
    const KernelCollider<Real> k = kernel_collider<Real>(c);
    Real distance;
    Vec3 normal;
    kernel::collider_contact(k.type, k.a, k.b, pos, distance, normal);
    kernel::contact_filter(vel, force, normal, distance, band, both);
  }
}

template <typename Real> void CpuSolver<Real>::project_at(Vec3& pos, Vec3& vel) const {
  const Real eps = Real(params_.contact_epsilon);
  for (const Collider& c : params_.colliders) {
    const KernelCollider<Real> k = kernel_collider<Real>(c);
    kernel::project_out(k.type, k.a, k.b, eps, pos, vel);
  }
}

template <typename Real> template <typename F> void CpuSolver<Real>::for_particles(F&& body) {
  pool_->parallel_for(pos_.size(), [&](std::size_t begin, std::size_t end) {
    for (std::size_t p = begin; p < end; ++p)
      body(p);
  });
}

template <typename Real> Result<void> CpuSolver<Real>::check_finite() const {
  const Real limit = Real(params_.divergence_limit);
  // Fast pass without early exit (vectorisable OR-reduction over the flat arrays): a component
  // is bad when not finite (c - c != 0 for inf and NaN) or, for positions, |x| > limit (or NaN).
  // Only when something is bad does the loop below look for the first particle, for the message.
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
  const Real h = Real(k == 1 ? params_.dt : params_.dt / double(k));
  for (std::uint32_t s = 0; s < k; ++s)
    substep(h);
  ++step_;
  if (swept_finite_)
    return {}; // the last substep's row sweep already checked every particle
  return check_finite();
}

template <typename Real> void CpuSolver<Real>::substep(const Real dt) {
  swept_finite_ = false;
  switch (params_.integrator) {
  case Integrator::implicit_euler:
    soa_valid_ = false;
    implicit_substep(dt);
    break;
  case Integrator::explicit_euler:
  case Integrator::semi_implicit_euler: {
    const bool semi = params_.integrator == Integrator::semi_implicit_euler;
    // Grid stencil: the vectorised row kernel takes every particle (masks for the border), or,
    // when some gather list is irregular (no masks), the interior runs of each row while the
    // border particles take the per-particle code below. It reads positions from the SoA copy
    // and writes the next one; one fork-join per substep (sweep + finite check).
    const bool rows = stencil_;
    const bool kernel_integrates = params_.colliders.empty();
    RowArgs<Real> ra{};
    std::int64_t gnx = 0, gny = 0;
    Real *nsx = nullptr, *nsy = nullptr, *nsz = nullptr;
    if (rows) {
      const std::size_t n = pos_.size(), pad = soa_pad_, stride = n + 2 * pad;
      if (soa_.size() != 3 * stride) {
        soa_.assign(3 * stride, Real(0));
        soa_next_.assign(3 * stride, Real(0));
        soa_valid_ = false;
      }
      Real* sx = soa_.data() + pad;
      Real* sy = sx + stride;
      Real* sz = sy + stride;
      if (!soa_valid_) { // first step, or pos_ changed outside the row sweep
        pool_->parallel_for(n, [&](std::size_t b, std::size_t e) {
          for (std::size_t p = b; p < e; ++p) {
            sx[p] = pos_[p].x;
            sy[p] = pos_[p].y;
            sz[p] = pos_[p].z;
          }
        });
      }
      nsx = soa_next_.data() + pad;
      nsy = nsx + stride;
      nsz = nsy + stride;
      gnx = system_->grid->nx;
      gny = system_->grid->ny;
      ra.px = sx;
      ra.py = sy;
      ra.pz = sz;
      ra.vel = &vel_[0].x;
      ra.vel_out = &vel_[0].x;
      ra.mass = mass_.data();
      ra.pinned = pinned_.data();
      ra.force_out = &force_[0].x;
      ra.normal_out = &normal_[0].x;
      ra.pos_next = &pos_next_[0].x;
      ra.sx_next = nsx;
      ra.sy_next = nsy;
      ra.sz_next = nsz;
      ra.mask = mask_.empty() ? nullptr : mask_.data();
      ra.nx = gnx;
      ra.off = stencil_offset_.data();
      for (int k = 0; k < 12; ++k) {
        stencil_rest_[k] = stencil_edge_[k].rest_length;
        stencil_stiff_[k] = stencil_edge_[k].stiffness;
      }
      ra.rest = stencil_rest_.data();
      ra.stiff = stencil_stiff_.data();
      const Vec3 g{params_.gravity}, w{params_.wind.direction};
      ra.gx = g.x;
      ra.gy = g.y;
      ra.gz = g.z;
      ra.damping = Real(params_.damping);
      ra.kw = Real(params_.wind.strength);
      ra.wind = ra.kw != Real(0);
      ra.wx = w.x;
      ra.wy = w.y;
      ra.wz = w.z;
      ra.dt = dt;
      ra.integrate = kernel_integrates;
      ra.semi = semi;
    }
    auto finish = [&](std::size_t p, Vec3 f) {
      if (pinned_[p]) {
        force_[p] = f;
        pos_next_[p] = pos_[p];
      } else {
        Vec3 v = vel_[p];
        contact_at(pos_[p], v, f);
        force_[p] = f;
        Vec3 x = pos_[p];
        kernel::euler_update(semi, x, v, f, mass_[p], dt);
        project_at(x, v);
        pos_next_[p] = x;
        vel_[p] = v; // only particle p reads its own velocity: updating in place is safe
      }
      if (nsx) {
        nsx[p] = pos_next_[p].x;
        nsy[p] = pos_next_[p].y;
        nsz[p] = pos_next_[p].z;
      }
    };
    if (rows) {
      // Whole vectors in SIMD, a remainder shorter than one vector through the per-particle
      // reference; then the finite check of what was written that the SIMD kernel did not check.
      const Real limit = Real(params_.divergence_limit);
      ra.limit = limit;
      Real* const pn = &pos_next_[0].x;
      Real* const vn = &vel_[0].x;
      auto kernel = [&](std::int64_t q0, std::int64_t q1, unsigned& bad_here) {
        std::int64_t done = q0;
        bool simd_bad = false;
#if VKCLOTH_ROW_SIMD
        if (simd_ == 2)
          done = detail::row_kernel_avx512(ra, done, q1, simd_bad);
        else if (simd_ == 1)
          done = detail::row_kernel_avx2(ra, done, q1, simd_bad);
#endif
        // The SIMD kernels integrate only without colliders; otherwise their forces finish here.
        std::int64_t unchecked = done;
        if (!kernel_integrates) {
          for (std::int64_t q = q0; q < done; ++q)
            finish(std::size_t(q), force_[std::size_t(q)]);
          unchecked = q0;
        }
        // The remainder (less than one vector), or every particle without SIMD: the reference.
        for (std::int64_t q = done; q < q1; ++q)
          finish(std::size_t(q), normal_force_at(pos_, vel_, std::size_t(q)));
        bad_here |= unsigned(simd_bad) | bad_components(pn + 3 * unchecked, vn + 3 * unchecked,
                                                        std::size_t(3 * (q1 - unchecked)), limit);
      };
      std::atomic<bool> bad{false};
      // Claimed in blocks of ~2048 particles by whichever thread is free (a thread the OS delays
      // holds up at most one block); within one, pieces of ~1024: finish() and the check read
      // what the kernel just wrote.
      pool_->parallel_blocks(pos_.size(), 2048, [&](std::size_t b, std::size_t e) {
        constexpr std::size_t block = 1024;
        unsigned bad_here = 0;
        for (std::size_t b0 = b; b0 < e;) {
          const std::size_t b1 = e - b0 < 2 * block ? e : b0 + block;
          if (ra.mask) {
            kernel(std::int64_t(b0), std::int64_t(b1), bad_here);
          } else {
            for (std::size_t p = b0; p < b1;) {
              const std::int64_t j = std::int64_t(p) / gnx, i = std::int64_t(p) % gnx;
              if (j >= 2 && j + 2 < gny && i >= 2 && i + 2 < gnx) {
                const std::size_t run_end = std::min<std::size_t>(b1, std::size_t(j * gnx + gnx - 2));
                kernel(std::int64_t(p), std::int64_t(run_end), bad_here);
                p = run_end;
                continue;
              }
              finish(p, normal_force_at(pos_, vel_, p));
              bad_here |= bad_components(pn + 3 * p, vn + 3 * p, 3, limit);
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
      break;
    }
    // One sweep: p's normal needs only positions (read-only here), and force_at reads p's own.
    for_particles([&](std::size_t p) { finish(p, normal_force_at(pos_, vel_, p)); });
    std::swap(pos_, pos_next_);
    break;
  }
  case Integrator::rk4: {
    soa_valid_ = false;
    // Stage s evaluates (v, F/m) at y_s = y0 + c_s dt k_{s-1}; contacts filter each stage.
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
        const Real c = kernel::rk4_c(st, dt);
        for_particles([&](std::size_t p) {
          stage_pos_[p] = kernel::rk4_stage_point(pos_[p], k_pos_[st - 1][p], c);
          stage_vel_[p] = kernel::rk4_stage_point(vel_[p], k_vel_[st - 1][p], c);
        });
      }
      for_particles([&](std::size_t p) {
        Vec3 f = normal_force_at(stage_pos_, stage_vel_, p);
        if (!pinned_[p])
          contact_at(stage_pos_[p], stage_vel_[p], f);
        if (st == 0)
          force_[p] = f;
        k_pos_[st][p] = pinned_[p] ? Vec3(0) : stage_vel_[p];
        k_vel_[st][p] = pinned_[p] ? Vec3(0) : f / mass_[p];
      });
    }
    const Real w = dt / Real(6);
    for_particles([&](std::size_t p) {
      if (pinned_[p])
        return;
      Vec3 dp(0), dv(0);
      for (std::uint32_t st = 0; st < 4; ++st) {
        dp = kernel::rk4_accumulate(st, dp, k_pos_[st][p]);
        dv = kernel::rk4_accumulate(st, dv, k_vel_[st][p]);
      }
      pos_[p] = kernel::rk4_finish(pos_[p], dp, w);
      vel_[p] = kernel::rk4_finish(vel_[p], dv, w);
      project_at(pos_[p], vel_[p]);
    });
    break;
  }
  }
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
  for (const Spring& s : system_->springs) {
    const double stretch = glm::length(glm::dvec3{pos_[s.b]} - glm::dvec3{pos_[s.a]}) - s.rest_length;
    e.spring += 0.5 * s.stiffness * stretch * stretch;
  }
  return e;
}

template class CpuSolver<float>;
template class CpuSolver<double>;

} // namespace vkcloth
