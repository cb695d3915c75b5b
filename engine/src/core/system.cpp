// SPDX-License-Identifier: MIT
#include "vkcloth/system.hpp"

#include <limits>

#include <fmt/format.h>

#include "internal/argument_checks.hpp"

namespace vkcloth {

const char* to_string(SpringKind kind) {
  switch (kind) {
  case SpringKind::plain:
    return "plain";
  case SpringKind::structural:
    return "structural";
  case SpringKind::shear:
    return "shear";
  case SpringKind::bend:
    return "bend";
  }
  return "?";
}

void ParticleSystem::finalize() {
  // Counting sort by particle; iterating springs in index order keeps each list sorted by spring
  // index, which fixes the force summation order for every solver.
  const std::size_t n = particles.size();
  adjacency.offsets.assign(n + 1, 0);
  // A spring with an end out of range is left out here; validate() reports it.
  const auto valid = [n](const Spring& s) { return s.a < n && s.b < n; };
  for (const Spring& s : springs) {
    if (!valid(s))
      continue;
    ++adjacency.offsets[s.a + 1];
    ++adjacency.offsets[s.b + 1];
  }
  for (std::size_t p = 0; p < n; ++p)
    adjacency.offsets[p + 1] += adjacency.offsets[p];
  adjacency.refs.assign(adjacency.offsets[n], SpringRef{});
  std::vector<std::uint32_t> fill(adjacency.offsets.begin(), adjacency.offsets.end() - 1);
  for (std::uint32_t k = 0; k < springs.size(); ++k) {
    const Spring& s = springs[k];
    if (!valid(s))
      continue;
    adjacency.refs[fill[s.a]++] = SpringRef{s.b, k};
    adjacency.refs[fill[s.b]++] = SpringRef{s.a, k};
  }
}

Result<void> ParticleSystem::validate() const {
  const std::size_t n = particles.size();
  auto bad = [](std::string m) { return make_error(ErrorCode::invalid_argument, std::move(m)); };
  if (n == 0)
    return bad("the particle system is empty");
  if (adjacency.offsets.size() != n + 1 || adjacency.refs.size() != adjacency.offsets[n])
    return bad("the particle system was not finalized (call finalize())");
  if (grid && std::uint64_t(grid->nx) * grid->ny != n)
    return bad(fmt::format("grid {} x {} does not match the {} particles", grid->nx, grid->ny, n));
  if (grid && surface)
    return bad("the particle system has both a grid and a surface; a cloth is one or the other");
  if (grid && !grid->uvs.empty() && grid->uvs.size() != n)
    return bad(fmt::format("the grid has {} uvs for {} particles (one each, or none)", grid->uvs.size(), n));
  if (surface) {
    if (surface->triangles.size() % 3 != 0)
      return bad(fmt::format("the surface's triangle list holds {} indices, not a multiple of 3",
                             surface->triangles.size()));
    for (std::size_t k = 0; k < surface->triangles.size(); ++k)
      if (surface->triangles[k] >= n)
        return bad(fmt::format("surface triangle {} refers to particle {}, but there are {}", k / 3,
                               surface->triangles[k], n));
    const auto& fo = surface->face_offsets;
    if (!fo.empty() && (fo.front() != 0 || fo.back() != surface->faces.size()))
      return bad("the surface's face_offsets do not span its face list");
    for (std::size_t f = 0; f + 1 < fo.size(); ++f)
      if (fo[f + 1] < fo[f] + 3)
        return bad(fmt::format("surface face {} has {} corners; faces need at least 3", f,
                               std::int64_t(fo[f + 1]) - std::int64_t(fo[f])));
    for (std::uint32_t v : surface->faces)
      if (v >= n)
        return bad(fmt::format("a surface face refers to particle {}, but there are {}", v, n));
    if (surface->uvs.size() != n)
      return bad(fmt::format("the surface has {} uvs for {} particles", surface->uvs.size(), n));
    if (!surface->source_vertex.empty() && surface->source_vertex.size() != n)
      return bad(fmt::format("the surface's source_vertex has {} entries for {} particles",
                             surface->source_vertex.size(), n));
  }
  for (std::size_t k = 0; k < springs.size(); ++k)
    if (springs[k].a >= n || springs[k].b >= n)
      return bad(fmt::format("spring {} joins particles {} and {}, but there are {}", k, springs[k].a,
                             springs[k].b, n));
  for (const SpringRef& r : adjacency.refs)
    if (r.other >= n || r.spring >= springs.size())
      return bad("the particle system's adjacency refers to a missing particle or spring (call finalize())");
  for (std::size_t p = 0; p < n; ++p)
    if (!particles[p].pinned && !(particles[p].mass > 0.0))
      return bad(
          fmt::format("particle {} has mass {}; free particles need a mass > 0", p, particles[p].mass));
  return {};
}

namespace detail {

Result<void> check_float_masses(const ParticleSystem& system) {
  constexpr double smallest = std::numeric_limits<float>::min();
  for (std::size_t p = 0; p < system.size(); ++p)
    if (!system.particles[p].pinned && system.particles[p].mass < smallest)
      return bad_argument(
          fmt::format("particle {} has mass {} kg, below float's smallest normal number ({:g}): "
                      "the float solvers would divide by zero; use a larger mass or the "
                      "double CPU solver (--precision double)",
                      p, system.particles[p].mass, smallest));
  return {};
}

} // namespace detail
} // namespace vkcloth
