// SPDX-License-Identifier: MIT
// Self-intersections of a cloth (vkcloth/measure.hpp; docs/model.md "Self-intersections"): the pairs
// of its triangles that intersect and share no vertex. A uniform grid over the triangles' bounding
// boxes finds the candidate pairs; triangles_intersect decides each, in double.
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <vector>

#include <fmt/format.h>
#include <glm/geometric.hpp>
#include <glm/vec2.hpp>

#include "vkcloth/measure.hpp"

#include "system_triangles.hpp"

namespace vkcloth {
namespace {

/// Distances (to a plane; to a line, in 2-D) within this fraction of the pair's longest edge count
/// as zero.
constexpr double rel_tol = 1e-12;

using Tri = std::array<glm::dvec3, 3>;
using Tri2 = std::array<glm::dvec2, 3>;

int side(double value, double tol) {
  return value > tol ? 1 : value < -tol ? -1 : 0;
}

double cross2(const glm::dvec2& a, const glm::dvec2& b) {
  return a.x * b.y - a.y * b.x;
}
double orient2(const glm::dvec2& a, const glm::dvec2& b, const glm::dvec2& c) {
  return cross2(b - a, c - a);
}

/// Projection onto the coordinate plane most parallel to a plane with normal `n`: the two other axes.
struct Projection {
  int u = 0, v = 1;
  explicit Projection(const glm::dvec3& n) {
    const glm::dvec3 a = glm::abs(n);
    const int drop = a.x >= a.y && a.x >= a.z ? 0 : a.y >= a.z ? 1 : 2;
    u = (drop + 1) % 3;
    v = (drop + 2) % 3;
  }
  glm::dvec2 operator()(const glm::dvec3& p) const { return {p[u], p[v]}; }
  Tri2 operator()(const Tri& t) const { return {(*this)(t[0]), (*this)(t[1]), (*this)(t[2])}; }
};

/// The side of c from the line through a and b: 0 within `tol` (a distance) of it.
int side_of_line(const glm::dvec2& a, const glm::dvec2& b, const glm::dvec2& c, double tol) {
  return side(orient2(a, b, c), tol * glm::length(b - a));
}

/// Closed point-in-triangle test in 2-D, with `tol` (a distance) of slack.
bool point_in_triangle(const glm::dvec2& p, const Tri2& t, double tol) {
  const int sign = orient2(t[0], t[1], t[2]) < 0.0 ? -1 : 1;
  for (int i = 0; i < 3; ++i)
    if (sign * side_of_line(t[i], t[(i + 1) % 3], p, tol) < 0)
      return false;
  return true;
}

/// Closed segment-segment test in 2-D, with `tol` (a distance) of slack.
bool segments_meet(const glm::dvec2& a, const glm::dvec2& b, const glm::dvec2& c, const glm::dvec2& d,
                   double tol) {
  const int s1 = side_of_line(a, b, c, tol), s2 = side_of_line(a, b, d, tol);
  const int s3 = side_of_line(c, d, a, tol), s4 = side_of_line(c, d, b, tol);
  if (s1 * s2 > 0 || s3 * s4 > 0)
    return false; // one segment strictly on one side of the other's line
  if ((s1 == 0 && s2 == 0) || (s3 == 0 && s4 == 0)) {
    // Collinear: the intervals along the longer segment's main axis overlap.
    const glm::dvec2 dir = glm::dot(b - a, b - a) >= glm::dot(d - c, d - c) ? b - a : d - c;
    const int k = std::abs(dir.x) >= std::abs(dir.y) ? 0 : 1;
    return std::max(std::min(a[k], b[k]), std::min(c[k], d[k])) <=
           std::min(std::max(a[k], b[k]), std::max(c[k], d[k])) + tol;
  }
  return true;
}

/// Closed segment-triangle test in 2-D.
bool segment_meets_triangle(const glm::dvec2& a, const glm::dvec2& b, const Tri2& t, double tol) {
  for (int i = 0; i < 3; ++i)
    if (segments_meet(a, b, t[i], t[(i + 1) % 3], tol))
      return true;
  return point_in_triangle(a, t, tol); // crossing no edge: inside or outside as a whole
}

/// Closed triangle-triangle overlap in 2-D: edges cross, or one holds the other.
bool triangles_overlap(const Tri2& p, const Tri2& q, double tol) {
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j)
      if (segments_meet(p[i], p[(i + 1) % 3], q[j], q[(j + 1) % 3], tol))
        return true;
  return point_in_triangle(p[0], q, tol) || point_in_triangle(q[0], p, tol);
}

/// A triangle's bounding box (closed). Triangles whose boxes do not overlap do not intersect, whatever
/// the tolerances: so the broad phase, which finds every pair of overlapping boxes, and
/// triangles_intersect agree exactly.
struct Box {
  glm::dvec3 lo, hi;
  explicit Box(const Tri& t)
      : lo(glm::min(glm::min(t[0], t[1]), t[2])), hi(glm::max(glm::max(t[0], t[1]), t[2])) {}
  Box() = default;
  bool overlaps(const Box& o) const {
    return lo.x <= o.hi.x && o.lo.x <= hi.x && lo.y <= o.hi.y && o.lo.y <= hi.y && lo.z <= o.hi.z &&
           o.lo.z <= hi.z;
  }
};

double longest_edge(const Tri& t) {
  return std::sqrt(std::max({glm::dot(t[1] - t[0], t[1] - t[0]), glm::dot(t[2] - t[1], t[2] - t[1]),
                             glm::dot(t[0] - t[2], t[0] - t[2])}));
}

/// cross(b - a, c - a), or zero for a degenerate triangle (see triangles_intersect).
glm::dvec3 area_normal(const Tri& t, double longest) {
  const glm::dvec3 n = glm::cross(t[1] - t[0], t[2] - t[0]);
  return glm::length(n) > rel_tol * longest * longest ? n : glm::dvec3(0.0);
}

/// Does the edge (a, b) of one triangle, at signed distances da, db (sides sa, sb) from the plane of
/// `t` (unit normal n), meet `t`?
bool edge_meets_triangle(const glm::dvec3& a, const glm::dvec3& b, double da, double db, int sa, int sb,
                         const Tri& t, const glm::dvec3& n, double tol) {
  if (sa * sb > 0)
    return false; // both ends strictly on one side
  const Projection proj(n);
  const Tri2 t2 = proj(t);
  if (sa == 0 && sb == 0)
    return segment_meets_triangle(proj(a), proj(b), t2, tol); // the edge lies in the plane
  if (sa == 0)
    return point_in_triangle(proj(a), t2, tol); // it touches the plane at a end
  if (sb == 0)
    return point_in_triangle(proj(b), t2, tol);
  const glm::dvec3 x = a + (b - a) * (da / (da - db)); // it crosses the plane strictly inside
  return point_in_triangle(proj(x), t2, tol);
}

/// triangles_intersect with the normals and longest edges already known (both not degenerate) and
/// the bounding boxes overlapping.
bool intersect(const Tri& p, const glm::dvec3& np_area, double lp, const Tri& q, const glm::dvec3& nq_area,
               double lq) {
  const double tol = rel_tol * std::max(lp, lq);
  const glm::dvec3 np = glm::normalize(np_area), nq = glm::normalize(nq_area);
  std::array<double, 3> dq{}, dp{}; // corners' signed distances to the other's plane
  std::array<int, 3> sq{}, sp{};
  for (int i = 0; i < 3; ++i) {
    dq[i] = glm::dot(np, q[i] - p[0]);
    dp[i] = glm::dot(nq, p[i] - q[0]);
    sq[i] = side(dq[i], tol);
    sp[i] = side(dp[i], tol);
  }
  const auto one_side = [](const std::array<int, 3>& s) {
    return (s[0] > 0 && s[1] > 0 && s[2] > 0) || (s[0] < 0 && s[1] < 0 && s[2] < 0);
  };
  if (one_side(sq) || one_side(sp))
    return false;
  const auto in_plane = [](const std::array<int, 3>& s) { return s[0] == 0 && s[1] == 0 && s[2] == 0; };
  if (in_plane(sq) || in_plane(sp)) {
    const Projection proj(in_plane(sq) ? np : nq);
    return triangles_overlap(proj(p), proj(q), tol);
  }
  // Not coplanar: the intersection is a segment on the planes' common line, and each of its ends
  // lies on an edge of one triangle inside the other.
  for (int i = 0; i < 3; ++i) {
    const int j = (i + 1) % 3;
    if (edge_meets_triangle(q[i], q[j], dq[i], dq[j], sq[i], sq[j], p, np, tol) ||
        edge_meets_triangle(p[i], p[j], dp[i], dp[j], sp[i], sp[j], q, nq, tol))
      return true;
  }
  return false;
}

/// Cell coordinates are packed into 21 bits each.
constexpr std::int32_t max_cell = (std::int32_t{1} << 21) - 1;

std::uint64_t cell_key(std::int32_t x, std::int32_t y, std::int32_t z) {
  return (static_cast<std::uint64_t>(x) << 42) | (static_cast<std::uint64_t>(y) << 21) |
         static_cast<std::uint64_t>(z);
}

/// The cell of a coordinate `offset` >= 0 from the grid's corner: floor(offset / cell) clamped to
/// [0, max_cell], monotonic in `offset` (so boxes that overlap share a cell), 0 for NaN.
std::int32_t cell_of(double offset, double cell) {
  const double q = offset / cell;
  return q >= 0.0 ? (q < static_cast<double>(max_cell) ? static_cast<std::int32_t>(q) : max_cell) : 0;
}

struct CellRange {
  std::array<std::int32_t, 3> lo{}, hi{};
};

struct Entry {
  std::uint64_t key;
  std::uint32_t tri;
  bool operator<(const Entry& o) const { return key != o.key ? key < o.key : tri < o.tri; }
};

bool share_vertex(const std::uint32_t* a, const std::uint32_t* b) {
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j)
      if (a[i] == b[j])
        return true;
  return false;
}

/// The triangle list must index `x`, in triples, and every position must be finite.
Result<void> check_triangles(std::span<const std::uint32_t> indices, std::span<const glm::dvec3> x) {
  constexpr const char* fn = "intersecting_triangle_pairs";
  if (indices.size() % 3 != 0)
    return make_error(ErrorCode::invalid_argument,
                      fmt::format("{}: {} triangle indices, not a multiple of 3", fn, indices.size()));
  if (indices.size() / 3 > std::numeric_limits<std::uint32_t>::max())
    return make_error(ErrorCode::invalid_argument,
                      fmt::format("{}: {} triangles, more than 2^32 - 1", fn, indices.size() / 3));
  for (std::size_t k = 0; k < indices.size(); ++k)
    if (indices[k] >= x.size())
      return make_error(ErrorCode::invalid_argument,
                        fmt::format("{}: triangle {} has vertex index {}, but there are {} positions", fn,
                                    k / 3, indices[k], x.size()));
  for (std::size_t k = 0; k < x.size(); ++k)
    if (!std::isfinite(x[k].x) || !std::isfinite(x[k].y) || !std::isfinite(x[k].z))
      return make_error(
          ErrorCode::invalid_argument,
          fmt::format("{}: position {} is not finite: ({}, {}, {})", fn, k, x[k].x, x[k].y, x[k].z));
  return {};
}

/// Per triangle: area normal (zero: degenerate, skipped), longest edge and box; the triangles
/// that are not degenerate, their common box and their mean edge length.
struct TriangleSet {
  std::vector<glm::dvec3> normals;
  std::vector<double> longest;
  std::vector<Box> boxes;
  std::vector<std::uint32_t> live;
  Box all;
  double mean_edge = 0.0;
  std::size_t degenerate = 0;
};

template <typename Corners> TriangleSet triangle_set(std::size_t n, const Corners& corners) {
  TriangleSet s;
  s.normals.resize(n);
  s.longest.resize(n);
  s.boxes.resize(n);
  s.live.reserve(n);
  double edge_sum = 0.0;
  s.all.lo = glm::dvec3(std::numeric_limits<double>::infinity());
  s.all.hi = -s.all.lo;
  for (std::size_t t = 0; t < n; ++t) {
    const Tri tri = corners(t);
    s.longest[t] = longest_edge(tri);
    s.normals[t] = area_normal(tri, s.longest[t]);
    if (s.normals[t] == glm::dvec3(0.0)) {
      ++s.degenerate;
      continue;
    }
    s.live.push_back(static_cast<std::uint32_t>(t));
    s.boxes[t] = Box(tri);
    s.all.lo = glm::min(s.all.lo, s.boxes[t].lo);
    s.all.hi = glm::max(s.all.hi, s.boxes[t].hi);
    edge_sum += glm::length(tri[1] - tri[0]) + glm::length(tri[2] - tri[1]) + glm::length(tri[0] - tri[2]);
  }
  if (!s.live.empty())
    s.mean_edge = edge_sum / (3.0 * static_cast<double>(s.live.size()));
  return s;
}

/// The broad phase: each live triangle's range of grid cells, and one entry per (cell, triangle)
/// sorted by cell then triangle. Cells of about the mean edge, coarser where the extent or the
/// entry budget needs it (long triangles: fewer, larger cells).
struct CellEntries {
  std::vector<CellRange> ranges; // by triangle
  std::vector<Entry> sorted;
};

CellEntries cell_entries(const TriangleSet& s) {
  const glm::dvec3 extent = s.all.hi - s.all.lo;
  double cell =
      std::max(s.mean_edge, std::max({extent.x, extent.y, extent.z}) / static_cast<double>(max_cell - 1));
  const std::uint64_t budget = 16 * static_cast<std::uint64_t>(s.live.size()) + 4096;
  CellEntries c;
  c.ranges.resize(s.boxes.size());
  std::uint64_t entries = 0;
  for (;;) {
    entries = 0;
    for (const std::uint32_t t : s.live) {
      CellRange& r = c.ranges[t];
      std::uint64_t cells = 1;
      for (int k = 0; k < 3; ++k) {
        r.lo[k] = cell_of(s.boxes[t].lo[k] - s.all.lo[k], cell);
        r.hi[k] = std::max(r.lo[k], cell_of(s.boxes[t].hi[k] - s.all.lo[k], cell));
        cells *= static_cast<std::uint64_t>(r.hi[k] - r.lo[k] + 1);
      }
      entries += cells;
      if (entries > budget)
        break;
    }
    if (entries <= budget)
      break;
    cell *= 2.0;
  }
  c.sorted.reserve(entries);
  for (const std::uint32_t t : s.live) {
    const CellRange& r = c.ranges[t];
    for (std::int32_t i = r.lo[0]; i <= r.hi[0]; ++i)
      for (std::int32_t j = r.lo[1]; j <= r.hi[1]; ++j)
        for (std::int32_t k = r.lo[2]; k <= r.hi[2]; ++k)
          c.sorted.push_back({cell_key(i, j, k), t});
  }
  std::sort(c.sorted.begin(), c.sorted.end());
  return c;
}

Result<IntersectionStats> pairs_impl(std::span<const std::uint32_t> indices, std::span<const glm::dvec3> x) {
  VKCLOTH_TRY(check_triangles(indices, x));
  const std::size_t n = indices.size() / 3;
  const auto corners = [&](std::size_t t) {
    return Tri{x[indices[3 * t]], x[indices[3 * t + 1]], x[indices[3 * t + 2]]};
  };
  const TriangleSet set = triangle_set(n, corners);
  IntersectionStats stats;
  stats.triangles = n;
  stats.degenerate = set.degenerate;
  if (set.live.size() < 2)
    return stats;
  const CellEntries grid = cell_entries(set);
  const std::vector<Entry>& cells = grid.sorted;

  // Each pair once: in the first cell both triangles' cell ranges share.
  bool found = false;
  for (std::size_t begin = 0; begin < cells.size();) {
    std::size_t end = begin + 1;
    while (end < cells.size() && cells[end].key == cells[begin].key)
      ++end;
    const std::uint64_t key = cells[begin].key;
    for (std::size_t u = begin; u < end; ++u) {
      const std::uint32_t a = cells[u].tri; // a < b: sorted by triangle within a cell
      for (std::size_t v = u + 1; v < end; ++v) {
        const std::uint32_t b = cells[v].tri;
        if (!set.boxes[a].overlaps(set.boxes[b]) ||
            share_vertex(&indices[3 * std::size_t(a)], &indices[3 * std::size_t(b)]))
          continue;
        const CellRange &ra = grid.ranges[a], &rb = grid.ranges[b];
        if (cell_key(std::max(ra.lo[0], rb.lo[0]), std::max(ra.lo[1], rb.lo[1]),
                     std::max(ra.lo[2], rb.lo[2])) != key)
          continue;
        if (!intersect(corners(a), set.normals[a], set.longest[a], corners(b), set.normals[b],
                       set.longest[b]))
          continue;
        ++stats.pairs;
        if (!found || a < stats.first_a || (a == stats.first_a && b < stats.first_b)) {
          stats.first_a = a;
          stats.first_b = b;
          found = true;
        }
      }
    }
    begin = end;
  }
  return stats;
}

/// The triangles ClothTopology::triangles() lists (detail::for_each_system_triangle).
std::vector<std::uint32_t> system_triangles(const ParticleSystem& system) {
  std::vector<std::uint32_t> tris;
  if (system.grid && system.grid->nx >= 2 && system.grid->ny >= 2)
    tris.reserve(std::size_t(system.grid->nx - 1) * (system.grid->ny - 1) * 6);
  detail::for_each_system_triangle(system, [&](std::uint32_t a, std::uint32_t b, std::uint32_t c) {
    tris.insert(tris.end(), {a, b, c});
  });
  return tris;
}

template <typename Vec>
Result<IntersectionStats> system_pairs(const ParticleSystem& system, std::span<const Vec> positions) {
  if (positions.size() != system.size())
    return make_error(ErrorCode::invalid_argument,
                      fmt::format("intersecting_triangle_pairs: {} positions for {} particles",
                                  positions.size(), system.size()));
  const std::vector<std::uint32_t> tris = system_triangles(system);
  return intersecting_triangle_pairs(std::span<const std::uint32_t>(tris), positions);
}

} // namespace

bool triangles_intersect(const std::array<glm::dvec3, 3>& p, const std::array<glm::dvec3, 3>& q) {
  const double lp = longest_edge(p), lq = longest_edge(q);
  const glm::dvec3 np = area_normal(p, lp), nq = area_normal(q, lq);
  if (np == glm::dvec3(0.0) || nq == glm::dvec3(0.0) || !Box(p).overlaps(Box(q)))
    return false;
  return intersect(p, np, lp, q, nq, lq);
}

Result<IntersectionStats> intersecting_triangle_pairs(std::span<const std::uint32_t> triangles,
                                                      std::span<const glm::dvec3> positions) {
  return pairs_impl(triangles, positions);
}

Result<IntersectionStats> intersecting_triangle_pairs(std::span<const std::uint32_t> triangles,
                                                      std::span<const glm::vec3> positions) {
  const std::vector<glm::dvec3> wide(positions.begin(), positions.end());
  return pairs_impl(triangles, wide);
}

Result<IntersectionStats> intersecting_triangle_pairs(const ParticleSystem& system,
                                                      std::span<const glm::dvec3> positions) {
  return system_pairs(system, positions);
}

Result<IntersectionStats> intersecting_triangle_pairs(const ParticleSystem& system,
                                                      std::span<const glm::vec3> positions) {
  return system_pairs(system, positions);
}

namespace detail {

double largest_circumradius(const ParticleSystem& system) {
  double largest = 0.0;
  for_each_system_triangle(system, [&](std::uint32_t i, std::uint32_t j, std::uint32_t k) {
    if (std::max({i, j, k}) >= system.size())
      return; // an unchecked system's bad index: ParticleSystem::validate names it
    const glm::dvec3 a = system.particles[i].position, b = system.particles[j].position,
                     c = system.particles[k].position;
    const double twice_area = glm::length(glm::cross(b - a, c - a));
    if (twice_area > 0.0) // R = |ab| |bc| |ca| / (4 area)
      largest = std::max(largest,
                         glm::length(b - a) * glm::length(c - b) * glm::length(a - c) / (2.0 * twice_area));
  });
  return largest;
}

} // namespace detail

} // namespace vkcloth
