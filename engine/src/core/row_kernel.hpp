// SPDX-License-Identifier: MIT
// The CPU solver's grid row kernel: its arguments and the per-ISA SIMD entry points.
// The reference is the shared kernel (shaders/include/cloth_kernel.h, per particle in
// cpu_solver.cpp); row_kernel_avx2.cpp and row_kernel_avx512.cpp hold the same arithmetic with
// 8 / 16 (float) particles per vector, each file compiled with its own -m flags and only called
// after __builtin_cpu_supports said yes.
#pragma once

#include <cstddef>
#include <cstdint>

namespace vkcloth::detail {

template <typename Real> struct RowArgs {
  const Real *px, *py, *pz; // positions, SoA
  const Real* vel;          // velocities, AoS (x, y, z) per particle; written when integrating
  Real* vel_out;            // == vel storage (in-place update), may be null when !integrate
  const Real* mass;
  const std::uint8_t* pinned;
  Real* force_out;                   // AoS
  Real* normal_out;                  // AoS
  Real* pos_next;                    // AoS, written when integrating
  Real *sx_next, *sy_next, *sz_next; // next positions, SoA, written when integrating
  // Per-particle masks (null: every particle in [q0, q1) is interior): bit k (0..11) = stencil
  // spring k is in the particle's gather list, bit 12 + k (0..3) = normal fan term k is present.
  // Absent terms are skipped by the same select as `len > 0`, so a border particle gets the CSR
  // path's bits; its absent neighbours may lie outside [0, n): px, py, pz are padded.
  const std::uint16_t* mask;
  std::int64_t nx;
  const std::int64_t* off; // 12 stencil offsets
  const Real* rest;        // 12
  const Real* stiff;       // 12
  Real gx, gy, gz, damping, kw, wx, wy, wz, dt;
  Real limit; // divergence limit (the SIMD kernels' finite check)
  bool wind, integrate, semi;
};

// Each processes whole vectors from q0 and returns where it stopped (q1 minus the remainder,
// fewer than one vector, which the caller runs through the per-particle reference). When integrating, each
// also applies check_finite's test to the positions and velocities it wrote and sets `bad` if one
// fails (it never clears it); without integrating the caller checks after finishing the particles.
std::int64_t row_kernel_avx512(const RowArgs<float>& a, std::int64_t q0, std::int64_t q1, bool& bad);
std::int64_t row_kernel_avx512(const RowArgs<double>& a, std::int64_t q0, std::int64_t q1, bool& bad);
std::int64_t row_kernel_avx2(const RowArgs<float>& a, std::int64_t q0, std::int64_t q1, bool& bad);
std::int64_t row_kernel_avx2(const RowArgs<double>& a, std::int64_t q0, std::int64_t q1, bool& bad);

} // namespace vkcloth::detail
