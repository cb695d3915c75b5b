// SPDX-License-Identifier: MIT
// Measurements of a state against its system's rest state, shared by the CLI and the tests.
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>

#include <glm/vec3.hpp>

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

} // namespace vkcloth
