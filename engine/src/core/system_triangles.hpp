// SPDX-License-Identifier: MIT
// A cloth's triangles, as the intersection counter and the self-collision checks see them
// (intersections.cpp).
#pragma once
#include <cstdint>
#include <vector>

#include "vkcloth/system.hpp"

namespace vkcloth::detail {

/// The triangles ClothTopology::triangles() lists: a grid's (a, b, d), (a, d, c) per cell, a mesh's
/// Surface::triangles, none for a chain.
std::vector<std::uint32_t> system_triangles(const ParticleSystem& system);

/// The largest circumradius of those triangles at the particles' positions (0 without triangles;
/// degenerate ones skipped): a point can cross a triangle that far from its three corners.
double largest_circumradius(const ParticleSystem& system);

} // namespace vkcloth::detail
