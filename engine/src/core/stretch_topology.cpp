// SPDX-License-Identifier: MIT
#include "internal/stretch_topology.hpp"
#include "vertex_colouring.hpp"

#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <queue>
#include <tuple>
#include <unordered_map>

#include <glm/geometric.hpp>

namespace vkcloth::detail {
namespace {

bool is_strain_link(SpringKind kind) {
  return kind == SpringKind::structural || kind == SpringKind::plain;
}

// The springs tethers travel along: the cloth's in-plane springs (bend springs skip a particle
// and would shorten a geodesic through a fold).
bool is_tether_path(SpringKind kind) {
  return kind == SpringKind::structural || kind == SpringKind::shear || kind == SpringKind::plain;
}

} // namespace

void colour_strain_links(const ParticleSystem& system, std::vector<StrainLink>& links,
                         std::vector<std::uint32_t>& offsets) {
  // Greedy: each link takes the smallest colour none of the links at its two ends has yet.
  // `seen[c] == s + 1` marks colour c as taken for link s (no clearing between links).
  const std::vector<Spring>& springs = system.springs;
  const SpringAdjacency& adj = system.adjacency;
  std::vector<std::uint32_t> colour(springs.size(), no_tether);
  std::vector<std::size_t> seen;
  for (std::size_t s = 0; s < springs.size(); ++s) {
    if (!is_strain_link(springs[s].kind))
      continue;
    for (std::uint32_t end : {springs[s].a, springs[s].b})
      for (std::uint32_t r = adj.offsets[end]; r < adj.offsets[end + 1]; ++r)
        if (const std::uint32_t c = colour[adj.refs[r].spring]; c != no_tether)
          mark_colour(seen, c, s + 1);
    colour[s] = smallest_free_colour(seen, s + 1);
  }
  links.clear();
  for (const std::uint32_t s : group_by_colour(colour, no_tether, offsets)) // spring order within a colour
    links.push_back(StrainLink{springs[s].a, springs[s].b, springs[s].rest_length});
}

void chain_strain_links(const ParticleSystem& system, const std::vector<StrainLink>& links,
                        std::vector<StrainLink>& chains, StrainChainShape& shape) {
  chains.clear();
  shape = {};
  if (!system.grid)
    return;
  const std::uint32_t nx = system.grid->nx, ny = system.grid->ny;
  std::unordered_map<std::uint64_t, double> rest; // each link's rest length by its ends
  auto key = [](std::uint32_t a, std::uint32_t b) {
    return (std::uint64_t(std::min(a, b)) << 32) | std::max(a, b);
  };
  for (const StrainLink& l : links)
    rest.emplace(key(l.a, l.b), l.rest_length);
  auto add = [&](std::uint32_t a, std::uint32_t b) {
    const auto found = rest.find(key(a, b));
    chains.push_back(found == rest.end() ? StrainLink{a, a, 0.0} : StrainLink{a, b, found->second});
  };
  if (nx >= 2) {
    shape.rows = ny;
    shape.row_links = nx - 1;
    for (std::uint32_t j = 0; j < ny; ++j)
      for (std::uint32_t i = 0; i + 1 < nx; ++i)
        add(j * nx + i, j * nx + i + 1);
  }
  if (ny >= 2) {
    shape.columns = nx;
    shape.column_links = ny - 1;
    for (std::uint32_t i = 0; i < nx; ++i)
      for (std::uint32_t j = 0; j + 1 < ny; ++j)
        add(j * nx + i, (j + 1) * nx + i);
  }
}

Result<void> check_sweep_order(const StretchLimit& sl, const ClothTopology& topology) {
  if (sl.chains() && topology.strain_chain_shape().empty())
    return make_error(ErrorCode::invalid_argument,
                      "stretch_limit.order \"chains\" needs a grid cloth (its rows and columns are the "
                      "chains), and this cloth has no grid: use \"colours\"");
  return {};
}

void link_incidence(std::size_t particles, const std::vector<StrainLink>& links,
                    std::vector<std::uint32_t>& offsets, std::vector<std::uint32_t>& entries) {
  offsets.assign(particles + 1, 0);
  for (const StrainLink& l : links) {
    ++offsets[l.a + 1];
    ++offsets[l.b + 1];
  }
  for (std::size_t p = 0; p < particles; ++p)
    offsets[p + 1] += offsets[p];
  entries.resize(offsets.back());
  std::vector<std::uint32_t> next(offsets.begin(), offsets.end() - 1);
  for (std::uint32_t l = 0; l < links.size(); ++l) {
    entries[next[links[l].a]++] = 2 * l;
    entries[next[links[l].b]++] = 2 * l + 1;
  }
}

std::vector<Tether> find_tethers(const ParticleSystem& system, bool geodesic) {
  // Dijkstra from every pinned particle at once, each particle keeping the first
  // tethers_per_particle distinct anchors that reach it: a (particle, anchor) pair is settled at
  // its shortest distance along the springs, the nearest anchors first.
  const std::size_t n = system.size();
  const SpringAdjacency& adj = system.adjacency;
  std::vector<Tether> slots(n * tethers_per_particle);
  std::vector<std::uint32_t> found(n, 0);
  using Entry = std::tuple<double, std::uint32_t, std::uint32_t>; // distance, particle, anchor
  std::priority_queue<Entry, std::vector<Entry>, std::greater<>> queue;
  for (std::uint32_t p = 0; p < n; ++p)
    if (system.particles[p].pinned)
      queue.emplace(0.0, p, p);
  while (!queue.empty()) {
    const double d = std::get<0>(queue.top());
    const std::uint32_t p = std::get<1>(queue.top()), anchor = std::get<2>(queue.top());
    queue.pop();
    Tether* const mine = &slots[std::size_t(p) * tethers_per_particle];
    if (found[p] == tethers_per_particle ||
        std::any_of(mine, mine + found[p], [&](const Tether& t) { return t.anchor == anchor; }))
      continue;
    const glm::dvec3 x = system.particles[p].position, xa = system.particles[anchor].position;
    mine[found[p]++] = Tether{anchor, geodesic ? d : glm::length(x - xa)};
    for (std::uint32_t r = adj.offsets[p]; r < adj.offsets[p + 1]; ++r) {
      const Spring& s = system.springs[adj.refs[r].spring];
      const std::uint32_t q = adj.refs[r].other;
      if (is_tether_path(s.kind) && !system.particles[q].pinned && found[q] < tethers_per_particle)
        queue.emplace(d + s.rest_length, q, anchor);
    }
  }
  // Pinned particles are their own anchor (found above at distance 0): they need no tether.
  for (std::uint32_t p = 0; p < n; ++p)
    if (system.particles[p].pinned)
      std::fill_n(&slots[std::size_t(p) * tethers_per_particle], tethers_per_particle, Tether{});
  return slots;
}

} // namespace vkcloth::detail
