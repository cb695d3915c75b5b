// SPDX-License-Identifier: MIT
#include "vkcloth/measure.hpp"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>
#include <glm/geometric.hpp>

#include "internal/kernel.hpp"

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

Result<PenetrationStats> penetration(const ParticleSystem& system, std::span<const Collider> colliders,
                                     std::span<const glm::dvec3> positions) {
  if (positions.size() != system.size())
    return make_error(ErrorCode::invalid_argument, fmt::format("penetration: {} positions for {} particles",
                                                               positions.size(), system.size()));
  PenetrationStats stats;
  for (std::uint32_t c = 0; c < colliders.size(); ++c) {
    const auto shape = kernel::kernel_shape<double>(colliders[c]);
    kernel::MeshData mesh;
    if (colliders[c].mesh) {
      mesh.nodes = colliders[c].mesh->nodes().data();
      mesh.triangles = colliders[c].mesh->triangles().data();
      if (!colliders[c].mesh->triangle_velocities().empty())
        mesh.velocities = colliders[c].mesh->triangle_velocities().data();
    }
    for (std::uint32_t p = 0; p < positions.size(); ++p) {
      if (system.particles[p].pinned)
        continue;
      double distance;
      glm::dvec3 normal, deform;
      kernel::collider_contact(mesh, shape, positions[p], positions[p], 1.0, distance, normal, deform);
      if (-distance > stats.depth)
        stats = {-distance, p, c};
    }
  }
  return stats;
}

double max_free_speed(const ParticleSystem& system, std::span<const glm::dvec3> velocities) {
  double m = 0.0;
  for (std::size_t p = 0; p < velocities.size() && p < system.size(); ++p)
    if (!system.particles[p].pinned)
      m = std::max(m, glm::length(velocities[p]));
  return m;
}

} // namespace vkcloth
