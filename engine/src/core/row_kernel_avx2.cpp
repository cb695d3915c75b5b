// SPDX-License-Identifier: MIT
// The interior row kernel for AVX2: 8 floats / 4 doubles per vector. This file alone is compiled
// with -mavx2 (engine/CMakeLists.txt; no -mfma) and is only called when the CPU has AVX2.
#include "row_kernel.hpp"

#include <immintrin.h>

#if !defined(__AVX2__)
#error "row_kernel_avx2.cpp must be compiled with -mavx2"
#endif

#include "simd_lanes.inl"

namespace {

typedef float vf8 __attribute__((vector_size(32)));
typedef int vi8 __attribute__((vector_size(32)));
typedef double vd4 __attribute__((vector_size(32)));
typedef long long vl4 __attribute__((vector_size(32)));

// Deinterleave component k: element 3l+k sits in source (3l+k)/8 at position (3l+k)%8: three
// one-source permutes by that position, blended by source. Interleave output o: element 8o+j is
// component (8o+j)%3 of lane (8o+j)/3: three permutes by lane, blended by component.
struct Perm8 {
  int d[3][8], dm1[3][8], dm2[3][8], s[3][8], sm1[3][8], sm2[3][8];
  constexpr Perm8() : d{}, dm1{}, dm2{}, s{}, sm1{}, sm2{} {
    for (int k = 0; k < 3; ++k)
      for (int l = 0; l < 8; ++l) {
        const int g = 3 * l + k;
        d[k][l] = g % 8;
        dm1[k][l] = g / 8 == 1 ? -1 : 0;
        dm2[k][l] = g / 8 == 2 ? -1 : 0;
      }
    for (int o = 0; o < 3; ++o)
      for (int j = 0; j < 8; ++j) {
        const int g = 8 * o + j;
        s[o][j] = g / 3;
        sm1[o][j] = g % 3 == 1 ? -1 : 0;
        sm2[o][j] = g % 3 == 2 ? -1 : 0;
      }
  }
};
constexpr Perm8 perm8{};

struct IsaF : IsaGeneric<float, vf8, vi8, 8> {
  using Real = float;
  using V = vf8;
  using M = vi8;
  static constexpr int W = 8;
  static V sqrt(V x) { return (V)_mm256_sqrt_ps((__m256)x); }
  static bool any(M m) { return !_mm256_testz_si256((__m256i)m, (__m256i)m); }
  static __m256i iv(const int* p) { return _mm256_loadu_si256(reinterpret_cast<const __m256i*>(p)); }
  static __m256 mk(const int* p) { return _mm256_castsi256_ps(iv(p)); }
  static void load3(const float* p, V& x, V& y, V& z) {
    const __m256 a = _mm256_loadu_ps(p), b = _mm256_loadu_ps(p + 8), c = _mm256_loadu_ps(p + 16);
    V* out[3] = {&x, &y, &z};
    for (int k = 0; k < 3; ++k) {
      const __m256i i = iv(perm8.d[k]);
      __m256 r =
          _mm256_blendv_ps(_mm256_permutevar8x32_ps(a, i), _mm256_permutevar8x32_ps(b, i), mk(perm8.dm1[k]));
      r = _mm256_blendv_ps(r, _mm256_permutevar8x32_ps(c, i), mk(perm8.dm2[k]));
      *out[k] = (V)r;
    }
  }
  static void store3(float* p, V x, V y, V z) {
    for (int o = 0; o < 3; ++o) {
      const __m256i i = iv(perm8.s[o]);
      __m256 r = _mm256_blendv_ps(_mm256_permutevar8x32_ps((__m256)x, i),
                                  _mm256_permutevar8x32_ps((__m256)y, i), mk(perm8.sm1[o]));
      r = _mm256_blendv_ps(r, _mm256_permutevar8x32_ps((__m256)z, i), mk(perm8.sm2[o]));
      _mm256_storeu_ps(p + 8 * o, r);
    }
  }
  static M pinmask(const std::uint8_t* p) {
    const vi8 v = (vi8)_mm256_cvtepu8_epi32(_mm_loadl_epi64(reinterpret_cast<const __m128i*>(p)));
    return v != 0;
  }
  // The positions of the 8 particles index[0..8) names (AoS): one 16-byte load per particle (x, y,
  // z and the next particle's x, unused), then a 4 x 4 transpose in each 128-bit lane, as the
  // AVX-512 file; reads one float past the particle: never called on a vector that names the last one.
  static void gather3(const float* pos, const std::uint32_t* index, V& x, V& y, V& z) {
    V w;
    transpose4([&](int l) { return _mm_loadu_ps(pos + 3 * std::size_t(index[l])); }, x, y, z, w);
  }
  // The four floats at base + offset[l] of each lane l, the same way.
  static void gather4(const float* base, const std::uint32_t* offset, V& x, V& y, V& z, V& w) {
    transpose4([&](int l) { return _mm_loadu_ps(base + offset[l]); }, x, y, z, w);
  }
  // Lane l's four floats at(l) as four vectors x, y, z, w.
  template <typename At> static void transpose4(At at, V& x, V& y, V& z, V& w) {
    const __m256 a = _mm256_set_m128(at(4), at(0)), b = _mm256_set_m128(at(5), at(1));
    const __m256 c = _mm256_set_m128(at(6), at(2)), d = _mm256_set_m128(at(7), at(3));
    const __m256 ab_lo = _mm256_unpacklo_ps(a, b), cd_lo = _mm256_unpacklo_ps(c, d);
    const __m256 ab_hi = _mm256_unpackhi_ps(a, b), cd_hi = _mm256_unpackhi_ps(c, d);
    x = (V)_mm256_shuffle_ps(ab_lo, cd_lo, _MM_SHUFFLE(1, 0, 1, 0));
    y = (V)_mm256_shuffle_ps(ab_lo, cd_lo, _MM_SHUFFLE(3, 2, 3, 2));
    z = (V)_mm256_shuffle_ps(ab_hi, cd_hi, _MM_SHUFFLE(1, 0, 1, 0));
    w = (V)_mm256_shuffle_ps(ab_hi, cd_hi, _MM_SHUFFLE(3, 2, 3, 2));
  }
  static M loadmask(const std::uint16_t* p) {
    return (vi8)_mm256_cvtepu16_epi32(_mm_loadu_si128(reinterpret_cast<const __m128i*>(p)));
  }
};

struct IsaD : IsaGeneric<double, vd4, vl4, 4> {
  using Real = double;
  using V = vd4;
  using M = vl4;
  static constexpr int W = 4;
  static V sqrt(V x) { return (V)_mm256_sqrt_pd((__m256d)x); }
  static bool any(M m) { return !_mm256_testz_si256((__m256i)m, (__m256i)m); }
};

} // namespace

#include "row_kernel_simd.inl"

namespace vkcloth::detail {
std::int64_t row_kernel_avx2(const RowArgs<float>& a, std::int64_t q0, std::int64_t q1, bool& bad) {
  return simd_dispatch<IsaF>(a, q0, q1, bad);
}
std::int64_t row_kernel_avx2(const RowArgs<double>& a, std::int64_t q0, std::int64_t q1, bool& bad) {
  return simd_dispatch<IsaD>(a, q0, q1, bad);
}
std::int64_t list_kernel_avx2(const ListArgs<float>& a, std::int64_t v0, std::int64_t v1, bool& bad) {
  return list_dispatch<IsaF>(a, v0, v1, bad);
}
std::int64_t list_kernel_avx2(const ListArgs<double>& a, std::int64_t v0, std::int64_t v1, bool& bad) {
  return list_dispatch<IsaD>(a, v0, v1, bad);
}
std::int64_t finish_avx2(const FinishArgs<float>& a, std::int64_t q0, std::int64_t q1) {
  return simd_finish<IsaF>(a, q0, q1);
}
std::int64_t finish_avx2(const FinishArgs<double>& a, std::int64_t q0, std::int64_t q1) {
  return simd_finish<IsaD>(a, q0, q1);
}
std::int64_t vbd_colour_avx2(const VbdArgs<float>& a, std::int64_t k0, std::int64_t k1) {
  return simd_vbd_colour<IsaF>(a, k0, k1);
}
std::int64_t vbd_colour_avx2(const VbdArgs<double>& a, std::int64_t k0, std::int64_t k1) {
  return simd_vbd_colour<IsaD>(a, k0, k1);
}
std::int64_t vbd_begin_avx2(const VbdBeginArgs<float>& a, std::int64_t q0, std::int64_t q1) {
  return simd_vbd_begin<IsaF>(a, q0, q1);
}
std::int64_t vbd_begin_avx2(const VbdBeginArgs<double>& a, std::int64_t q0, std::int64_t q1) {
  return simd_vbd_begin<IsaD>(a, q0, q1);
}
std::int64_t vbd_finish_avx2(const VbdFinishArgs<float>& a, std::int64_t q0, std::int64_t q1) {
  return simd_vbd_finish<IsaF>(a, q0, q1);
}
std::int64_t vbd_finish_avx2(const VbdFinishArgs<double>& a, std::int64_t q0, std::int64_t q1) {
  return simd_vbd_finish<IsaD>(a, q0, q1);
}
} // namespace vkcloth::detail
