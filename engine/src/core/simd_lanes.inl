// SPDX-License-Identifier: MIT
// SIMD lane types for the shared kernel (engine/kernel/*.h) on the CPU: W particles per value, as
// Jolt's Vec3 / Vec4 wrap a register, over GCC vector extensions. Included first by
// row_kernel_avx2.cpp / row_kernel_avx512.cpp, whose ISA traits T (Real, V = W lanes of Real, M = W
// lanes of same-width ints, W, sqrt, any, AoS load3 / store3, gather3, pinmask, loadmask) parameterise
// these templates; row_kernel_simd.inl then compiles the kernel with real = Lanes<T>, vec3 = Lanes3<T>.
// Everything here has internal linkage, so the two ISA translation units never share (ODR-merge) a
// function compiled for the other's ISA: include nothing with inline functions here.
//
// Bits: each operation is the IEEE operation of the kernel's scalar C++, lane by lane (+, -, *, /
// and sqrt are correctly rounded in SIMD as in scalar code, -ffp-contract=off forbids FMA); min, max
// and abs are std's on scalars and GLM's on vectors: (b < a) ? b : a, (a < b) ? b : a, fabs for a
// scalar and x >= 0 ? x : -x for each component of a vector (which keeps -0).

namespace {

template <typename T> struct Mask;
template <typename T> struct Lanes3;

/// W lanes of Real: the kernel's `real`. Implicit from a Real (broadcast), so a uniform value (a
/// collider's radius, a time step) enters an expression as it is.
template <typename T> struct Lanes {
  using Real = typename T::Real;
  using V = typename T::V;
  V v;
  Lanes() = default;
  Lanes(Real x) : v(x - V{}) {} // every lane x (x - 0 is x, -0 included; V{} + x would give +0)
  explicit Lanes(V x) : v(x) {}

  friend Lanes operator+(Lanes a, Lanes b) { return Lanes(a.v + b.v); }
  friend Lanes operator-(Lanes a, Lanes b) { return Lanes(a.v - b.v); }
  friend Lanes operator*(Lanes a, Lanes b) { return Lanes(a.v * b.v); }
  friend Lanes operator/(Lanes a, Lanes b) { return Lanes(a.v / b.v); }
  friend Lanes operator-(Lanes a) { return Lanes(-a.v); }
  friend Mask<T> operator<(Lanes a, Lanes b) { return Mask<T>(a.v < b.v); }
  friend Mask<T> operator<=(Lanes a, Lanes b) { return Mask<T>(a.v <= b.v); }
  friend Mask<T> operator>(Lanes a, Lanes b) { return Mask<T>(a.v > b.v); }
  friend Mask<T> operator>=(Lanes a, Lanes b) { return Mask<T>(a.v >= b.v); }
  friend Mask<T> operator==(Lanes a, Lanes b) { return Mask<T>(a.v == b.v); }
  friend Mask<T> operator!=(Lanes a, Lanes b) { return Mask<T>(a.v != b.v); }
  friend Lanes select(Mask<T> c, Lanes a, Lanes b) { return Lanes(c.m ? a.v : b.v); }
  friend Lanes sqrt(Lanes a) { return Lanes(T::sqrt(a.v)); }
  friend Lanes abs(Lanes a) { // std::abs: the sign bit cleared
    using M = typename T::M;
    const M sign = (M)Lanes(Real(-0.0)).v;
    return Lanes((V)((M)a.v & ~sign));
  }
  friend Lanes min(Lanes a, Lanes b) { return select(b < a, b, a); }
  friend Lanes max(Lanes a, Lanes b) { return select(a < b, b, a); }
  // A vector times a scalar: here, so that a uniform vector (Uniform3) times lanes finds it.
  friend Lanes3<T> operator*(Lanes3<T> a, Lanes b) { return Lanes3<T>(a.x * b, a.y * b, a.z * b); }
  friend Lanes3<T> operator/(Lanes3<T> a, Lanes b) { return Lanes3<T>(a.x / b, a.y / b, a.z / b); }
};

/// W lanes of a condition (0 or -1 each): what a comparison of lanes gives, and VARYING(bool). No
/// conversion to bool: a kernel `if` on a per-particle condition does not compile on lanes.
template <typename T> struct Mask {
  using M = typename T::M;
  M m;
  Mask() = default;
  explicit Mask(M x) : m(x) {}
  friend Mask operator!(Mask a) { return Mask(a.m == 0); }
  friend Mask operator&&(Mask a, Mask b) { return Mask(a.m & b.m); }
  friend Mask operator||(Mask a, Mask b) { return Mask(a.m | b.m); }
  friend Mask operator&&(bool a, Mask b) { return a ? b : Mask(M{}); }
  friend Mask operator&(Mask a, Mask b) { return Mask(a.m & b.m); }
  friend Mask operator|(Mask a, Mask b) { return Mask(a.m | b.m); }
  friend Mask select(Mask c, Mask a, Mask b) { return Mask(c.m ? a.m : b.m); }
  friend bool any_particle(Mask a) { return T::any(a.m); } // some lane is set
  // Where a lane almost always needs the work (a spring's len > 0): no test, no branch.
  friend bool maybe_any_particle(Mask) { return true; }
};

/// W lanes of a uint (VARYING(uint): a gather-list entry's ring bits), in the width of Real.
template <typename T> struct ULanes {
  using M = typename T::M;
  using E = decltype(M{}[0] + 0);
  M u;
  friend ULanes operator&(ULanes a, unsigned b) { return ULanes{a.u & (M{} + E(b))}; }
  friend Mask<T> operator!=(ULanes a, unsigned b) { return Mask<T>(a.u != (M{} + E(b))); }
};

/// A vector the same for every lane (a collider's, in shapes.h's scalar ColliderShape): converts to
/// lanes where it meets them.
template <typename T> struct Uniform3 {
  typename T::Real x, y, z;
  friend Lanes3<T> operator-(Uniform3 a, Uniform3 b) { return Lanes3<T>(a) - Lanes3<T>(b); }
};

/// Three lanes: the kernel's `vec3`, with GLM's operators (component-wise).
template <typename T> struct Lanes3 {
  using L = Lanes<T>;
  L x, y, z;
  Lanes3() = default;
  explicit Lanes3(L s) : x(s), y(s), z(s) {}
  Lanes3(L a, L b, L c) : x(a), y(b), z(c) {}
  Lanes3(Uniform3<T> u) : x(u.x), y(u.y), z(u.z) {}

  friend Lanes3 operator+(Lanes3 a, Lanes3 b) { return Lanes3(a.x + b.x, a.y + b.y, a.z + b.z); }
  friend Lanes3 operator-(Lanes3 a, Lanes3 b) { return Lanes3(a.x - b.x, a.y - b.y, a.z - b.z); }
  friend Lanes3 operator*(Lanes3 a, Lanes3 b) { return Lanes3(a.x * b.x, a.y * b.y, a.z * b.z); }
  friend Lanes3 operator/(Lanes3 a, Lanes3 b) { return Lanes3(a.x / b.x, a.y / b.y, a.z / b.z); }
  friend Lanes3 operator-(Lanes3 a) { return Lanes3(-a.x, -a.y, -a.z); }
  friend Lanes3 select(Mask<T> c, Lanes3 a, Lanes3 b) {
    return Lanes3(select(c, a.x, b.x), select(c, a.y, b.y), select(c, a.z, b.z));
  }
  friend Lanes3 abs(Lanes3 a) { // glm::abs: x >= 0 ? x : -x
    auto f = [](L c) { return select(c >= L(0), c, -c); };
    return Lanes3(f(a.x), f(a.y), f(a.z));
  }
  friend Lanes3 min(Lanes3 a, Lanes3 b) { return Lanes3(min(a.x, b.x), min(a.y, b.y), min(a.z, b.z)); }
  friend Lanes3 max(Lanes3 a, Lanes3 b) { return Lanes3(max(a.x, b.x), max(a.y, b.y), max(a.z, b.z)); }
  // No component is NaN or inf (c - c is 0 for every finite c, NaN otherwise).
  friend Mask<T> all_finite(Lanes3 a) {
    const L zero(0);
    return a.x - a.x == zero && a.y - a.y == zero && a.z - a.z == zero;
  }
};

/// VARYING(X) on lanes.
template <typename T, typename X> struct Varying;
template <typename T> struct Varying<T, bool> { using type = Mask<T>; };
template <typename T> struct Varying<T, std::uint32_t> { using type = ULanes<T>; };

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
  // The four values at base + offset[l] of each lane l (a record's row of four), as Reals.
  template <typename S>
  static void gather4(const S* base, const std::uint32_t* offset, V& x, V& y, V& z, V& w) {
    for (int l = 0; l < W; ++l) {
      const S* p = base + offset[l];
      x[l] = Real(p[0]);
      y[l] = Real(p[1]);
      z[l] = Real(p[2]);
      w[l] = Real(p[3]);
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
  // Some lane of m is nonzero.
  static bool any(M m) {
    std::uint64_t w[sizeof(M) / 8], acc = 0;
    __builtin_memcpy(w, &m, sizeof m);
    for (std::size_t k = 0; k < sizeof(M) / 8; ++k)
      acc |= w[k];
    return acc != 0;
  }
};

} // namespace
