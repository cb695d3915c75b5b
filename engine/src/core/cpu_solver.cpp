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
#include "row_kernel.hpp"
#include "thread_pool.hpp"

// Floating-point expressions below are written in the exact order the GLSL passes use
// (shaders/force.comp, shaders/integrate.comp); the engine is built with -ffp-contract=off so the
// compiler does not fuse them differently. Change one side, change the other.

namespace vkcloth {
namespace {

template <typename V> auto dot3(V a, V b) { return a.x * b.x + a.y * b.y + a.z * b.z; }

/// Signed distance to a collider and its outward unit normal at the closest surface point.
template <typename Real> struct Contact {
  Real distance;
  glm::vec<3, Real> normal;
};

template <typename Real> Contact<Real> collider_contact(const Collider& c, glm::vec<3, Real> p) {
  using V = glm::vec<3, Real>;
  if (c.type == Collider::Type::plane) {
    const V n{c.normal};
    return {dot3(n, p) - Real(c.offset), n};
  }
  const V r = p - V{c.center};
  const Real len = std::sqrt(dot3(r, r));
  const V n = len > Real(0) ? r / len : V{0, 0, 1}; // at the exact centre, push up
  return {len - Real(c.radius), n};
}

// ---- Interior row kernel (grid stencil) ----------------------------------------------------------
// One contiguous run of interior particles [q0, q1) of one grid row, vectorised ACROSS particles:
// positions are read from structure-of-arrays copies (px, py, pz) at the 12 fixed stencil offsets
// and the 4 normal-fan offsets, so every load is unit-stride. Each particle's arithmetic is the
// scalar path's, term for term and in the same order (normal_at, force_at, step()); `if (len > 0)`
// becomes a select of the unchanged sum, which is the same value. sqrt and division are correctly
// rounded in SIMD as in scalar code and -ffp-contract=off forbids FMA, so every lane computes the
// bits the scalar code computes, on every ISA the clones below target.
using detail::RowArgs;

template <typename Real, bool wind, bool integrate, bool semi>
#if defined(__GNUC__)
__attribute__((always_inline))
#endif
inline void row_kernel_body(const RowArgs<Real>& a, std::int64_t q0, std::int64_t q1) {
  const Real* __restrict px = a.px;
  const Real* __restrict py = a.py;
  const Real* __restrict pz = a.pz;
  const Real* __restrict mass = a.mass;
  const std::uint8_t* __restrict pinned = a.pinned;
  Real* __restrict fo = a.force_out;
  Real* __restrict no = a.normal_out;
  Real* __restrict vel = a.vel_out; // read and written in place (own particle only)
  Real* __restrict pos_next = a.pos_next;
  Real* __restrict sxn = a.sx_next;
  Real* __restrict syn = a.sy_next;
  Real* __restrict szn = a.sz_next;
  const std::uint16_t* __restrict mask = a.mask;
  const Real gx = a.gx, gy = a.gy, gz = a.gz, damping = a.damping, kw = a.kw, wx = a.wx, wy = a.wy, wz = a.wz,
             dt = a.dt;
  const std::int64_t nx = a.nx;
  const std::int64_t o0 = a.off[0], o1 = a.off[1], o2 = a.off[2], o3 = a.off[3], o4 = a.off[4], o5 = a.off[5],
                     o6 = a.off[6], o7 = a.off[7], o8 = a.off[8], o9 = a.off[9], o10 = a.off[10], o11 = a.off[11];
  const Real L[12] = {a.rest[0], a.rest[1], a.rest[2], a.rest[3], a.rest[4],  a.rest[5],
                      a.rest[6], a.rest[7], a.rest[8], a.rest[9], a.rest[10], a.rest[11]};
  const Real K[12] = {a.stiff[0], a.stiff[1], a.stiff[2], a.stiff[3], a.stiff[4],  a.stiff[5],
                      a.stiff[6], a.stiff[7], a.stiff[8], a.stiff[9], a.stiff[10], a.stiff[11]};
  const std::int64_t O[12] = {o0, o1, o2, o3, o4, o5, o6, o7, o8, o9, o10, o11};
  for (std::int64_t q = q0; q < q1; ++q) {
    // Border particles (mask): absent spring and fan terms are skipped, as the CSR path does.
    const unsigned mk = mask ? unsigned(mask[q]) : 0xFFFFu;
    const Real x0 = px[q], y0 = py[q], z0 = pz[q];
    // normal_at: fan right (e0), up (e1), left (e2), down (e3); all present inside.
    const Real e0x = px[q + 1] - x0, e0y = py[q + 1] - y0, e0z = pz[q + 1] - z0;
    const Real e1x = px[q + nx] - x0, e1y = py[q + nx] - y0, e1z = pz[q + nx] - z0;
    const Real e2x = px[q - 1] - x0, e2y = py[q - 1] - y0, e2z = pz[q - 1] - z0;
    const Real e3x = px[q - nx] - x0, e3y = py[q - nx] - y0, e3z = pz[q - nx] - z0;
    // sum = 0; sum += cross(e_k, e_k+1) (glm::cross order), k = 0..3
    Real sx = Real(0), sy = Real(0), sz = Real(0);
#define VKCLOTH_CROSS_ADD(bit, ax, ay, az, bx, by, bz)                                                                  \
  if (mk >> (bit) & 1u) {                                                                                              \
    sx = sx + (ay * bz - by * az);                                                                                     \
    sy = sy + (az * bx - bz * ax);                                                                                     \
    sz = sz + (ax * by - bx * ay);                                                                                     \
  }
    VKCLOTH_CROSS_ADD(12, e0x, e0y, e0z, e1x, e1y, e1z)
    VKCLOTH_CROSS_ADD(13, e1x, e1y, e1z, e2x, e2y, e2z)
    VKCLOTH_CROSS_ADD(14, e2x, e2y, e2z, e3x, e3y, e3z)
    VKCLOTH_CROSS_ADD(15, e3x, e3y, e3z, e0x, e0y, e0z)
#undef VKCLOTH_CROSS_ADD
    const Real nlen = std::sqrt(sx * sx + sy * sy + sz * sz);
    const bool npos = nlen > Real(0);
    // Computed unconditionally, then selected (no speculation for the vectoriser to refuse).
    const Real qx = sx / nlen, qy = sy / nlen, qz = sz / nlen;
    const Real nxv = npos ? qx : Real(0), nyv = npos ? qy : Real(0), nzv = npos ? qz : Real(0);
    // force_at: the 12 stencil springs in CSR order.
    Real fx = Real(0), fy = Real(0), fz = Real(0);
#define VKCLOTH_SPRING(k)                                                                                              \
  {                                                                                                                    \
    const std::int64_t r = q + O[k];                                                                                   \
    const Real ux = px[r] - x0, uy = py[r] - y0, uz = pz[r] - z0;                                                      \
    const Real len = std::sqrt(ux * ux + uy * uy + uz * uz);                                                           \
    const Real c = K[k] * (len - L[k]) / len;                                                                          \
    const bool pos = len > Real(0) && (mk >> (k) & 1u);                                                                \
    const Real tx = fx + ux * c, ty = fy + uy * c, tz = fz + uz * c;                                                   \
    fx = pos ? tx : fx;                                                                                                \
    fy = pos ? ty : fy;                                                                                                \
    fz = pos ? tz : fz;                                                                                                \
  }
    VKCLOTH_SPRING(0) VKCLOTH_SPRING(1) VKCLOTH_SPRING(2) VKCLOTH_SPRING(3) VKCLOTH_SPRING(4) VKCLOTH_SPRING(5)
    VKCLOTH_SPRING(6) VKCLOTH_SPRING(7) VKCLOTH_SPRING(8) VKCLOTH_SPRING(9) VKCLOTH_SPRING(10) VKCLOTH_SPRING(11)
#undef VKCLOTH_SPRING
    const Real m = mass[q];
    fx = fx + gx * m;
    fy = fy + gy * m;
    fz = fz + gz * m;
    const Real vx = vel[3 * q], vy = vel[3 * q + 1], vz = vel[3 * q + 2];
    const Real dm = damping * m;
    fx = fx - vx * dm;
    fy = fy - vy * dm;
    fz = fz - vz * dm;
    if constexpr (wind) {
      const Real kn = kw * (nxv * wx + nyv * wy + nzv * wz);
      fx = fx + nxv * kn;
      fy = fy + nyv * kn;
      fz = fz + nzv * kn;
    }
    no[3 * q] = nxv;
    no[3 * q + 1] = nyv;
    no[3 * q + 2] = nzv;
    fo[3 * q] = fx;
    fo[3 * q + 1] = fy;
    fo[3 * q + 2] = fz;
    if constexpr (integrate) { // no colliders: contact_at and project_at do nothing
      const Real ax = fx / m, ay = fy / m, az = fz / m;
      const Real xx = x0, xy = y0, xz = z0; // the SoA copy holds the AoS positions' values
      Real nvx, nvy, nvz, nxx, nxy, nxz;
      if constexpr (semi) {
        nvx = vx + ax * dt;
        nvy = vy + ay * dt;
        nvz = vz + az * dt;
        nxx = xx + nvx * dt;
        nxy = xy + nvy * dt;
        nxz = xz + nvz * dt;
      } else {
        nxx = xx + vx * dt;
        nxy = xy + vy * dt;
        nxz = xz + vz * dt;
        nvx = vx + ax * dt;
        nvy = vy + ay * dt;
        nvz = vz + az * dt;
      }
      const bool pin = pinned[q] != 0;
      pos_next[3 * q] = sxn[q] = pin ? xx : nxx;
      pos_next[3 * q + 1] = syn[q] = pin ? xy : nxy;
      pos_next[3 * q + 2] = szn[q] = pin ? xz : nxz;
      vel[3 * q] = pin ? vx : nvx;
      vel[3 * q + 1] = pin ? vy : nvy;
      vel[3 * q + 2] = pin ? vz : nvz;
    }
  }
}

// Runtime-dispatched clones (GCC/Clang ifunc): the default build stays portable (x86-64 baseline),
// AVX2 / AVX-512 machines get wider vectors. Same bits on every clone (see above).
#if defined(__x86_64__) && defined(__ELF__) && (defined(__GNUC__) || defined(__clang__)) && \
    !defined(VKCLOTH_NO_TARGET_CLONES)
#define VKCLOTH_ROW_CLONES __attribute__((target_clones("avx512f", "avx2", "default")))
#else
#define VKCLOTH_ROW_CLONES
#endif
template <typename Real>
#if defined(__GNUC__)
__attribute__((always_inline)) // into each clone below, so that each is compiled for its ISA
#endif
inline void row_kernel_dispatch(const RowArgs<Real>& a, std::int64_t q0, std::int64_t q1) {
  const int v = (a.wind ? 4 : 0) | (a.integrate ? 2 : 0) | (a.semi ? 1 : 0);
  switch (v) {
  case 0: row_kernel_body<Real, false, false, false>(a, q0, q1); break;
  case 1: row_kernel_body<Real, false, false, true>(a, q0, q1); break;
  case 2: row_kernel_body<Real, false, true, false>(a, q0, q1); break;
  case 3: row_kernel_body<Real, false, true, true>(a, q0, q1); break;
  case 4: row_kernel_body<Real, true, false, false>(a, q0, q1); break;
  case 5: row_kernel_body<Real, true, false, true>(a, q0, q1); break;
  case 6: row_kernel_body<Real, true, true, false>(a, q0, q1); break;
  default: row_kernel_body<Real, true, true, true>(a, q0, q1); break;
  }
}
VKCLOTH_ROW_CLONES void row_kernel_f(const RowArgs<float>& a, std::int64_t q0, std::int64_t q1) {
  row_kernel_dispatch(a, q0, q1);
}
VKCLOTH_ROW_CLONES void row_kernel_d(const RowArgs<double>& a, std::int64_t q0, std::int64_t q1) {
  row_kernel_dispatch(a, q0, q1);
}
inline void row_kernel(const RowArgs<float>& a, std::int64_t q0, std::int64_t q1) { row_kernel_f(a, q0, q1); }
inline void row_kernel(const RowArgs<double>& a, std::int64_t q0, std::int64_t q1) { row_kernel_d(a, q0, q1); }

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
  if (__builtin_cpu_supports("avx2")) best = 1;
  if (__builtin_cpu_supports("avx512f")) best = 2;
#endif
  if (const char* env = std::getenv("VKCLOTH_CPU_SIMD")) {
    if (std::strcmp(env, "scalar") == 0) best = 0;
    else if (std::strcmp(env, "avx2") == 0) best = std::min(best, 1);
  }
  return best;
}

} // namespace

template <typename Real> CpuSolver<Real>::CpuSolver() = default;
template <typename Real> CpuSolver<Real>::CpuSolver(CpuSolver&&) noexcept = default;
template <typename Real> CpuSolver<Real>& CpuSolver<Real>::operator=(CpuSolver&&) noexcept = default;
template <typename Real> CpuSolver<Real>::~CpuSolver() = default;
template <typename Real> unsigned CpuSolver<Real>::threads() const { return pool_->size(); }

template <typename Real>
Result<CpuSolver<Real>> CpuSolver<Real>::create(const ParticleSystem& system, SimParams params, CpuSolverOptions options) {
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
    return make_error(ErrorCode::invalid_argument, fmt::format("threads must be at most 256, got {}", options.threads));
  // Below ~1000 particles per thread the fork-join costs more than it saves.
  const unsigned wanted = options.threads ? options.threads : std::max(1u, std::thread::hardware_concurrency());
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
                      fmt::format("set_particle: index {} is out of range (the system has {} particles)", index,
                                  pos_.size()));
  for (int k = 0; k < 3; ++k)
    if (!std::isfinite(position[k]) || !std::isfinite(velocity[k]))
      return make_error(ErrorCode::invalid_argument,
                        fmt::format("set_particle: particle {} position ({}, {}, {}) and velocity ({}, {}, {}) must be finite",
                                    index, position.x, position.y, position.z, velocity.x, velocity.y, velocity.z));
  pos_[index] = position;
  vel_[index] = pinned_[index] ? Vec3(0) : velocity;
  soa_valid_ = false;
  return {};
}

template <typename Real>
typename CpuSolver<Real>::Vec3 CpuSolver<Real>::normal_at(std::span<const Vec3> pos, std::size_t index) const {
  const std::int64_t nx = system_->grid->nx, ny = system_->grid->ny;
  const std::int64_t i = std::int64_t(index) % nx, j = std::int64_t(index) / nx;
  const Vec3 p = pos[index];
  // Fan around p: right, up, left, down. Each present pair adds one triangle's
  // cross product (twice its area times its normal): an area-weighted vertex normal.
  const bool has[4] = {i + 1 < nx, j + 1 < ny, i > 0, j > 0};
  Vec3 e[4] = {};
  if (has[0]) e[0] = pos[index + 1] - p;
  if (has[1]) e[1] = pos[index + nx] - p;
  if (has[2]) e[2] = pos[index - 1] - p;
  if (has[3]) e[3] = pos[index - nx] - p;
  Vec3 sum(0);
  for (int k = 0; k < 4; ++k)
    if (has[k] && has[(k + 1) & 3]) sum += glm::cross(e[k], e[(k + 1) & 3]);
  const Real len = std::sqrt(dot3(sum, sum));
  return len > Real(0) ? sum / len : Vec3(0);
}

template <typename Real> void CpuSolver<Real>::detect_stencil() {
  stencil_ = false;
  if (!system_->grid) return;
  const std::int64_t nx = system_->grid->nx, ny = system_->grid->ny;
  if (nx < 5 || ny < 5) return;
  const std::int64_t first = 2 * nx + 2;
  if (edge_offsets_[first + 1] - edge_offsets_[first] != 12) return;
  for (int k = 0; k < 12; ++k) {
    const Edge& e = edges_[edge_offsets_[first] + k];
    stencil_offset_[k] = std::int64_t(e.other) - first;
    stencil_edge_[k] = e;
  }
  for (std::int64_t j = 2; j < ny - 2; ++j)
    for (std::int64_t i = 2; i < nx - 2; ++i) {
      const std::int64_t p = j * nx + i;
      if (edge_offsets_[p + 1] - edge_offsets_[p] != 12) return;
      for (int k = 0; k < 12; ++k) {
        const Edge& e = edges_[edge_offsets_[p] + k];
        if (std::int64_t(e.other) - p != stencil_offset_[k] || e.rest_length != stencil_edge_[k].rest_length ||
            e.stiffness != stencil_edge_[k].stiffness)
          return;
      }
    }
  stencil_ = true;
  // Pad of the SoA copies: the farthest neighbour a (masked) lane may read.
  std::int64_t reach = nx + 1;
  for (std::int64_t o : stencil_offset_) reach = std::max(reach, o < 0 ? -o : o);
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
      if (has[k] && has[(k + 1) & 3]) m |= 1u << (12 + k);
    int k = 0;
    for (std::uint32_t e = edge_offsets_[p]; e < edge_offsets_[p + 1]; ++e, ++k) {
      const Edge& ed = edges_[e];
      while (k < 12 && (std::int64_t(ed.other) - std::int64_t(p) != stencil_offset_[k] ||
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
typename CpuSolver<Real>::Vec3 CpuSolver<Real>::normal_force_at(std::span<const Vec3> pos, std::span<const Vec3> vel,
                                                                std::size_t p) {
  if (system_->grid) normal_[p] = normal_at(pos, p);
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
      const Vec3 u = pos[std::size_t(std::int64_t(p) + stencil_offset_[k])] - x;
      const Real len = std::sqrt(dot3(u, u));
      if (len > Real(0)) f += u * (s.stiffness * (len - s.rest_length) / len); // report eq. 2
    }
  } else {
    for (std::uint32_t e = edge_offsets_[p]; e < edge_offsets_[p + 1]; ++e) {
      const Edge& s = edges_[e];
      const Vec3 u = pos[s.other] - x;
      const Real len = std::sqrt(dot3(u, u));
      if (len > Real(0)) f += u * (s.stiffness * (len - s.rest_length) / len); // report eq. 2
    }
  }
  const Real m = mass_[p];
  f += Vec3{params_.gravity} * m;
  f -= vel[p] * (Real(params_.damping) * m);
  const Real kw = Real(params_.wind.strength);
  if (kw != Real(0)) {
    const Vec3 nrm = normal_[p];
    f += nrm * (kw * dot3(nrm, Vec3{params_.wind.direction}));
  }
  return f;
}

template <typename Real> void CpuSolver<Real>::contact_at(Vec3 pos, Vec3& vel, Vec3& force) const {
  const Real band = Real(2) * Real(params_.contact_epsilon);
  for (const Collider& c : params_.colliders) {
    const Contact<Real> ct = collider_contact<Real>(c, pos);
    if (!(ct.distance < band)) continue;
    // Only the part pointing INTO the collider is removed: a hand lifting the cloth keeps
    // its outward pull (report §4, Figure 12).
    const bool both = !params_.contact_inward_only; // Figure 12's variant: outward parts go too
    const Real vn = dot3(vel, ct.normal);
    if (vn < Real(0) || (both && vn != Real(0))) vel -= ct.normal * vn;
    const Real fn = dot3(force, ct.normal);
    if (fn < Real(0) || (both && fn != Real(0))) force -= ct.normal * fn;
  }
}

template <typename Real> void CpuSolver<Real>::project_at(Vec3& pos, Vec3& vel) const {
  const Real eps = Real(params_.contact_epsilon);
  for (const Collider& c : params_.colliders) {
    const Contact<Real> ct = collider_contact<Real>(c, pos);
    if (!(ct.distance < Real(0))) continue;
    if (c.type == Collider::Type::plane)
      pos += ct.normal * (eps - ct.distance); // report eq. 5: back to z_s + eps
    else
      pos = Vec3{c.center} + ct.normal * (Real(c.radius) + eps); // report eq. 6
    const Real vn = dot3(vel, ct.normal);
    if (vn < Real(0)) vel -= ct.normal * vn;
  }
}

template <typename Real> template <typename F> void CpuSolver<Real>::for_particles(F&& body) {
  pool_->parallel_for(pos_.size(), [&](std::size_t begin, std::size_t end) {
    for (std::size_t p = begin; p < end; ++p) body(p);
  });
}

template <typename Real> Result<void> CpuSolver<Real>::check_finite() const {
  const Real limit = Real(params_.divergence_limit);
  // Fast pass without early exit (vectorisable OR-reduction over the flat arrays): a component
  // is bad when not finite (c - c != 0 for inf and NaN) or, for positions, |x| > limit (or NaN).
  // Only when something is bad does the loop below look for the first particle, for the message.
  if (pos_.empty() || !bad_components(&pos_[0].x, &vel_[0].x, 3 * pos_.size(), limit)) return {};
  for (std::size_t p = 0; p < pos_.size(); ++p) {
    const Vec3 x = pos_[p], v = vel_[p];
    const bool finite = std::isfinite(x.x) && std::isfinite(x.y) && std::isfinite(x.z) && std::isfinite(v.x) &&
                        std::isfinite(v.y) && std::isfinite(v.z);
    if (!finite || std::abs(x.x) > limit || std::abs(x.y) > limit || std::abs(x.z) > limit)
      return make_error(ErrorCode::diverged,
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
  for (std::uint32_t s = 0; s < k; ++s) substep(h);
  ++step_;
  if (swept_finite_) return {}; // the last substep's row sweep already checked every particle
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
        const Vec3 a = f / mass_[p];
        Vec3 x = pos_[p];
        if (semi) {
          v += a * dt;
          x += v * dt;
        } else {
          x += v * dt;
          v += a * dt;
        }
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
      // Whole vectors in SIMD, a remainder shorter than one vector through the scalar kernel;
      // then the finite check of what was written that the SIMD kernel did not check already.
      const Real limit = Real(params_.divergence_limit);
      ra.limit = limit;
      Real* const pn = &pos_next_[0].x;
      Real* const vn = &vel_[0].x;
      auto kernel = [&](std::int64_t q0, std::int64_t q1, unsigned& bad_here) {
        std::int64_t done = q0;
        bool simd_bad = false;
#if VKCLOTH_ROW_SIMD
        if (simd_ == 2) done = detail::row_kernel_avx512(ra, done, q1, simd_bad);
        else if (simd_ == 1) done = detail::row_kernel_avx2(ra, done, q1, simd_bad);
#endif
        if (done < q1) row_kernel(ra, done, q1);
        if (!kernel_integrates) {
          for (std::int64_t q = q0; q < q1; ++q) finish(std::size_t(q), force_[std::size_t(q)]);
          done = q0;
        }
        bad_here |= unsigned(simd_bad) | bad_components(pn + 3 * done, vn + 3 * done, std::size_t(3 * (q1 - done)), limit);
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
        if (bad_here) bad.store(true, std::memory_order_relaxed);
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
      for (auto& k : k_pos_) k.resize(n);
      for (auto& k : k_vel_) k.resize(n);
      stage_pos_.resize(n);
      stage_vel_.resize(n);
    }
    const Real c[4] = {Real(0), dt / Real(2), dt / Real(2), dt};
    for (int s = 0; s < 4; ++s) {
      if (s == 0) {
        stage_pos_ = pos_;
        stage_vel_ = vel_;
      } else {
        for_particles([&](std::size_t p) {
          stage_pos_[p] = pos_[p] + k_pos_[s - 1][p] * c[s];
          stage_vel_[p] = vel_[p] + k_vel_[s - 1][p] * c[s];
        });
      }
      for_particles([&](std::size_t p) {
        Vec3 f = normal_force_at(stage_pos_, stage_vel_, p);
        if (!pinned_[p]) contact_at(stage_pos_[p], stage_vel_[p], f);
        if (s == 0) force_[p] = f;
        k_pos_[s][p] = pinned_[p] ? Vec3(0) : stage_vel_[p];
        k_vel_[s][p] = pinned_[p] ? Vec3(0) : f / mass_[p];
      });
    }
    const Real w = dt / Real(6);
    for_particles([&](std::size_t p) {
      if (pinned_[p]) return;
      Vec3 dp = k_pos_[0][p] + k_pos_[1][p] * Real(2);
      dp += k_pos_[2][p] * Real(2);
      dp += k_pos_[3][p];
      Vec3 dv = k_vel_[0][p] + k_vel_[1][p] * Real(2);
      dv += k_vel_[2][p] * Real(2);
      dv += k_vel_[3][p];
      pos_[p] += dp * w;
      vel_[p] += dv * w;
      project_at(pos_[p], vel_[p]);
    });
    break;
  }
  }
}

template <typename Real> Result<void> CpuSolver<Real>::run(std::uint64_t steps) {
  for (std::uint64_t s = 0; s < steps; ++s) VKCLOTH_TRY(step());
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
