// SPDX-License-Identifier: MIT
// The positions a ParticleSystem was built with, one per particle (the tests' reference shape).
#pragma once

#include <vector>

#include <glm/vec3.hpp>

#include "vkcloth/system.hpp"

namespace vkcloth::test {

inline std::vector<glm::dvec3> rest_positions(const ParticleSystem& s) {
  std::vector<glm::dvec3> x;
  x.reserve(s.particles.size());
  for (const Particle& p : s.particles)
    x.push_back(p.position);
  return x;
}

} // namespace vkcloth::test
