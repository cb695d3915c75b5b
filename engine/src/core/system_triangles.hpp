// SPDX-License-Identifier: MIT
// A cloth's triangles, as the intersection counter and the self-collision checks see them
// (intersections.cpp).
#pragma once
#include <cstdint>
#include <vector>

#include "vkcloth/system.hpp"

namespace vkcloth::detail {

/// Calls f(a, b, c) for each triangle ClothTopology::triangles() lists: a grid's (a, b, d), (a, d, c)
/// per cell, a mesh's Surface::triangles, none for a chain; without making the list.
template <typename F> void for_each_system_triangle(const ParticleSystem& system, F&& f) {
  if (system.grid) {
    const std::uint32_t nx = system.grid->nx, ny = system.grid->ny;
    for (std::uint32_t j = 0; j + 1 < ny; ++j)
      for (std::uint32_t i = 0; i + 1 < nx; ++i) {
        const std::uint32_t a = j * nx + i, b = a + 1, c = a + nx, d = c + 1;
        f(a, b, d);
        f(a, d, c);
      }
  } else if (system.surface) {
    const std::vector<std::uint32_t>& t = system.surface->triangles;
    for (std::size_t k = 0; k + 2 < t.size(); k += 3)
      f(t[k], t[k + 1], t[k + 2]);
  }
}

/// The largest circumradius of those triangles at the particles' positions (0 without triangles;
/// degenerate ones skipped): a point can cross a triangle that far from its three corners.
double largest_circumradius(const ParticleSystem& system);

} // namespace vkcloth::detail
