// SPDX-License-Identifier: MIT
// Greedy colourings and vertex block descent's colouring (ClothTopology::vertex_order, docs/model.md
// "Vertex block descent"); the strain links' colouring (stretch_topology.cpp) shares the helpers.
// Internal to the engine.
#pragma once

#include <cstdint>
#include <optional>
#include <span>
#include <vector>

#include "vkcloth/topology.hpp"

namespace vkcloth::detail {

/// A greedy colouring's step: the smallest colour c that is not marked, seen[c] != mark (the
/// colours of the item's neighbours carry `mark`, so `seen` needs no clearing between items).
std::uint32_t smallest_free_colour(const std::vector<std::size_t>& seen, std::size_t mark);
/// Marks colour c for the item whose mark is `mark`, growing `seen` as needed.
void mark_colour(std::vector<std::size_t>& seen, std::uint32_t c, std::size_t mark);

/// The items 0 .. colour.size() - 1 grouped by colour, in index order within a colour (a stable
/// counting sort), those of colour `none` left out; `offsets`: each colour's range in the result
/// (colours + 1 entries, one zero entry without items).
std::vector<std::uint32_t> group_by_colour(std::span<const std::uint32_t> colour, std::uint32_t none,
                                           std::vector<std::uint32_t>& offsets);

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
