// SPDX-License-Identifier: MIT
#include "vkcloth/measure.hpp"

#include <cmath>

#include <fmt/format.h>
#include <glm/geometric.hpp>

namespace vkcloth {
namespace {

template <typename Vec>
Result<StrainStats> structural_strain_impl(const ParticleSystem& system, std::span<const Vec> positions) {
  const std::size_t n = system.size();
  if (positions.size() != n)
    return make_error(ErrorCode::invalid_argument,
                      fmt::format("structural_strain: {} positions for {} particles", positions.size(), n));
  StrainStats stats;
  for (std::size_t k = 0; k < system.springs.size(); ++k) {
    const Spring& s = system.springs[k];
    if (s.kind != SpringKind::structural || !(s.rest_length > 0.0))
      continue;
    if (s.a >= n || s.b >= n)
      return make_error(
          ErrorCode::invalid_argument,
          fmt::format("structural_strain: spring {} joins particles {} and {}, but there are {}", k, s.a, s.b,
                      n));
    const double length = glm::length(glm::dvec3(positions[s.b]) - glm::dvec3(positions[s.a]));
    const double strain = (length - s.rest_length) / s.rest_length;
    if (stats.count == 0 || strain > stats.max) {
      stats.max = strain;
      stats.spring = static_cast<std::uint32_t>(k);
    }
    ++stats.count;
  }
  return stats;
}

} // namespace

Result<StrainStats> structural_strain(const ParticleSystem& system, std::span<const glm::vec3> positions) {
  return structural_strain_impl(system, positions);
}

Result<StrainStats> structural_strain(const ParticleSystem& system, std::span<const glm::dvec3> positions) {
  return structural_strain_impl(system, positions);
}

} // namespace vkcloth
