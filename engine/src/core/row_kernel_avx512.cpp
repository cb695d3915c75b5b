// SPDX-License-Identifier: MIT
// The interior row kernel for AVX-512F: 16 floats / 8 doubles per vector. This file alone is
// compiled with -mavx512f (engine/CMakeLists.txt) and is only called when the CPU has AVX-512F.
#include "row_kernel.hpp"

#include <immintrin.h>

#if !defined(__AVX512F__)
#error "row_kernel_avx512.cpp must be compiled with -mavx512f"
#endif

#include "simd_lanes.inl"

namespace {

typedef float vf16 __attribute__((vector_size(64)));
typedef int vi16 __attribute__((vector_size(64)));
typedef double vd8 __attribute__((vector_size(64)));
typedef long long vl8 __attribute__((vector_size(64)));

// Index vectors of the two-source permutes that (de)interleave W lanes of x, y, z:
// deinterleave component k: t = perm2(a, I1, b) takes the lanes whose element 3l+k lies in a or b,
// then perm2(t, I2, c) the rest from c. Interleave output vector o: t = perm2(x, S1, y), then
// perm2(t, S2, z).
template <typename I, int W> struct Perm {
  I d1[3][W], d2[3][W], s1[3][W], s2[3][W];
  constexpr Perm() : d1{}, d2{}, s1{}, s2{} {
    for (int k = 0; k < 3; ++k)
      for (int l = 0; l < W; ++l) {
        const int g = 3 * l + k;
        d1[k][l] = I(g < 2 * W ? g : 0);
        d2[k][l] = I(g < 2 * W ? l : W + g - 2 * W);
      }
    for (int o = 0; o < 3; ++o)
      for (int j = 0; j < W; ++j) {
        const int g = W * o + j, comp = g % 3, l = g / 3;
        s1[o][j] = I(comp == 0 ? l : comp == 1 ? W + l : 0);
        s2[o][j] = I(comp == 2 ? W + l : j);
      }
  }
};
constexpr Perm<int, 16> perm_f{};
constexpr Perm<long long, 8> perm_d{};

struct IsaF : IsaGeneric<float, vf16, vi16, 16> {
  using Real = float;
  using V = vf16;
  using M = vi16;
  static constexpr int W = 16;
  // Masked form (all lanes): the plain one reads _mm512_undefined, a GCC 12 -Wmaybe-uninitialized.
  static V sqrt(V x) { return (V)_mm512_mask_sqrt_ps((__m512)x, __mmask16(0xFFFF), (__m512)x); }
  static bool any(M m) { return _mm512_test_epi32_mask((__m512i)m, (__m512i)m) != 0; }
  static __m512i idx(const int* p) { return _mm512_loadu_si512(p); }
  static void load3(const float* p, V& x, V& y, V& z) {
    const __m512 a = _mm512_loadu_ps(p), b = _mm512_loadu_ps(p + 16), c = _mm512_loadu_ps(p + 32);
    V* out[3] = {&x, &y, &z};
    for (int k = 0; k < 3; ++k)
      *out[k] =
          (V)_mm512_permutex2var_ps(_mm512_permutex2var_ps(a, idx(perm_f.d1[k]), b), idx(perm_f.d2[k]), c);
  }
  static void store3(float* p, V x, V y, V z) {
    for (int o = 0; o < 3; ++o)
      _mm512_storeu_ps(p + 16 * o,
                       _mm512_permutex2var_ps(_mm512_permutex2var_ps((__m512)x, idx(perm_f.s1[o]), (__m512)y),
                                              idx(perm_f.s2[o]), (__m512)z));
  }
  static M pinmask(const std::uint8_t* p) {
    const vi16 v = (vi16)_mm512_maskz_cvtepu8_epi32(__mmask16(0xFFFF),
                                                    _mm_loadu_si128(reinterpret_cast<const __m128i*>(p)));
    return v != 0;
  }
  // The positions of the 16 particles index[0..16) names (AoS): one 16-byte load per particle (x,
  // y, z and the next particle's x, unused), then a 4 x 4 transpose in each 128-bit lane. Faster
  // than 48 lane inserts, a hardware gather or masked loads (all measured, docs/performance.md);
  // reads one float past the particle: never called on a vector that names the last one.
  static void gather3(const float* pos, const std::uint32_t* index, V& x, V& y, V& z) {
    V w;
    transpose4([&](int l) { return _mm_loadu_ps(pos + 3 * std::size_t(index[l])); }, x, y, z, w);
  }
  // The four floats at base + offset[l] of each lane l, the same way.
  static void gather4(const float* base, const std::uint32_t* offset, V& x, V& y, V& z, V& w) {
    transpose4([&](int l) { return _mm_loadu_ps(base + offset[l]); }, x, y, z, w);
  }
  // Lane l's four floats at(l) as four vectors x, y, z, w. (Masked forms, all lanes: the plain ones
  // read _mm512_undefined, a GCC 12 -Wmaybe-uninitialized.)
  template <typename At> static void transpose4(At at, V& x, V& y, V& z, V& w) {
    constexpr __mmask16 all = 0xFFFF;
    auto row = [&](int r) { // lanes r, r + 4, r + 8, r + 12, one per 128-bit lane
      const __m512d lo = _mm512_castpd256_pd512(_mm256_castps_pd(_mm256_set_m128(at(r + 4), at(r))));
      const __m256d hi = _mm256_castps_pd(_mm256_set_m128(at(r + 12), at(r + 8)));
      return _mm512_castpd_ps(_mm512_mask_insertf64x4(lo, __mmask8(0xFF), lo, hi, 1));
    };
    const __m512 a = row(0), b = row(1), c = row(2), d = row(3);
    const __m512 ab_lo = _mm512_mask_unpacklo_ps(a, all, a, b), cd_lo = _mm512_mask_unpacklo_ps(c, all, c, d);
    const __m512 ab_hi = _mm512_mask_unpackhi_ps(a, all, a, b), cd_hi = _mm512_mask_unpackhi_ps(c, all, c, d);
    x = (V)_mm512_mask_shuffle_ps(ab_lo, all, ab_lo, cd_lo, _MM_SHUFFLE(1, 0, 1, 0));
    y = (V)_mm512_mask_shuffle_ps(ab_lo, all, ab_lo, cd_lo, _MM_SHUFFLE(3, 2, 3, 2));
    z = (V)_mm512_mask_shuffle_ps(ab_hi, all, ab_hi, cd_hi, _MM_SHUFFLE(1, 0, 1, 0));
    w = (V)_mm512_mask_shuffle_ps(ab_hi, all, ab_hi, cd_hi, _MM_SHUFFLE(3, 2, 3, 2));
  }
  static M loadmask(const std::uint16_t* p) {
    return (vi16)_mm512_maskz_cvtepu16_epi32(__mmask16(0xFFFF),
                                             _mm256_loadu_si256(reinterpret_cast<const __m256i*>(p)));
  }
};

struct IsaD : IsaGeneric<double, vd8, vl8, 8> {
  using Real = double;
  using V = vd8;
  using M = vl8;
  static constexpr int W = 8;
  static V sqrt(V x) { return (V)_mm512_mask_sqrt_pd((__m512d)x, __mmask8(0xFF), (__m512d)x); }
  static bool any(M m) { return _mm512_test_epi64_mask((__m512i)m, (__m512i)m) != 0; }
  static __m512i idx(const long long* p) { return _mm512_loadu_si512(p); }
  static void load3(const double* p, V& x, V& y, V& z) {
    const __m512d a = _mm512_loadu_pd(p), b = _mm512_loadu_pd(p + 8), c = _mm512_loadu_pd(p + 16);
    V* out[3] = {&x, &y, &z};
    for (int k = 0; k < 3; ++k)
      *out[k] =
          (V)_mm512_permutex2var_pd(_mm512_permutex2var_pd(a, idx(perm_d.d1[k]), b), idx(perm_d.d2[k]), c);
  }
  static void store3(double* p, V x, V y, V z) {
    for (int o = 0; o < 3; ++o)
      _mm512_storeu_pd(
          p + 8 * o, _mm512_permutex2var_pd(_mm512_permutex2var_pd((__m512d)x, idx(perm_d.s1[o]), (__m512d)y),
                                            idx(perm_d.s2[o]), (__m512d)z));
  }
};

} // namespace

#include "row_kernel_simd.inl"

namespace vkcloth::detail {
std::int64_t row_kernel_avx512(const RowArgs<float>& a, std::int64_t q0, std::int64_t q1, bool& bad) {
  return simd_dispatch<IsaF>(a, q0, q1, bad);
}
std::int64_t row_kernel_avx512(const RowArgs<double>& a, std::int64_t q0, std::int64_t q1, bool& bad) {
  return simd_dispatch<IsaD>(a, q0, q1, bad);
}
std::int64_t list_kernel_avx512(const ListArgs<float>& a, std::int64_t v0, std::int64_t v1, bool& bad) {
  return list_dispatch<IsaF>(a, v0, v1, bad);
}
std::int64_t list_kernel_avx512(const ListArgs<double>& a, std::int64_t v0, std::int64_t v1, bool& bad) {
  return list_dispatch<IsaD>(a, v0, v1, bad);
}
std::int64_t finish_avx512(const FinishArgs<float>& a, std::int64_t q0, std::int64_t q1) {
  return simd_finish<IsaF>(a, q0, q1);
}
std::int64_t finish_avx512(const FinishArgs<double>& a, std::int64_t q0, std::int64_t q1) {
  return simd_finish<IsaD>(a, q0, q1);
}
std::int64_t vbd_colour_avx512(const VbdArgs<float>& a, std::int64_t k0, std::int64_t k1) {
  return simd_vbd_colour<IsaF>(a, k0, k1);
}
std::int64_t vbd_colour_avx512(const VbdArgs<double>& a, std::int64_t k0, std::int64_t k1) {
  return simd_vbd_colour<IsaD>(a, k0, k1);
}
std::int64_t vbd_begin_avx512(const VbdBeginArgs<float>& a, std::int64_t q0, std::int64_t q1) {
  return simd_vbd_begin<IsaF>(a, q0, q1);
}
std::int64_t vbd_begin_avx512(const VbdBeginArgs<double>& a, std::int64_t q0, std::int64_t q1) {
  return simd_vbd_begin<IsaD>(a, q0, q1);
}
std::int64_t vbd_finish_avx512(const VbdFinishArgs<float>& a, std::int64_t q0, std::int64_t q1) {
  return simd_vbd_finish<IsaF>(a, q0, q1);
}
std::int64_t vbd_finish_avx512(const VbdFinishArgs<double>& a, std::int64_t q0, std::int64_t q1) {
  return simd_vbd_finish<IsaD>(a, q0, q1);
}
} // namespace vkcloth::detail
