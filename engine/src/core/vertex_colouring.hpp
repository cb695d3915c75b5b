// SPDX-License-Identifier: MIT
// Vertex block descent's colouring (ClothTopology::vertex_order, docs/model.md "Vertex block
// descent"). Internal to the engine.
#pragma once

#include <cstdint>
#include <optional>
#include <span>
#include <vector>

#include "vkcloth/topology.hpp"

namespace vkcloth::detail {

/// Particles grouped by colour so that no two of one colour share a spring (a gather-list entry):
/// `order` holds colour 0's particles, then colour 1's, ..., each in index order; `offsets` the
/// colours' ranges (colours + 1 entries). A grid first tries (i + 2 j) mod 5, which separates
/// every structural, shear and bend neighbour (offsets (1,0), (0,1), (1,+-1), (2,0), (0,2) give
/// 1, 2, 3, 4, 2, 4 mod 5, never 0); if some spring joins two particles of one colour (a grid with
/// other springs), and for every other system, a greedy colouring in index order: each particle
/// takes the smallest colour none of its neighbours already has.
void colour_vertices(const ParticleSystem& system, std::span<const std::uint32_t> edge_offsets,
                     std::span<const GatherEdge> edges, std::vector<std::uint32_t>& order,
                     std::vector<std::uint32_t>& offsets);

} // namespace vkcloth::detail
