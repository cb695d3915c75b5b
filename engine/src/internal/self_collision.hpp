// SPDX-License-Identifier: MIT
// CpuSolver's self-collision workspace (self_collision.cpp).
#pragma once

#include <cstdint>
#include <vector>

#include <glm/vec3.hpp>

#include "vkcloth/params.hpp"

namespace vkcloth {

namespace detail {
/// The hash table, the neighbour lists and the per-particle constants of self-collision, made by
/// the first substep with it on (rest positions and inverse masses as the GPU computes them: cast
/// to Real, then the kernel).
template <typename Real> struct SelfCollisionGrid {
  using Vec3 = glm::vec<3, Real>;
  std::vector<Vec3> rest;
  std::vector<Real> inv_mass;
  std::uint32_t mask = 0; // the hash table's size - 1 (kernel.hpp self_table_size of the particle count)
  std::vector<std::uint32_t>
      start; // table size + 1: bucket b's particles are sorted[start[b] .. start[b + 1])
  std::vector<std::uint32_t> fill; // the counting sort's next slot per bucket
  std::vector<std::uint32_t> key;  // each particle's cell key (its bucket: kernel::self_bucket)
  std::vector<std::uint32_t> sorted;
  // In table order: each entry's key, and (after a list build's hash) its particle's position and
  // rest position, which the build's walks read as contiguous memory.
  std::vector<std::uint32_t> sorted_key;
  std::vector<Vec3> entry_pos, entry_rest;
  std::vector<Vec3> dx, dv; // this pass's moves and velocity changes
  // The neighbour lists (SelfCollision::skin > 0): where each particle was when they were built
  // (NaN before the first build), each list's length (past the capacity: overflowed) and entries.
  std::vector<Vec3> built;
  std::vector<std::uint32_t> listed, list;
  Real built_reach2 = 0, built_thickness = 0; // what they were built for
  SelfCollisionStats stats;
};
/// SelfCollision's numbers as the kernel takes them, each computed in double and cast once (the GPU's
/// SelfCollisionGpu::packed casts the same to float): the hash's cells are twice the reach,
/// thickness + skin, with a skin (self_walk's GATHER visits the 2 x 2 x 2 on a particle's side), and
/// the thickness without one (the walk's 27).
template <typename Real> struct SelfConstants {
  Real thickness, friction, inv_cell, reach2, half_skin2, stiffness;
};
template <typename Real> SelfConstants<Real> self_constants(const SelfCollision& sc) {
  const double reach = sc.thickness + sc.skin;
  const double cell = sc.skin > 0.0 ? 2.0 * reach : sc.thickness; // the lists' build walks 2 x 2 x 2 cells
  return {Real(sc.thickness),
          Real(sc.friction),
          Real(1.0 / cell),
          Real(reach * reach),
          Real(0.25 * sc.skin * sc.skin),
          Real(sc.stiffness)};
}
/// Whether vbd takes self-contact as an energy in its vertex steps rather than passes after the step
/// (SelfCollision::stiffness with a skin, in the solver's precision): CpuSolver and the GPU batch decide
/// alike.
template <typename Real> bool self_contact_energy(const SimParams& p) {
  const SelfConstants<Real> k = self_constants<Real>(p.self_collision);
  return p.self_collision.enabled && p.integrator == Integrator::vbd && k.stiffness > Real(0) &&
         k.half_skin2 > Real(0);
}
/// Whether self-collision runs as passes after each substep (on, and not vbd's energy).
template <typename Real> bool self_collision_passes(const SimParams& p) {
  return p.self_collision.enabled && !self_contact_energy<Real>(p);
}
} // namespace detail

} // namespace vkcloth
