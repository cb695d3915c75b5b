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
  std::vector<std::size_t> seen;
  for (std::size_t p = 0; p < n; ++p) {
    for (std::uint32_t e = offsets[p]; e < offsets[p + 1]; ++e)
      if (const std::uint32_t c = colour[edges[e].other]; c != no_colour)
        mark_colour(seen, c, p + 1);
    colour[p] = smallest_free_colour(seen, p + 1);
  }
  return colour;
}

} // namespace

std::uint32_t smallest_free_colour(const std::vector<std::size_t>& seen, std::size_t mark) {
  std::uint32_t c = 0;
  while (c < seen.size() && seen[c] == mark)
    ++c;
  return c;
}

void mark_colour(std::vector<std::size_t>& seen, std::uint32_t c, std::size_t mark) {
  if (c >= seen.size())
    seen.resize(c + 1, 0);
  seen[c] = mark;
}

std::vector<std::uint32_t> group_by_colour(std::span<const std::uint32_t> colour, std::uint32_t none,
                                           std::vector<std::uint32_t>& offsets) {
  std::uint32_t colours = 0;
  for (const std::uint32_t c : colour)
    if (c != none)
      colours = std::max(colours, c + 1);
  offsets.assign(colours + 1, 0);
  for (const std::uint32_t c : colour)
    if (c != none)
      ++offsets[c + 1];
  for (std::uint32_t c = 0; c < colours; ++c)
    offsets[c + 1] += offsets[c];
  std::vector<std::uint32_t> order(offsets.back());
  std::vector<std::uint32_t> next(offsets.begin(), offsets.end() - 1);
  for (std::size_t i = 0; i < colour.size(); ++i)
    if (colour[i] != none)
      order[next[colour[i]]++] = std::uint32_t(i);
  return order;
}

void colour_vertices(const ParticleSystem& system, std::span<const std::uint32_t> edge_offsets,
                     std::span<const GatherEdge> edges, std::vector<std::uint32_t>& order,
                     std::vector<std::uint32_t>& offsets) {
  std::optional<std::vector<std::uint32_t>> colour;
  if (system.grid && !edge_offsets.empty())
    colour = grid_colours(*system.grid, edge_offsets, edges);
  if (!colour)
    colour = edge_offsets.empty() ? std::vector<std::uint32_t>{} : greedy_colours(edge_offsets, edges);
  order = group_by_colour(*colour, no_colour, offsets);
}

} // namespace vkcloth::detail
