// SPDX-License-Identifier: MIT
// The interior row kernel, vectorised across particles with GCC vector extensions. Included by
// row_kernel_avx2.cpp / row_kernel_avx512.cpp after they define, inside an anonymous namespace,
// the ISA traits `IsaF` / `IsaD` (Real, V = W lanes of Real, M = W lanes of same-width ints,
// sqrt, pin mask, AoS load3/store3). Everything here has internal linkage, so the two ISA
// translation units never share (ODR-merge) a function compiled for the other's ISA.
//
// An optimised copy of the shared kernel (engine/kernel/cloth_kernel.h: add_fan_triangle,
// add_ring_term, unit_or_zero, add_spring, add_body_forces, euler_update, diverged), the one place a formula
// is written twice: GCC vector types cannot pass through the kernel's scalar-typed functions. Bits: every
// lane performs the kernel's operations on its particle, one for one and in the same order; IEEE +, -, *, /
// and sqrt are correctly rounded in SIMD as in scalar code, -ffp-contract=off forbids FMA, `if (len > 0)` is
// the same select. tests/test_cloth.cpp "the SIMD row kernels ... give the shared reference's bits" fails
// when they differ: change both together. Do not include anything else here (no std headers with inline
// functions: see above).

namespace {

template <typename T> inline typename T::V ld(const typename T::Real* p) {
  typename T::V v;
  __builtin_memcpy(&v, p, sizeof v);
  return v;
}
template <typename T> inline typename T::V bc(typename T::Real x) {
  return typename T::V{} + x;
}

template <bool B> struct Flag { static constexpr bool value = B; };

#define VKCLOTH_AI inline __attribute__((always_inline))

// The end of one vector's step, shared by the row and list kernels: add_body_forces (gravity,
// damping, wind), the normal and force stores and, when integrating, euler_update with the pins
// and check_finite's test. `skipped` lanes (a tail vector's, done already) are left out of the
// check; put3 stores AoS (and knows the tail); put_soa stores the next positions' SoA copy (the
// row kernel's; the list kernel has none).
template <typename T, bool wind, bool integrate, bool semi> struct StepTail {
  using Real = typename T::Real;
  using V = typename T::V;
  using M = typename T::M;
  // Copies of the arguments' pointers: stores through them cannot change these (nor the args).
  const Real* __restrict mass;
  const std::uint8_t* __restrict pinned;
  Real* __restrict vel;
  Real* __restrict force_out;
  Real* __restrict normal_out;
  Real* __restrict pos_next;
  Real gx_, gy_, gz_, damping_, kw_, wx_, wy_, wz_, dt_, limit_; // broadcast where used (registers are few)

  explicit StepTail(const vkcloth::detail::StepArgs<Real>& args)
      : mass(args.mass), pinned(args.pinned), vel(args.vel_out), force_out(args.force_out),
        normal_out(args.normal_out), pos_next(args.pos_next), gx_(args.gx), gy_(args.gy), gz_(args.gz),
        damping_(args.damping), kw_(args.kw), wx_(args.wx), wy_(args.wy), wz_(args.wz), dt_(args.dt),
        limit_(args.limit) {}

  template <typename Put3, typename PutSoa>
  VKCLOTH_AI void operator()(std::int64_t q, V x0, V y0, V z0, V fx, V fy, V fz, V nxv, V nyv, V nzv,
                             M skipped, M& ok, Put3 put3, PutSoa put_soa) const {
    const V zero = V{}, gx = bc<T>(gx_), gy = bc<T>(gy_), gz = bc<T>(gz_), damping = bc<T>(damping_),
            kw = bc<T>(kw_), wx = bc<T>(wx_), wy = bc<T>(wy_), wz = bc<T>(wz_), dt = bc<T>(dt_),
            lim = bc<T>(limit_), nlim = bc<T>(-limit_);
    const V m = ld<T>(mass + q);
    fx = fx + gx * m;
    fy = fy + gy * m;
    fz = fz + gz * m;
    V vx, vy, vz;
    T::load3(vel + 3 * q, vx, vy, vz);
    const V dm = damping * m;
    fx = fx - vx * dm;
    fy = fy - vy * dm;
    fz = fz - vz * dm;
    if constexpr (wind) {
      const V kn = kw * (nxv * wx + nyv * wy + nzv * wz);
      fx = fx + nxv * kn;
      fy = fy + nyv * kn;
      fz = fz + nzv * kn;
    }
    put3(normal_out + 3 * q, nxv, nyv, nzv);
    put3(force_out + 3 * q, fx, fy, fz);
    if constexpr (integrate) {
      const V ax = fx / m, ay = fy / m, az = fz / m;
      // The current position is x0, y0, z0.
      V nvx, nvy, nvz, nxx, nxy, nxz;
      if constexpr (semi) {
        nvx = vx + ax * dt;
        nvy = vy + ay * dt;
        nvz = vz + az * dt;
        nxx = x0 + nvx * dt;
        nxy = y0 + nvy * dt;
        nxz = z0 + nvz * dt;
      } else {
        nxx = x0 + vx * dt;
        nxy = y0 + vy * dt;
        nxz = z0 + vz * dt;
        nvx = vx + ax * dt;
        nvy = vy + ay * dt;
        nvz = vz + az * dt;
      }
      const M pin = T::pinmask(pinned + q);
      const V ox = pin ? x0 : nxx, oy = pin ? y0 : nxy, oz = pin ? z0 : nxz;
      put3(pos_next + 3 * q, ox, oy, oz);
      put_soa(ox, oy, oz);
      const V ux = pin ? vx : nvx, uy = pin ? vy : nvy, uz = pin ? vz : nvz;
      put3(vel + 3 * q, ux, uy, uz);
      // check_finite's test (bad_components), lane by lane: |x| <= limit (false for NaN) is
      // x <= limit and -limit <= x; c - c == 0 fails for inf and NaN.
      const M good = (ox <= lim) & (nlim <= ox) & (ox - ox == zero) & (oy <= lim) & (nlim <= oy) &
                     (oy - oy == zero) & (oz <= lim) & (nlim <= oz) & (oz - oz == zero) & (ux - ux == zero) &
                     (uy - uy == zero) & (uz - uz == zero);
      ok = ok & (good | skipped);
    }
  }
};

// unit_or_zero, lane by lane: the fan sum over its length, zero where the length is not > 0.
template <typename T>
VKCLOTH_AI void unit_or_zero_v(typename T::V sx, typename T::V sy, typename T::V sz, typename T::V& nx,
                               typename T::V& ny, typename T::V& nz) {
  using V = typename T::V;
  const V zero = V{};
  const V nlen = T::sqrt(sx * sx + sy * sy + sz * sz);
  const typename T::M npos = nlen > zero;
  const V qx = sx / nlen, qy = sy / nlen, qz = sz / nlen;
  nx = npos ? qx : zero;
  ny = npos ? qy : zero;
  nz = npos ? qz : zero;
}

// add_spring, lane by lane, for the lanes of `present` (u = the neighbour's position - x).
template <typename T>
VKCLOTH_AI void add_spring_v(typename T::V& fx, typename T::V& fy, typename T::V& fz, typename T::V ux,
                             typename T::V uy, typename T::V uz, typename T::V rest, typename T::V k,
                             typename T::M present) {
  using V = typename T::V;
  const V len = T::sqrt(ux * ux + uy * uy + uz * uz);
  const V c = k * (len - rest) / len;
  const typename T::M pos = (len > V{}) & present;
  const V tx = fx + ux * c, ty = fy + uy * c, tz = fz + uz * c;
  fx = pos ? tx : fx;
  fy = pos ? ty : fy;
  fz = pos ? tz : fz;
}

// Every lane of m is set.
template <typename T> VKCLOTH_AI bool all_lanes(typename T::M m) {
  bool r = true;
  for (int l = 0; l < T::W; ++l)
    r = r && m[l] != 0;
  return r;
}

// Sets `bad` when some lane of `ok` is false.
template <typename T> VKCLOTH_AI void report_bad(typename T::M ok, bool& bad) {
  if (!all_lanes<T>(ok))
    bad = true;
}

// One vector of W particles per iteration: normal fan, the 12 stencil springs, body forces, the
// Euler update and the finite check, in the kernel's order. One loop body whose values stay in
// vector registers: the pieces it shares with the list kernel (StepTail, add_spring_v,
// unit_or_zero_v) are always inlined, since across real calls GCC spills the 16-lane temporaries.
template <typename T, bool wind, bool integrate, bool semi>
std::int64_t simd_body(const vkcloth::detail::RowArgs<typename T::Real>& a, std::int64_t q0, std::int64_t q1,
                       bool& bad) {
  using Real = typename T::Real;
  using V = typename T::V;
  using M = typename T::M;
  constexpr int W = T::W;
  const Real* __restrict px = a.px;
  const Real* __restrict py = a.py;
  const Real* __restrict pz = a.pz;
  const std::uint16_t* __restrict mask = a.mask;
  Real* __restrict sxn = a.sx_next;
  Real* __restrict syn = a.sy_next;
  Real* __restrict szn = a.sz_next;
  const V zero = V{};
  const StepTail<T, wind, integrate, semi> step_tail(a);
  M lane{}; // lane index, to leave a tail vector's skipped lanes out of the finite check
  for (int l = 0; l < W; ++l)
    lane[l] = l;
  M ok = lane == lane; // all lanes true: every value written so far passed the finite check
  const std::int64_t nx = a.nx;
  std::int64_t O[12];
  V L[12], K[12];
  for (int k = 0; k < 12; ++k) {
    O[k] = a.off[k];
    L[k] = bc<T>(a.rest[k]);
    K[k] = bc<T>(a.stiff[k]);
  }
  // One vector of W particles from q; with Tail, the first `skip` lanes were done already and only
  // the others are stored (the overlapped last vector of a run: the skipped lanes read velocities
  // updated in place, but their results are thrown away; the stored lanes read only their own).
  // With Masked, each lane's spring and fan terms are selected by its mask (border particles).
  auto vec = [&](std::int64_t q, int skip, auto tail, auto masked) {
    constexpr bool Tail = decltype(tail)::value;
    constexpr bool Masked = decltype(masked)::value;
    auto put3 = [&](Real* p, V x, V y, V z) {
      if constexpr (!Tail) {
        T::store3(p, x, y, z);
      } else {
        Real buf[3 * W];
        T::store3(buf, x, y, z);
        __builtin_memcpy(p + 3 * skip, buf + 3 * skip, sizeof(Real) * std::size_t(3 * (W - skip)));
      }
    };
    auto put = [&](Real* p, V x) {
      if constexpr (!Tail) {
        __builtin_memcpy(p, &x, sizeof x);
      } else {
        Real buf[W];
        __builtin_memcpy(buf, &x, sizeof x);
        __builtin_memcpy(p + skip, buf + skip, sizeof(Real) * std::size_t(W - skip));
      }
    };
    M mk{};
    if constexpr (Masked)
      mk = T::loadmask(mask + q);
    auto has = [&](int bit) -> M { return (mk & (1 << bit)) != 0; }; // only used when Masked
    const V x0 = ld<T>(px + q), y0 = ld<T>(py + q), z0 = ld<T>(pz + q);
    const V e0x = ld<T>(px + q + 1) - x0, e0y = ld<T>(py + q + 1) - y0, e0z = ld<T>(pz + q + 1) - z0;
    const V e1x = ld<T>(px + q + nx) - x0, e1y = ld<T>(py + q + nx) - y0, e1z = ld<T>(pz + q + nx) - z0;
    const V e2x = ld<T>(px + q - 1) - x0, e2y = ld<T>(py + q - 1) - y0, e2z = ld<T>(pz + q - 1) - z0;
    const V e3x = ld<T>(px + q - nx) - x0, e3y = ld<T>(py + q - nx) - y0, e3z = ld<T>(pz + q - nx) - z0;
    V sx = zero, sy = zero, sz = zero;
#define VKCLOTH_CROSS_ADD(bit, ax, ay, az, bx, by, bz)                                                       \
  if constexpr (Masked) {                                                                                    \
    const M h = has(bit);                                                                                    \
    sx = h ? sx + (ay * bz - by * az) : sx;                                                                  \
    sy = h ? sy + (az * bx - bz * ax) : sy;                                                                  \
    sz = h ? sz + (ax * by - bx * ay) : sz;                                                                  \
  } else {                                                                                                   \
    sx = sx + (ay * bz - by * az);                                                                           \
    sy = sy + (az * bx - bz * ax);                                                                           \
    sz = sz + (ax * by - bx * ay);                                                                           \
  }
    VKCLOTH_CROSS_ADD(12, e0x, e0y, e0z, e1x, e1y, e1z)
    VKCLOTH_CROSS_ADD(13, e1x, e1y, e1z, e2x, e2y, e2z)
    VKCLOTH_CROSS_ADD(14, e2x, e2y, e2z, e3x, e3y, e3z)
    VKCLOTH_CROSS_ADD(15, e3x, e3y, e3z, e0x, e0y, e0z)
#undef VKCLOTH_CROSS_ADD
    V nxv, nyv, nzv;
    unit_or_zero_v<T>(sx, sy, sz, nxv, nyv, nzv);
    V fx = zero, fy = zero, fz = zero;
    const M all = lane == lane;
#pragma GCC unroll 12
    for (int k = 0; k < 12; ++k) {
      const std::int64_t r = q + O[k];
      add_spring_v<T>(fx, fy, fz, ld<T>(px + r) - x0, ld<T>(py + r) - y0, ld<T>(pz + r) - z0, L[k], K[k],
                      Masked ? has(k) : all);
    }
    step_tail(q, x0, y0, z0, fx, fy, fz, nxv, nyv, nzv, Tail ? M(lane < skip) : M{}, ok, put3,
              [&](V ox, V oy, V oz) {
                put(sxn + q, ox);
                put(syn + q, oy);
                put(szn + q, oz);
              });
  };
  // Interior vectors (all W masks full) take the unmasked code; with no mask array, all do.
  auto full = [&](std::int64_t q) {
    if (!mask)
      return true;
    constexpr int words = W / 4; // 4 masks per 64-bit word (W is a multiple of 4)
    std::uint64_t w[words];
    __builtin_memcpy(w, mask + q, sizeof w);
    std::uint64_t acc = ~std::uint64_t(0);
    for (int l = 0; l < words; ++l)
      acc &= w[l];
    return acc == ~std::uint64_t(0);
  };
  std::int64_t done = q0;
  for (; done + W <= q1; done += W) {
    if (full(done))
      vec(done, 0, Flag<false>{}, Flag<false>{});
    else
      vec(done, 0, Flag<false>{}, Flag<true>{});
  }
  if (done < q1 && q1 - q0 >= W) { // the remainder as one vector overlapping the previous one
    const std::int64_t q = q1 - W;
    if (full(q))
      vec(q, int(W - (q1 - done)), Flag<true>{}, Flag<false>{});
    else
      vec(q, int(W - (q1 - done)), Flag<true>{}, Flag<true>{});
    done = q1;
  }
  if constexpr (integrate)
    report_bad<T>(ok, bad);
  return done;
}

// Calls fn(Flag<wind>, Flag<integrate>, Flag<semi>) with the arguments' flags as constants.
template <typename Args, typename Fn> VKCLOTH_AI std::int64_t with_flags(const Args& a, Fn fn) {
  using F = Flag<false>;
  using R = Flag<true>;
  switch ((a.wind ? 4 : 0) | (a.integrate ? 2 : 0) | (a.semi ? 1 : 0)) {
  case 0:
    return fn(F{}, F{}, F{});
  case 1:
    return fn(F{}, F{}, R{});
  case 2:
    return fn(F{}, R{}, F{});
  case 3:
    return fn(F{}, R{}, R{});
  case 4:
    return fn(R{}, F{}, F{});
  case 5:
    return fn(R{}, F{}, R{});
  case 6:
    return fn(R{}, R{}, F{});
  default:
    return fn(R{}, R{}, R{});
  }
}

template <typename T>
std::int64_t simd_dispatch(const vkcloth::detail::RowArgs<typename T::Real>& a, std::int64_t q0,
                           std::int64_t q1, bool& bad) {
  return with_flags(a, [&](auto wind, auto integrate, auto semi) {
    return simd_body<T, decltype(wind)::value, decltype(integrate)::value, decltype(semi)::value>(a, q0, q1,
                                                                                                  bad);
  });
}

// ---- Three-lane-vector helpers (the list kernel, the contact finish) -------------------------

template <typename T> struct V3 { typename T::V x, y, z; };

template <typename T> VKCLOTH_AI V3<T> bc3(const typename T::Real* p) {
  return {bc<T>(p[0]), bc<T>(p[1]), bc<T>(p[2])};
}
template <typename T> VKCLOTH_AI V3<T> operator+(V3<T> a, V3<T> b) {
  return {a.x + b.x, a.y + b.y, a.z + b.z};
}
template <typename T> VKCLOTH_AI V3<T> operator-(V3<T> a, V3<T> b) {
  return {a.x - b.x, a.y - b.y, a.z - b.z};
}
template <typename T> VKCLOTH_AI V3<T> operator*(V3<T> a, typename T::V s) {
  return {a.x * s, a.y * s, a.z * s};
}
template <typename T> VKCLOTH_AI V3<T> operator/(V3<T> a, typename T::V s) {
  return {a.x / s, a.y / s, a.z / s};
}
template <typename T> VKCLOTH_AI V3<T> sel(typename T::M m, V3<T> a, V3<T> b) {
  return {m ? a.x : b.x, m ? a.y : b.y, m ? a.z : b.z};
}
// dot3: a.x b.x + a.y b.y, then + a.z b.z.
template <typename T> VKCLOTH_AI typename T::V dot(V3<T> a, V3<T> b) {
  const typename T::V r = a.x * b.x + a.y * b.y;
  return r + a.z * b.z;
}
// cross3 in glm::cross's order.
template <typename T> VKCLOTH_AI V3<T> cross(V3<T> x, V3<T> y) {
  return {x.y * y.z - y.y * x.z, x.z * y.x - y.z * x.x, x.x * y.y - y.x * x.y};
}
// ---- The list kernel: meshes and other cloths without a stencil (ListArgs) ---------------------
// The same step as simd_body, the springs read from the padded lists instead of at constant
// offsets: per slot, the W lanes' neighbours' positions come from T::gather3 (the float ISAs: one
// 16-byte load per lane and a transpose; the lanes' neighbours differ). A vector's lanes walk as many slots
// as its longest list; the padding adds nothing (row_kernel.hpp ListArgs), so each lane sums its own terms in
// its list's order, with the kernel's operations: the reference's bits. The normal comes from the same edges
// (cloth_kernel.h add_ring_term), in the slots before ring_end. A vector whose lists name the last particle
// gathers with gather3_last (T::gather3 may read one float past the particle it loads).

template <typename T> VKCLOTH_AI typename T::M load_index(const std::uint32_t* p) {
  typename T::M m;
  for (int l = 0; l < T::W; ++l)
    m[l] = p[l];
  return m;
}

// add_ring_term, lane by lane: `ring` holds each lane's VKCLOTH_RING_* bits.
template <typename T>
VKCLOTH_AI void add_ring_term_v(V3<T>& sum, V3<T>& prev, V3<T>& first, V3<T> u, typename T::M ring) {
  using M = typename T::M;
  const M start = (ring & (M{} + VKCLOTH_RING_START)) != 0;
  const M with_prev = (ring & (M{} + VKCLOTH_RING_PREV)) != 0;
  const M close = (ring & (M{} + VKCLOTH_RING_CLOSE)) != 0;
  first = sel<T>(start, u, first);
  sum = sel<T>(with_prev, sum + cross<T>(prev, u), sum);
  sum = sel<T>(close, sum + cross<T>(u, first), sum);
  prev = u;
}

template <typename T, bool wind, bool integrate, bool semi>
std::int64_t list_body(const vkcloth::detail::ListArgs<typename T::Real>& a, std::int64_t v0, std::int64_t v1,
                       bool& bad) {
  using Real = typename T::Real;
  using V = typename T::V;
  using M = typename T::M;
  constexpr int W = T::W;
  const Real* __restrict pos = a.pos;
  const StepTail<T, wind, integrate, semi> step_tail(a);
  M lane{};
  for (int l = 0; l < W; ++l)
    lane[l] = l;
  const M all = lane == lane;
  M ok = all;
  const V zero = V{};
  for (std::int64_t b = v0; b < v1; ++b) {
    const std::int64_t q = b * W;
    V xs, ys, zs;
    T::load3(pos + 3 * q, xs, ys, zs);
    const V3<T> x0{xs, ys, zs};
    V3<T> f{zero, zero, zero}, fan{zero, zero, zero}, prev{zero, zero, zero}, first{zero, zero, zero};
    const bool reads_last = a.reads_last[b];
    auto spring = [&](std::uint32_t s) {
      V xq, yq, zq;
      if (reads_last)
        T::gather3_last(pos, a.other + s, xq, yq, zq);
      else
        T::gather3(pos, a.other + s, xq, yq, zq);
      const V3<T> u{xq - x0.x, yq - x0.y, zq - x0.z};
      add_spring_v<T>(f.x, f.y, f.z, u.x, u.y, u.z, ld<T>(a.rest + s), ld<T>(a.stiff + s), all);
      return u;
    };
    std::uint32_t s = a.spring_begin[b];
    for (; s < a.ring_end[b]; s += W)
      add_ring_term_v<T>(fan, prev, first, spring(s), load_index<T>(a.ring + s));
    for (; s < a.spring_begin[b + 1]; s += W)
      spring(s);
    V nxv, nyv, nzv;
    unit_or_zero_v<T>(fan.x, fan.y, fan.z, nxv, nyv, nzv);
    step_tail(
        q, x0.x, x0.y, x0.z, f.x, f.y, f.z, nxv, nyv, nzv, M{}, ok,
        [](Real* p, V x, V y, V z) { T::store3(p, x, y, z); }, [](V, V, V) {});
  }
  if constexpr (integrate)
    report_bad<T>(ok, bad);
  return v1;
}

template <typename T>
std::int64_t list_dispatch(const vkcloth::detail::ListArgs<typename T::Real>& a, std::int64_t v0,
                           std::int64_t v1, bool& bad) {
  return with_flags(a, [&](auto wind, auto integrate, auto semi) {
    return list_body<T, decltype(wind)::value, decltype(integrate)::value, decltype(semi)::value>(a, v0, v1,
                                                                                                  bad);
  });
}

// ---- Contacts: the finish of a grid substep with colliders (FinishArgs) -----------------------
// The second optimised copy of the shared kernel: cloth_kernel.h collider_contact (plane, sphere,
// capsule, box), remove_inward, contact_filter, coulomb_friction, contact_response, surface_velocity,
// project_out and euler_update, as CpuSolver::euler_finish calls them, W particles per vector. The
// collider's type is the same for every lane (a switch per collider); each `if` on a per-particle
// value becomes a select between values computed for every lane, each expression written in the
// kernel's order (glm's min, max and abs: (y < x) ? y : x, (x < y) ? y : x, x >= 0 ? x : -x).
// tests/test_cloth.cpp "the SIMD row kernels ... give the shared reference's bits" covers it.

// glm's scalar max(x, y) = (x < y) ? y : x, lane by lane.
template <typename T> VKCLOTH_AI typename T::V vmax(typename T::V x, typename T::V y) {
  return x < y ? y : x;
}
template <typename T> VKCLOTH_AI typename T::V vmin(typename T::V x, typename T::V y) {
  return y < x ? y : x;
}

// Some lane of m is set (a branch that skips work whose result every lane would drop).
template <typename T> VKCLOTH_AI bool any(typename T::M m) {
  bool r = false;
  for (int l = 0; l < T::W; ++l)
    r = r || m[l] != 0;
  return r;
}

// surface_velocity: velocity + cross3(spin, p - pivot).
template <typename T>
VKCLOTH_AI V3<T> surface_velocity_v(const vkcloth::detail::FinishShape<typename T::Real>& s, V3<T> p) {
  return bc3<T>(s.velocity) + cross<T>(bc3<T>(s.spin), p - bc3<T>(s.pivot));
}

// collider_contact for a plane, sphere, capsule or box (0..3): the signed distance and the normal.
// The normal only when some lane's distance is below `wanted` (the caller uses it nowhere else):
// returns false, normal unset, when none is.
template <typename T>
VKCLOTH_AI bool collider_contact_v(const vkcloth::detail::FinishShape<typename T::Real>& s, V3<T> p,
                                   typename T::V wanted, typename T::V& distance, V3<T>& normal) {
  using Real = typename T::Real;
  using V = typename T::V;
  using M = typename T::M;
  const V zero = V{}, one = bc<T>(Real(1));
  const V3<T> a = bc3<T>(s.a);
  if (s.type == 0) { // plane
    distance = dot<T>(a, p) - bc<T>(s.b);
    normal = a;
    return any<T>(distance < wanted);
  }
  if (s.type == 1 || s.type == 2) { // sphere; capsule: the segment's nearest point first
    V3<T> r = p - a;
    if (s.type == 2) {
      const Real axis[3] = {s.c[0] - s.a[0], s.c[1] - s.a[1], s.c[2] - s.a[2]};
      Real len2 = axis[0] * axis[0] + axis[1] * axis[1];
      len2 = len2 + axis[2] * axis[2];
      const V3<T> ax = bc3<T>(axis);
      V t = zero;
      if (len2 > Real(0))
        t = dot<T>(p - a, ax) / bc<T>(len2);
      t = vmin<T>(vmax<T>(t, zero), one);
      r = p - (a + ax * t);
    }
    const V len = T::sqrt(dot<T>(r, r));
    distance = len - bc<T>(s.b);
    if (!any<T>(distance < wanted))
      return false;
    const M pos = len > zero;
    normal = sel<T>(pos, r / len, V3<T>{zero, zero, one});
    return true;
  }
  // box: q = R^T (p - centre)
  const V3<T> ax = bc3<T>(s.ax), ay = bc3<T>(s.ay), az = bc3<T>(s.az);
  const V3<T> r = p - a;
  const V3<T> q{dot<T>(ax, r), dot<T>(ay, r), dot<T>(az, r)};
  const V3<T> c = bc3<T>(s.c);
  const V3<T> aq{q.x >= zero ? q.x : -q.x, q.y >= zero ? q.y : -q.y, q.z >= zero ? q.z : -q.z};
  const V3<T> over = aq - c;
  const V3<T> out{vmax<T>(over.x, zero), vmax<T>(over.y, zero), vmax<T>(over.z, zero)};
  const V out_len = T::sqrt(dot<T>(out, out));
  const M outside = out_len > zero;
  // Inside: out through the nearest face (x, then y if deeper, then z).
  V d = over.x;
  const M y_deeper = over.y > d;
  d = y_deeper ? over.y : d;
  const M z_deeper = over.z > d;
  d = z_deeper ? over.z : d;
  distance = outside ? out_len : d;
  if (!any<T>(distance < wanted))
    return false;
  const V3<T> sgn{q.x < zero ? -one : one, q.y < zero ? -one : one, q.z < zero ? -one : one};
  const V3<T> nb_out{(out.x * sgn.x) / out_len, (out.y * sgn.y) / out_len, (out.z * sgn.z) / out_len};
  V3<T> nb_in{sgn.x, zero, zero};
  nb_in = sel<T>(y_deeper, V3<T>{zero, sgn.y, zero}, nb_in);
  nb_in = sel<T>(z_deeper, V3<T>{zero, zero, sgn.z}, nb_in);
  const V3<T> nb = sel<T>(outside, nb_out, nb_in);
  // to_world_dir: ax nb.x + ay nb.y, then + az nb.z.
  normal = (ax * nb.x + ay * nb.y) + az * nb.z;
  return true;
}

// remove_inward on the lanes of `active`: w loses its part along n when <w, n> < 0 (or != 0 with `both`).
template <typename T> VKCLOTH_AI void remove_inward_v(V3<T>& w, V3<T> n, bool both, typename T::M active) {
  const typename T::V zero{};
  const typename T::V wn = dot<T>(w, n);
  typename T::M cond = wn < zero;
  if (both)
    cond = cond | (wn != zero);
  w = sel<T>(active & cond, w - n * wn, w);
}

template <typename T>
std::int64_t simd_finish(const vkcloth::detail::FinishArgs<typename T::Real>& a, std::int64_t q0,
                         std::int64_t q1) {
  using Real = typename T::Real;
  using V = typename T::V;
  using M = typename T::M;
  constexpr int W = T::W;
  const V zero{};
  const V dt = bc<T>(a.dt), band = bc<T>(a.band), eps = bc<T>(a.eps);
  const M all = zero == zero;
  std::int64_t q = q0;
  for (; q + W <= q1; q += W) {
    const V3<T> x0{ld<T>(a.px + q), ld<T>(a.py + q), ld<T>(a.pz + q)};
    V fx, fy, fz, vx, vy, vz;
    T::load3(a.force + 3 * q, fx, fy, fz);
    T::load3(a.vel + 3 * q, vx, vy, vz);
    const V3<T> f0{fx, fy, fz}, v0{vx, vy, vz};
    const V m = ld<T>(a.mass + q);
    const V h_over_m = dt / m;
    V3<T> v = v0, f = f0;
    // contact_at: each collider's response at the substep's start position.
    for (std::uint32_t k = 0; k < a.shape_count; ++k) {
      const vkcloth::detail::FinishShape<Real>& s = a.shapes[k];
      V distance;
      V3<T> n;
      if (!collider_contact_v<T>(s, x0, band, distance, n))
        continue; // no lane in contact with this collider: nothing changes
      const M in_band = distance < band;
      if (!s.moving && s.mu_s == Real(0) && s.mu_k == Real(0)) { // contact_filter
        remove_inward_v<T>(v, n, a.both, in_band);
        remove_inward_v<T>(f, n, a.both, in_band);
        continue;
      }
      const V3<T> vs = s.moving ? surface_velocity_v<T>(s, x0) : V3<T>{zero, zero, zero};
      V3<T> w = v - vs, g = f;
      const V wn = dot<T>(w, n), fn = dot<T>(g, n);
      remove_inward_v<T>(w, n, a.both, all);
      remove_inward_v<T>(g, n, a.both, all);
      const V j = vmax<T>(-wn, zero) + vmax<T>(-fn, zero) * h_over_m;
      // coulomb_friction
      const V3<T> wt = w - n * dot<T>(w, n);
      const V3<T> ft = g - n * dot<T>(g, n);
      const V3<T> slip = wt + ft * h_over_m;
      const V slip_len = T::sqrt(dot<T>(slip, slip));
      const V hold = bc<T>(s.mu_s) * j;
      const V kinetic = bc<T>(s.mu_k) * j / slip_len;
      const V kf = slip_len > hold ? kinetic : bc<T>(Real(1));
      const V3<T> nw = w - wt * kf;
      const V3<T> nf = g - ft * kf;
      v = sel<T>(in_band, nw + vs, v);
      f = sel<T>(in_band, nf, f);
    }
    // euler_update
    const V3<T> acc = f / m;
    V3<T> x, u;
    if (a.semi) {
      u = v + acc * dt;
      x = x0 + u * dt;
    } else {
      x = x0 + v * dt;
      u = v + acc * dt;
    }
    // project_at: each collider's projection of the new position.
    for (std::uint32_t k = 0; k < a.shape_count; ++k) {
      const vkcloth::detail::FinishShape<Real>& s = a.shapes[k];
      V distance;
      V3<T> n;
      if (!collider_contact_v<T>(s, x, zero, distance, n))
        continue; // no lane inside this collider: nothing moves
      const M inside = distance < zero;
      V3<T> xp;
      if (s.type == 1) {
        const Real r = s.b + a.eps;
        xp = bc3<T>(s.a) + n * bc<T>(r);
      } else {
        const V back = eps - distance;
        xp = x + n * back;
      }
      x = sel<T>(inside, xp, x);
      if (!s.moving) {
        remove_inward_v<T>(u, n, false, inside);
        continue;
      }
      const V3<T> vs = surface_velocity_v<T>(s, x);
      V3<T> w = u - vs;
      remove_inward_v<T>(w, n, false, all);
      u = sel<T>(inside, w + vs, u);
    }
    const M pin = T::pinmask(a.pinned + q);
    const V3<T> xo = sel<T>(pin, x0, x), vo = sel<T>(pin, v0, u), fo = sel<T>(pin, f0, f);
    T::store3(a.force + 3 * q, fo.x, fo.y, fo.z);
    T::store3(a.pos_next + 3 * q, xo.x, xo.y, xo.z);
    T::store3(a.vel + 3 * q, vo.x, vo.y, vo.z);
    __builtin_memcpy(a.sx_next + q, &xo.x, sizeof(V));
    __builtin_memcpy(a.sy_next + q, &xo.y, sizeof(V));
    __builtin_memcpy(a.sz_next + q, &xo.z, sizeof(V));
  }
  return q;
}
#undef VKCLOTH_AI

// Generic AoS <-> SoA and pin mask by lanes (the ISA files specialise the hot float cases).
template <typename Real, typename V, typename M, int W> struct IsaGeneric {
  static void load3(const Real* p, V& x, V& y, V& z) {
    for (int l = 0; l < W; ++l) {
      x[l] = p[3 * l];
      y[l] = p[3 * l + 1];
      z[l] = p[3 * l + 2];
    }
  }
  static void store3(Real* p, V x, V y, V z) {
    for (int l = 0; l < W; ++l) {
      p[3 * l] = x[l];
      p[3 * l + 1] = y[l];
      p[3 * l + 2] = z[l];
    }
  }
  // The positions of the W particles index[0..W) names, from AoS storage.
  static void gather3(const Real* pos, const std::uint32_t* index, V& x, V& y, V& z) {
    for (int l = 0; l < W; ++l) {
      const Real* p = pos + 3 * std::size_t(index[l]);
      x[l] = p[0];
      y[l] = p[1];
      z[l] = p[2];
    }
  }
  // The same where index may name the last particle (the ISA files' gather3 reads past it).
  static void gather3_last(const Real* pos, const std::uint32_t* index, V& x, V& y, V& z) {
    IsaGeneric::gather3(pos, index, x, y, z);
  }
  static M pinmask(const std::uint8_t* p) {
    M m;
    for (int l = 0; l < W; ++l)
      m[l] = p[l] ? -1 : 0;
    return m;
  }
  static M loadmask(const std::uint16_t* p) {
    M m;
    for (int l = 0; l < W; ++l)
      m[l] = p[l];
    return m;
  }
};

} // namespace
