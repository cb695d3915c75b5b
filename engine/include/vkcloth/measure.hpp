// SPDX-License-Identifier: MIT
// Measurements of a state against its system's rest state, shared by the CLI and the tests.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <span>

#include <glm/vec3.hpp>

#include "vkcloth/params.hpp"
#include "vkcloth/result.hpp"
#include "vkcloth/system.hpp"

namespace vkcloth {

/// The largest strain over a system's structural springs (SpringKind::structural: a grid's
/// horizontal and vertical neighbours, a mesh cloth's face sides; docs/model.md "Springs").
struct StrainStats {
  /// max over structural springs of (|x_b - x_a| - L0) / L0, computed in double; negative when
  /// every one is compressed. 0 when count == 0.
  double max = 0.0;
  std::uint32_t spring = 0; ///< index into ParticleSystem::springs of the first spring reaching `max`
  std::size_t count = 0;    ///< structural springs measured; 0: none (a chain, or K_struct = 0)
};

/// Structural strain of `positions` (one per particle, in particle order). Springs with a rest
/// length of 0 have no strain and are not counted. ErrorCode::invalid_argument when the position
/// count is not the particle count or a spring's end is out of range.
Result<StrainStats> structural_strain(const ParticleSystem& system, std::span<const glm::vec3> positions);
Result<StrainStats> structural_strain(const ParticleSystem& system, std::span<const glm::dvec3> positions);

/// How deep the free particles are inside the colliders (docs/model.md "Collisions": after a step
/// no particle should be deeper than contact_epsilon).
struct PenetrationStats {
  /// max over free particles and colliders of -(signed distance), computed in double with
  /// cloth_kernel.h's collider_contact (a mesh: from the particle's own side); <= 0 when every
  /// particle is outside (-eps for a cloth resting at surface + eps). -inf without colliders.
  double depth = -std::numeric_limits<double>::infinity();
  std::uint32_t particle = 0; ///< the first particle reaching `depth`
  std::uint32_t collider = 0; ///< and the collider
};

/// Penetration of `positions` (one per particle) into `colliders` at their current pose (a
/// solver's params().colliders). ErrorCode::invalid_argument when the counts differ.
Result<PenetrationStats> penetration(const ParticleSystem& system, std::span<const Collider> colliders,
                                     std::span<const glm::dvec3> positions);

/// The largest |v| of the free particles (0 for none): the jitter of a cloth that should be at rest.
double max_free_speed(const ParticleSystem& system, std::span<const glm::dvec3> velocities);

/// Self-intersections of a cloth (docs/model.md "Self-intersections"): the pairs of its
/// triangles that intersect each other and share no vertex. Computed in double on the positions
/// given (float ones are widened exactly).
struct IntersectionStats {
  std::size_t pairs = 0;      ///< intersecting pairs of triangles sharing no vertex, each counted once
  std::size_t triangles = 0;  ///< triangles given (degenerate ones included)
  std::size_t degenerate = 0; ///< of those, skipped as zero-area (see triangles_intersect)
  /// The first intersecting pair a < b (the smallest a, then the smallest b) as triangle numbers
  /// (triangle t: indices 3t .. 3t + 2); both 0 when pairs == 0. For messages.
  std::uint32_t first_a = 0, first_b = 0;
};

/// Whether two triangles intersect (closed sets, so touching counts; computed in double). Each edge of
/// either triangle is tested against the other (signed distances of its ends to the other's plane,
/// then the crossing point, or the end on the plane, inside the other); when all three corners of one
/// are within 1e-12 L of the other's plane (L: the longest edge of the two) they are coplanar and
/// their projections on that plane are tested for overlap (edges crossing, or a corner inside the
/// other). Distances to a plane, or in the projection to an edge's line, within 1e-12 L count as
/// zero, so triangles that merely touch, or miss each other by about 1e-12 L, may count either way;
/// triangles whose bounding boxes do not overlap never do. False for a degenerate triangle:
/// |cross(b - a, c - a)| <= 1e-12 times its longest edge squared (zero area, or a sliver). Shared
/// corners are not excluded here: triangles with a common vertex touch.
bool triangles_intersect(const std::array<glm::dvec3, 3>& p, const std::array<glm::dvec3, 3>& q);

/// The pairs of `triangles` (3 indices into `positions` each: a ParticleSystem's surface triangles,
/// ClothTopology::triangles()) that intersect (triangles_intersect) and share no vertex index.
/// Broad phase: a uniform grid of cells about the mean edge length over the triangles' bounding boxes
/// (each pair is tested once, in the first cell both boxes share); a flat 512 x 512 grid (522k
/// triangles) takes well under a second. ErrorCode::invalid_argument, naming the value, when the
/// index count is not a multiple of 3, an index is out of range, or a position is not finite.
Result<IntersectionStats> intersecting_triangle_pairs(std::span<const std::uint32_t> triangles,
                                                      std::span<const glm::dvec3> positions);
Result<IntersectionStats> intersecting_triangle_pairs(std::span<const std::uint32_t> triangles,
                                                      std::span<const glm::vec3> positions);

/// The same over a system's triangles (a grid's two per cell, a mesh cloth's Surface::triangles: the
/// triangles ClothTopology::triangles() lists; none for a chain, which gives 0 pairs of 0 triangles)
/// at `positions`, one per particle (ErrorCode::invalid_argument when the counts differ).
Result<IntersectionStats> intersecting_triangle_pairs(const ParticleSystem& system,
                                                      std::span<const glm::dvec3> positions);
Result<IntersectionStats> intersecting_triangle_pairs(const ParticleSystem& system,
                                                      std::span<const glm::vec3> positions);

} // namespace vkcloth
