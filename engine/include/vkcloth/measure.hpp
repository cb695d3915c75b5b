// SPDX-License-Identifier: MIT
// Measurements of a state against its system's rest state, shared by the CLI and the tests.
#pragma once

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

} // namespace vkcloth
