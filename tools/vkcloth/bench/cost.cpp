// SPDX-License-Identifier: MIT
// `vkcloth bench`'s cost model: the bytes and flops of one particle-step of each solver variant,
// counted from the kernels (docs/performance.md, "Counting").
#include <algorithm>
#include <string>

#include "bench.hpp"

namespace vkcloth::cli::bench {
namespace {

double kernel_flops(double s, bool grid, double fans, bool wind) {
  // grid: 4 edges 12, 4 crosses 36, sum 12, length 5 + sqrt 1, divide 3; a mesh's fan: per term
  // 2 edges 6, a cross 9, sum 3, then the same normalisation 9.
  const double normal = grid ? 69.0 : fans > 0.0 ? 18.0 * fans + 9.0 : 0.0;
  const double springs = 18.0 * s; // u 3, dot 5, sqrt 1, (len - L) 1, k * 1, / len 1, u * 3, += 3
  const double external = 6.0 + 7.0 + (wind ? 12.0 : 0.0); // gravity, damping, wind
  return normal + springs + external;
}

} // namespace

// `grid`: the bench's regular cloth, whose springs both solvers sum from the grid stencil (no
// CSR reads since round 4); `steps_per_submit`: fused Vulkan steps store forces and normals only
// in the last step of a submission.
// `fans`: a mesh's mean normal-fan terms per particle (0 for grids and chains), read from CSR lists.
Cost cost_of(const std::string& variant, Integrator integrator, double s, bool grid, double fans, bool wind,
             std::uint32_t steps_per_submit, std::uint32_t sweeps) {
  Cost c;
  const double eval = kernel_flops(s, grid, fans, wind);
  if (integrator == Integrator::vbd) {
    // The begin's force evaluation (its normal), then per sweep each spring's force and block
    // (~35 flops from one sqrt and one reciprocal, the gather list's entries: vbd works from CSR
    // lists on both backends) and the vertex's 3x3 step (~45); the finish ~30. Bytes per sweep:
    // read x, y, x0, the particle's constants and its list (offsets + entries), write x and the push
    // (the neighbours' positions are counted as cached).
    const double vec = variant == "cpu" ? 12.0 : 16.0, entry = variant == "cpu" ? 12.0 : 16.0;
    c.flops = eval + double(sweeps) * (35.0 * s + 45.0) + 30.0;
    c.bytes = 4.0 * vec + 8.0 + double(sweeps) * (5.0 * vec + 8.0 + 4.0 + entry * s) + 4.0 * vec;
    return c;
  }
  const bool rk4 = integrator == Integrator::rk4;
  // Euler update: a = f/m 3, two axpys 12. RK4: 4 stages (eval + k sums 6 + next stage 12), final 12.
  c.flops = rk4 ? 4.0 * (eval + 18.0) + 12.0 : eval + 15.0;
  // offsets + edges (12 bytes on the CPU, whose list kernel pads them per vector, ~6 % on a
  // valence-grouped mesh, not counted; 16 on the GPU: one RGBA32UI texel, and the texel builds read
  // a 16-byte range texel instead of the 4-byte offset: not counted); a mesh's fan lists: offsets +
  // 8-byte terms
  const double edge_bytes = variant == "cpu" ? 12.0 : 16.0;
  const double csr = grid ? 0.0 : 4.0 + edge_bytes * s + (fans > 0.0 ? 4.0 + 8.0 * fans : 0.0);
  if (variant == "cpu") {
    // float vec3 (12 B): read pos, vel; write pos_next, vel, force, normal (and, on grids, the
    // next step's SoA position copy); mass 4 + pinned 1.
    const double euler = 6 * 12.0 + 5.0 + csr + (grid ? 12.0 : 0.0);
    c.bytes = rk4 ? 4.0 * (4 * 12.0 + 5.0 + csr + 6 * 12.0) + 4 * 12.0 : euler;
  } else if (variant == "fused" || variant == "batched" || variant == "unbatched") {
    // vec4 (16 B): read pos, vel, particle 8; write pos, vel; force, normal once per submission.
    c.bytes = 16.0 * 2 + 8.0 + csr + 16.0 * 2 + 16.0 * 2 / double(std::max(steps_per_submit, 1u));
  } else {
    // two-pass: force reads pos, vel, particle, CSR; writes force, vel_filt, normal.
    //           integrate reads particle, force, vel_filt, pos; writes pos, vel.
    const double force = 16.0 * 2 + 8.0 + csr + 16.0 * 3;
    const double integ = 8.0 + 16.0 * 3 + 16.0 * 2;
    // RK4 stages also read and write the running sums and write the stage state (4 x 16 B more).
    c.bytes = rk4 ? 4.0 * (force + integ + 64.0) : force + integ;
  }
  return c;
}

} // namespace vkcloth::cli::bench
