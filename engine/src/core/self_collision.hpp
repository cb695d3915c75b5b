// SPDX-License-Identifier: MIT
// CpuSolver's self-collision workspace (self_collision.cpp).
#pragma once

#include <cstdint>
#include <vector>

#include <glm/vec3.hpp>

namespace vkcloth {

namespace detail {
/// The hash table and the per-particle constants of self-collision, made by the first substep with
/// it on (rest positions and inverse masses as the GPU computes them: cast to Real, then the kernel).
template <typename Real> struct SelfCollisionGrid {
  using Vec3 = glm::vec<3, Real>;
  std::vector<Vec3> rest;
  std::vector<Real> inv_mass;
  std::vector<std::uint32_t>
      start; // table size + 1: bucket b's particles are sorted[start[b] .. start[b + 1])
  std::vector<std::uint32_t> fill; // the counting sort's next slot per bucket
  std::vector<std::uint32_t> key;  // each particle's cell key (its bucket: kernel::self_bucket)
  std::vector<std::uint32_t> sorted;
  std::vector<Vec3> dx, dv; // this pass's moves and velocity changes
};
} // namespace detail

} // namespace vkcloth
