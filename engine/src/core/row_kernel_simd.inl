// SPDX-License-Identifier: MIT
// The CPU's SIMD kernels: the grid's row kernel, the list kernel (meshes) and the contacts' finish,
// W particles per vector (vertex block descent's: simd_vbd.inl, included at the end). Included by
// row_kernel_avx2.cpp / row_kernel_avx512.cpp after simd_lanes.inl and their ISA traits IsaF / IsaD (float,
// double); everything has internal linkage.
//
// No formula is written here: every term is the shared kernel's function (engine/kernel:
// add_fan_triangle, add_spring, add_spring_edge, add_ring_term, unit_or_zero, add_body_forces,
// euler_update, diverged, collider_contact, contact_response, project_out), compiled below on lanes
// (simd_kernel.inl: real = W lanes of Real), called in the order the per-particle reference
// (cpu_solver.cpp normal_force_at, euler_finish) calls it. This file loads and stores the lanes,
// selects which lanes a term applies to (a border particle's stencil mask, pins, a tail vector's
// lanes) and loops. Bits: each lane performs the reference's operations on its particle
// (simd_lanes.inl); tests/test_cloth.cpp "the SIMD row kernels ... give the shared reference's
// bits" and "the SIMD list kernel ..." fail when they differ.

#include "internal/kernel.hpp" // the scalar kernel: a mesh collider's search, lane by lane

/// MESH_DATA on lanes: a mesh collider's hierarchy and search entries and its shape as the scalar
/// kernel takes them (null for the other shapes), and the lanes' particles: index[l], or first + l.
template <typename Isa> struct LaneMesh {
  const vkcloth::kernel::MeshData* mesh = nullptr;
  const vkcloth::kernel::ColliderShape<typename Isa::Real>* scalar = nullptr;
  const std::uint32_t* index = nullptr;
  std::uint32_t first = 0;
  std::uint32_t particle(int l) const { return index ? index[l] : first + std::uint32_t(l); }
};

#define VKCLOTH_KERNEL_LANES // the kernel's macros on lanes (kernel/language.h)
#include "kernel/language.h"

namespace {
namespace lanes_f32 {
using Isa = IsaF;
#include "simd_kernel.inl"
} // namespace lanes_f32
namespace lanes_f64 {
using Isa = IsaD;
#include "simd_kernel.inl"
} // namespace lanes_f64
} // namespace

#undef VKCLOTH_KERNEL_LANES
#define VKCLOTH_KERNEL_LANGUAGE_END
#include "kernel/language.h"
#undef VKCLOTH_KERNEL_LANGUAGE_END

namespace {

using namespace lanes_f32; // the kernel's functions, overloaded on the lane types
using namespace lanes_f64;

template <typename T> struct ShapeOf;
template <> struct ShapeOf<IsaF> { using type = lanes_f32::ColliderShape; };
template <> struct ShapeOf<IsaD> { using type = lanes_f64::ColliderShape; };
template <typename T> struct BlockOf;
template <> struct BlockOf<IsaF> { using type = lanes_f32::SpringBlock; };
template <> struct BlockOf<IsaD> { using type = lanes_f64::SpringBlock; };

#define VKCLOTH_AI inline __attribute__((always_inline))

// The lanes' view of collider f for the particles first .. first + W - 1, or index[0 .. W).
template <typename T>
VKCLOTH_AI LaneMesh<T> lane_mesh(const vkcloth::detail::FinishShape<typename T::Real>& f, std::uint32_t first,
                                 const std::uint32_t* index = nullptr) {
  return LaneMesh<T>{f.mesh, f.scalar, index, first};
}

template <bool B> struct Flag { static constexpr bool value = B; };

// W consecutive Reals.
template <typename T> VKCLOTH_AI Lanes<T> load(const typename T::Real* p) {
  typename T::V v;
  __builtin_memcpy(&v, p, sizeof v);
  return Lanes<T>(v);
}
// W particles' vectors from AoS storage, and back.
template <typename T> VKCLOTH_AI Lanes3<T> load3(const typename T::Real* p) {
  typename T::V x, y, z;
  T::load3(p, x, y, z);
  return {Lanes<T>(x), Lanes<T>(y), Lanes<T>(z)};
}
template <typename T> VKCLOTH_AI void store3(typename T::Real* p, Lanes3<T> a) {
  T::store3(p, a.x.v, a.y.v, a.z.v);
}
template <typename T>
VKCLOTH_AI Lanes3<T> splat3(typename T::Real x, typename T::Real y, typename T::Real z) {
  return {Lanes<T>(x), Lanes<T>(y), Lanes<T>(z)};
}

// Every lane of m is set.
template <typename T> VKCLOTH_AI bool all_lanes(Mask<T> m) {
  bool r = true;
  for (int l = 0; l < T::W; ++l)
    r = r && m.m[l] != 0;
  return r;
}
// Lane l holds l.
template <typename T> VKCLOTH_AI typename T::M lane_index() {
  typename T::M lane{};
  for (int l = 0; l < T::W; ++l)
    lane[l] = l;
  return lane;
}

// The end of one vector's step, shared by the row and list kernels, as normal_force_at and
// euler_finish end it without colliders: add_body_forces, the normal and force stores and, when
// integrating, euler_update, the pins, and check_finite's test (diverged). `skipped` lanes (a tail
// vector's, done already) are left out of the check; put3 stores AoS (and knows the tail); put_soa
// stores the next positions' SoA copy (the row kernel's; the list kernel has none).
template <typename T, bool wind, bool integrate, bool semi> struct StepTail {
  using Real = typename T::Real;
  using L = Lanes<T>;
  using L3 = Lanes3<T>;
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
  VKCLOTH_AI void operator()(std::int64_t q, L3 x0, L3 springs, L3 nrm, Mask<T> skipped, Mask<T>& ok,
                             Put3 put3, PutSoa put_soa) const {
    const L m = load<T>(mass + q);
    const L3 v = load3<T>(vel + 3 * q);
    const L3 f = add_body_forces(springs, m, v, splat3<T>(gx_, gy_, gz_), L(damping_), wind, nrm,
                                 splat3<T>(wx_, wy_, wz_), L(kw_));
    put3(normal_out + 3 * q, nrm);
    put3(force_out + 3 * q, f);
    if constexpr (integrate) {
      L3 x = x0, u = v;
      euler_update(semi, x, u, f, m, L(dt_));
      const Mask<T> pin(T::pinmask(pinned + q)); // euler_finish: a pinned particle keeps x and v
      x = select(pin, x0, x);
      u = select(pin, v, u);
      put3(pos_next + 3 * q, x);
      put_soa(x);
      put3(vel + 3 * q, u);
      ok = ok && (skipped || !diverged(x, u, L(limit_)));
    }
  }
};

// One vector of W particles per iteration: normal fan, the 12 stencil springs, body forces, the
// Euler update and the finite check, in the reference's order. One loop body whose values stay in
// vector registers: the kernel's functions and StepTail are always inlined, since across real
// calls GCC spills the 16-lane temporaries.
template <typename T, bool wind, bool integrate, bool semi>
std::int64_t simd_body(const vkcloth::detail::RowArgs<typename T::Real>& a, std::int64_t q0, std::int64_t q1,
                       bool& bad) {
  using Real = typename T::Real;
  using L = Lanes<T>;
  using L3 = Lanes3<T>;
  using M = typename T::M;
  constexpr int W = T::W;
  const Real* __restrict px = a.px;
  const Real* __restrict py = a.py;
  const Real* __restrict pz = a.pz;
  const std::uint16_t* __restrict mask = a.mask;
  Real* __restrict sxn = a.sx_next;
  Real* __restrict syn = a.sy_next;
  Real* __restrict szn = a.sz_next;
  const StepTail<T, wind, integrate, semi> step_tail(a);
  const M lane = lane_index<T>(); // to leave a tail vector's skipped lanes out of the finite check
  Mask<T> ok(lane == lane);       // all lanes true: every value written so far passed the finite check
  const std::int64_t nx = a.nx;
  std::int64_t O[12];
  L rest[12], stiff[12];
  for (int k = 0; k < 12; ++k) {
    O[k] = a.off[k];
    rest[k] = L(a.rest[k]);
    stiff[k] = L(a.stiff[k]);
  }
  // One vector of W particles from q; with Tail, the first `skip` lanes were done already and only
  // the others are stored (the overlapped last vector of a run: the skipped lanes read velocities
  // updated in place, but their results are thrown away; the stored lanes read only their own).
  // With Masked, each lane's spring and fan terms are selected by its mask (border particles).
  auto vec = [&](std::int64_t q, int skip, auto tail, auto masked) {
    constexpr bool Tail = decltype(tail)::value;
    constexpr bool Masked = decltype(masked)::value;
    auto put3 = [&](Real* p, L3 x) {
      if constexpr (!Tail) {
        store3<T>(p, x);
      } else {
        Real buf[3 * W];
        store3<T>(buf, x);
        __builtin_memcpy(p + 3 * skip, buf + 3 * skip, sizeof(Real) * std::size_t(3 * (W - skip)));
      }
    };
    auto put = [&](Real* p, L x) {
      if constexpr (!Tail) {
        __builtin_memcpy(p, &x.v, sizeof x.v);
      } else {
        Real buf[W];
        __builtin_memcpy(buf, &x.v, sizeof x.v);
        __builtin_memcpy(p + skip, buf + skip, sizeof(Real) * std::size_t(W - skip));
      }
    };
    M mk{};
    if constexpr (Masked)
      mk = T::loadmask(mask + q);
    auto has = [&](int bit) { return Mask<T>((mk & (1 << bit)) != 0); }; // only used when Masked
    auto at = [&](std::int64_t r) { return L3(load<T>(px + r), load<T>(py + r), load<T>(pz + r)); };
    const L3 x0 = at(q);
    // The grid's fan (ClothTopology: triangles (k, k + 1 mod 4) of the neighbours +x, +y, -x, -y), the
    // triangle k in the mask's bit 12 + k.
    const L3 e[4] = {at(q + 1) - x0, at(q + nx) - x0, at(q - 1) - x0, at(q - nx) - x0};
    L3 fan(L(0));
    for (int k = 0; k < 4; ++k) {
      if constexpr (Masked) {
        L3 t = fan;
        add_fan_triangle(t, e[k], e[(k + 1) % 4]);
        fan = select(has(12 + k), t, fan);
      } else {
        add_fan_triangle(fan, e[k], e[(k + 1) % 4]);
      }
    }
    const L3 nrm = unit_or_zero(fan);
    L3 f(L(0));
#pragma GCC unroll 12
    for (int k = 0; k < 12; ++k) {
      if constexpr (Masked) { // spring k in the mask's bit k
        L3 t = f;
        add_spring(t, x0, at(q + O[k]), rest[k], stiff[k]);
        f = select(has(k), t, f);
      } else {
        add_spring(f, x0, at(q + O[k]), rest[k], stiff[k]);
      }
    }
    step_tail(q, x0, f, nrm, Mask<T>(Tail ? M(lane < skip) : M{}), ok, put3, [&](L3 x) {
      put(sxn + q, x.x);
      put(syn + q, x.y);
      put(szn + q, x.z);
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
  if (integrate && !all_lanes<T>(ok))
    bad = true;
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

// ---- The list kernel: meshes and other cloths without a stencil (ListArgs) ---------------------
// The same step as simd_body, the springs read from the padded lists instead of at constant
// offsets: per slot, the W lanes' neighbours' positions come from T::gather3 (the float ISAs: one
// 16-byte load per lane and a transpose; the lanes' neighbours differ). A vector's lanes walk as many slots
// as its longest list; the padding adds nothing (row_kernel.hpp ListArgs), so each lane sums its own terms in
// its list's order, as normal_force_at does: the reference's bits. The normal comes from the same edges
// (add_ring_term), in the slots before ring_end. A vector whose lists name the last particle
// gathers with gather3_last (T::gather3 may read one float past the particle it loads).
template <typename T, bool wind, bool integrate, bool semi>
std::int64_t list_body(const vkcloth::detail::ListArgs<typename T::Real>& a, std::int64_t v0, std::int64_t v1,
                       bool& bad) {
  using Real = typename T::Real;
  using V = typename T::V;
  using L = Lanes<T>;
  using L3 = Lanes3<T>;
  using M = typename T::M;
  constexpr int W = T::W;
  const Real* __restrict pos = a.pos;
  const StepTail<T, wind, integrate, semi> step_tail(a);
  const M lane = lane_index<T>();
  Mask<T> ok(lane == lane);
  for (std::int64_t b = v0; b < v1; ++b) {
    const std::int64_t q = b * W;
    const L3 x0 = load3<T>(pos + 3 * q);
    L3 f(L(0)), fan(L(0)), prev(L(0)), first(L(0));
    const bool reads_last = a.reads_last[b];
    auto edge = [&](std::uint32_t s) { // slot s: u = x_other - x, its spring
      V xq, yq, zq;
      if (reads_last)
        T::gather3_last(pos, a.other + s, xq, yq, zq);
      else
        T::gather3(pos, a.other + s, xq, yq, zq);
      const L3 u = L3(L(xq), L(yq), L(zq)) - x0;
      add_spring_edge(f, u, load<T>(a.rest + s), load<T>(a.stiff + s));
      return u;
    };
    std::uint32_t s = a.spring_begin[b];
    for (; s < a.ring_end[b]; s += W) {
      const std::uint32_t* bits = a.ring + s;
      ULanes<T> ring;
      for (int l = 0; l < W; ++l)
        ring.u[l] = bits[l];
      add_ring_term(fan, prev, first, edge(s), ring);
    }
    for (; s < a.spring_begin[b + 1]; s += W)
      edge(s);
    step_tail(
        q, x0, f, unit_or_zero(fan), Mask<T>(M{}), ok, [](Real* p, L3 x) { store3<T>(p, x); }, [](L3) {});
  }
  if (integrate && !all_lanes<T>(ok))
    bad = true;
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
// CpuSolver::euler_finish, W particles per vector: each collider's collider_contact and
// contact_response at the substep's start position, euler_update, then each collider's project_out;
// a pinned particle keeps its position and velocity and the kernel's force. The collider is the
// same for every lane (shapes.h's ColliderShape, scalar: its type and flags branch as in the
// reference); each lane's own conditions are the kernel's selects.

template <typename T>
VKCLOTH_AI typename ShapeOf<T>::type lane_shape(const vkcloth::detail::FinishShape<typename T::Real>& f) {
  auto u3 = [](const typename T::Real* p) { return Uniform3<T>{p[0], p[1], p[2]}; };
  typename ShapeOf<T>::type s{};
  s.type = f.type;
  s.a = u3(f.a);
  s.b = f.b;
  s.c = u3(f.c);
  s.ax = u3(f.ax);
  s.ay = u3(f.ay);
  s.az = u3(f.az);
  s.moving = f.moving;
  s.velocity = u3(f.velocity);
  s.spin = u3(f.spin);
  s.pivot = u3(f.pivot);
  s.mu_k = f.mu_k;
  s.mu_s = f.mu_s;
  s.mesh_vel0 = f.scalar->mesh_vel0;
  return s;
}

template <typename T>
std::int64_t simd_finish(const vkcloth::detail::FinishArgs<typename T::Real>& a, std::int64_t q0,
                         std::int64_t q1) {
  using Real = typename T::Real;
  using L = Lanes<T>;
  using L3 = Lanes3<T>;
  constexpr int W = T::W;
  // Copies of the arguments: stores through the outputs cannot change these.
  const Real* __restrict px = a.px;
  const Real* __restrict py = a.py;
  const Real* __restrict pz = a.pz;
  const Real* __restrict mass = a.mass;
  const std::uint8_t* __restrict pinned = a.pinned;
  Real* __restrict vel = a.vel;
  Real* __restrict force = a.force;
  Real* __restrict pos_next = a.pos_next;
  Real* __restrict sxn = a.sx_next;
  Real* __restrict syn = a.sy_next;
  Real* __restrict szn = a.sz_next;
  const std::uint32_t shape_count = a.shape_count;
  const bool both = a.both, semi = a.semi;
  const L dt(a.dt), band(a.band), eps(a.eps);
  // The colliders as the kernel takes them, converted once: the kernel's by-value shapes then read
  // this array where they are used (converted per vector, each call spilled the shape's fields).
  using S = typename ShapeOf<T>::type;
  S shapes[vkcloth::detail::finish_max_shapes];
  if (shape_count > vkcloth::detail::finish_max_shapes)
    return q0; // the caller finishes them all
  for (std::uint32_t k = 0; k < shape_count; ++k)
    shapes[k] = lane_shape<T>(a.shapes[k]);
  std::int64_t q = q0;
  for (; q + W <= q1; q += W) {
    const L3 x0(load<T>(px + q), load<T>(py + q), load<T>(pz + q));
    const L3 f0 = load3<T>(force + 3 * q), v0 = load3<T>(vel + 3 * q);
    const L m = load<T>(mass + q);
    const L h_over_m = dt / m;
    L3 v = v0, f = f0;
    for (std::uint32_t k = 0; k < shape_count; ++k) { // contact_at
      const S& s = shapes[k];
      L distance;
      L3 n, deform;
      collider_contact(lane_mesh<T>(a.shapes[k], std::uint32_t(q)), s, x0, x0, band, distance, n, deform);
      contact_response(v, f, s, x0, n, distance, band, both, h_over_m, deform);
    }
    L3 x = x0;
    euler_update(semi, x, v, f, m, dt);
    for (std::uint32_t k = 0; k < shape_count; ++k) // project_at
      project_out(lane_mesh<T>(a.shapes[k], std::uint32_t(q)), shapes[k], eps, x0, x, v);
    const Mask<T> pin(T::pinmask(pinned + q));
    store3<T>(force + 3 * q, select(pin, f0, f));
    x = select(pin, x0, x);
    store3<T>(pos_next + 3 * q, x);
    store3<T>(vel + 3 * q, select(pin, v0, v));
    __builtin_memcpy(sxn + q, &x.x.v, sizeof x.x.v);
    __builtin_memcpy(syn + q, &x.y.v, sizeof x.y.v);
    __builtin_memcpy(szn + q, &x.z.v, sizeof x.z.v);
  }
  return q;
}

#include "simd_vbd.inl" // vertex block descent: a colour, the begin, the finish
#undef VKCLOTH_AI

} // namespace
