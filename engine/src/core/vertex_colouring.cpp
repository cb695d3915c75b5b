// SPDX-License-Identifier: MIT
// Vertex block descent's colouring (the rule: vertex_colouring.hpp).
#include "vertex_colouring.hpp"

#include <algorithm>

namespace vkcloth::detail {
namespace {

constexpr std::uint32_t no_colour = 0xffffffffu;

/// (i + 2 j) mod 5 for each grid particle, or nothing when a spring joins two of one colour.
std::optional<std::vector<std::uint32_t>>
grid_colours(const Grid& grid, std::span<const std::uint32_t> offsets, std::span<const GatherEdge> edges) {
  const std::size_t n = offsets.size() - 1;
  if (std::size_t(grid.nx) * grid.ny != n)
    return std::nullopt;
  std::vector<std::uint32_t> colour(n);
  for (std::size_t p = 0; p < n; ++p)
    colour[p] = std::uint32_t((p % grid.nx + 2 * (p / grid.nx)) % 5);
  for (std::size_t p = 0; p < n; ++p)
    for (std::uint32_t e = offsets[p]; e < offsets[p + 1]; ++e)
      if (colour[edges[e].other] == colour[p])
        return std::nullopt;
  return colour;
}

std::vector<std::uint32_t> greedy_colours(std::span<const std::uint32_t> offsets,
                                          std::span<const GatherEdge> edges) {
  const std::size_t n = offsets.size() - 1;
  std::vector<std::uint32_t> colour(n, no_colour);
  std::vector<std::size_t> seen; // seen[c] == p + 1: colour c is taken around particle p
  for (std::size_t p = 0; p < n; ++p) {
    for (std::uint32_t e = offsets[p]; e < offsets[p + 1]; ++e)
      if (const std::uint32_t c = colour[edges[e].other]; c != no_colour) {
        if (c >= seen.size())
          seen.resize(c + 1, 0);
        seen[c] = p + 1;
      }
    std::uint32_t c = 0;
    while (c < seen.size() && seen[c] == p + 1)
      ++c;
    colour[p] = c;
  }
  return colour;
}

} // namespace

void colour_vertices(const ParticleSystem& system, std::span<const std::uint32_t> edge_offsets,
                     std::span<const GatherEdge> edges, std::vector<std::uint32_t>& order,
                     std::vector<std::uint32_t>& offsets) {
  const std::size_t n = edge_offsets.empty() ? 0 : edge_offsets.size() - 1;
  std::optional<std::vector<std::uint32_t>> grid;
  if (system.grid)
    grid = grid_colours(*system.grid, edge_offsets, edges);
  const std::vector<std::uint32_t> colour = grid ? std::move(*grid) : greedy_colours(edge_offsets, edges);
  const std::uint32_t colours = n == 0 ? 0 : *std::max_element(colour.begin(), colour.end()) + 1;
  offsets.assign(colours + 1, 0);
  for (const std::uint32_t c : colour)
    ++offsets[c + 1];
  for (std::uint32_t c = 0; c < colours; ++c)
    offsets[c + 1] += offsets[c];
  order.resize(n);
  std::vector<std::uint32_t> next(offsets.begin(), offsets.end() - 1);
  for (std::size_t p = 0; p < n; ++p) // index order within a colour
    order[next[colour[p]]++] = std::uint32_t(p);
}

} // namespace vkcloth::detail
