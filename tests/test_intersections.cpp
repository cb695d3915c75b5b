// SPDX-License-Identifier: MIT
// Self-intersections (vkcloth/measure.hpp: triangles_intersect, intersecting_triangle_pairs; docs/model.md
// "Self-intersections"): closed cases, a flat grid, a grid folded through itself and flattened onto
// itself, the broad phase against a brute force, bad input.
#include <doctest/doctest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <numbers>
#include <random>
#include <vector>

#include <glm/geometric.hpp>

#include "vkcloth/mesh.hpp"
#include "vkcloth/vkcloth.hpp"
#include "rest_positions.hpp"

using namespace vkcloth;
using vkcloth::test::rest_positions;

namespace {

using Tri = std::array<glm::dvec3, 3>;

/// The intersecting pairs of two triangles given by their corners: indices 0-2 and 3-5, or, with
/// `shared`, the second triangle's first corner is the first's (index 0).
std::size_t pairs_of(const Tri& p, const Tri& q, bool shared = false) {
  const std::vector<glm::dvec3> x{p[0], p[1], p[2], q[0], q[1], q[2]};
  const std::vector<std::uint32_t> tris{0, 1, 2, shared ? 0u : 3u, 4, 5};
  if (shared)
    REQUIRE(glm::length(p[0] - q[0]) == 0.0);
  const auto r =
      intersecting_triangle_pairs(std::span<const std::uint32_t>(tris), std::span<const glm::dvec3>(x));
  REQUIRE_MESSAGE(r.ok(), (r.ok() ? "" : r.error().message));
  CHECK(r->triangles == 2);
  // The narrow phase alone agrees (in both orders), and so does the float overload where the
  // corners are floats.
  if (!shared) {
    CHECK(triangles_intersect(p, q) == (r->pairs == 1));
    CHECK(triangles_intersect(q, p) == (r->pairs == 1));
  }
  return r->pairs;
}

/// A rotation about a unit axis through `centre` (Rodrigues), so that closed cases can be turned
/// into a plane that is not a coordinate plane.
glm::dvec3 rotate(const glm::dvec3& x, const glm::dvec3& centre, const glm::dvec3& axis, double angle) {
  const glm::dvec3 v = x - centre;
  return centre + v * std::cos(angle) + glm::cross(axis, v) * std::sin(angle) +
         axis * glm::dot(axis, v) * (1.0 - std::cos(angle));
}

Tri rotated(const Tri& t) {
  const glm::dvec3 axis = glm::normalize(glm::dvec3(0.3, -0.7, 0.5));
  Tri r;
  for (int i = 0; i < 3; ++i)
    r[i] = rotate(t[i], {0.2, 0.1, -0.3}, axis, 1.1);
  return r;
}

/// A horizontal n x n grid over [0, 1]^2 at z = 0, nothing pinned.
ParticleSystem flat_grid(std::uint32_t n) {
  ClothDesc d;
  d.nx = n;
  d.ny = n;
  d.size = {1.0, 1.0};
  d.orientation = ClothOrientation::horizontal;
  d.pin_default_corners = false;
  auto s = make_cloth(d);
  REQUIRE(s.ok());
  return std::move(*s);
}

std::span<const std::uint32_t> topology_triangles(const ParticleSystem& s,
                                                  std::shared_ptr<const ClothTopology>& keep) {
  auto t = ClothTopology::create(s);
  REQUIRE(t.ok());
  keep = *t;
  return keep->triangles();
}

/// The right half (x > 0.5) of a flat cloth over [0, 1]^2 turned by 90 degrees about the line
/// x = 0.5, z = -0.25 (along y): it becomes a wall at x = 0.25, z = x_rest - 0.75, which passes
/// through the left half along the line x = 0.25.
glm::dvec3 fold_through(const glm::dvec3& x) {
  if (x.x <= 0.5)
    return x;
  return rotate(x, {0.5, 0.0, -0.25}, {0.0, 1.0, 0.0}, -std::numbers::pi / 2);
}

/// A lower bound of the pairs fold_through makes: every triangle of the left half that the line
/// x = 0.25 crosses (in its interior: rest x-range strictly around 0.25) meets the wall there, which
/// the right half's triangles cover at z = 0 (rest x = 0.75, strictly inside a column of cells) for
/// every y: one pair at least each, with a triangle of the other half (so no shared vertex).
std::size_t fold_through_bound(std::span<const std::uint32_t> tris, const std::vector<glm::dvec3>& rest) {
  std::size_t bound = 0;
  for (std::size_t t = 0; t < tris.size(); t += 3) {
    double lo = 1e9, hi = -1e9;
    bool left = true;
    for (int c = 0; c < 3; ++c) {
      const double x = rest[tris[t + c]].x;
      left = left && x < 0.5;
      lo = std::min(lo, x);
      hi = std::max(hi, x);
    }
    bound += left && lo < 0.25 && hi > 0.25;
  }
  return bound;
}

IntersectionStats pairs(std::span<const std::uint32_t> tris, std::span<const glm::dvec3> x) {
  const auto r = intersecting_triangle_pairs(tris, x);
  REQUIRE_MESSAGE(r.ok(), (r.ok() ? "" : r.error().message));
  return *r;
}

/// O(n^2): every pair a < b sharing no vertex, with the narrow phase.
IntersectionStats brute_force(std::span<const std::uint32_t> tris, std::span<const glm::dvec3> x) {
  IntersectionStats s;
  s.triangles = tris.size() / 3;
  const auto corners = [&](std::size_t t) {
    return Tri{x[tris[3 * t]], x[tris[3 * t + 1]], x[tris[3 * t + 2]]};
  };
  for (std::size_t a = 0; a < s.triangles; ++a)
    for (std::size_t b = a + 1; b < s.triangles; ++b) {
      bool shared = false;
      for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j)
          shared = shared || tris[3 * a + i] == tris[3 * b + j];
      if (shared || !triangles_intersect(corners(a), corners(b)))
        continue;
      if (s.pairs++ == 0) {
        s.first_a = static_cast<std::uint32_t>(a);
        s.first_b = static_cast<std::uint32_t>(b);
      }
    }
  return s;
}

void check_same(const IntersectionStats& got, const IntersectionStats& want) {
  CHECK(got.pairs == want.pairs);
  CHECK(got.triangles == want.triangles);
  CHECK(got.first_a == want.first_a);
  CHECK(got.first_b == want.first_b);
}

} // namespace

TEST_CASE("intersections: crossing, separated, vertex-sharing and degenerate triangle pairs") {
  const Tri floor{glm::dvec3{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
  // A vertical triangle through the floor triangle's interior.
  const Tri pierce{glm::dvec3{0.2, 0.2, -0.5}, {0.3, 0.2, 0.5}, {0.2, 0.3, 0.5}};
  CHECK(pairs_of(floor, pierce) == 1);
  CHECK(pairs_of(rotated(floor), rotated(pierce)) == 1);
  // Two triangles crossing each other edge through edge (each has one edge through the other).
  const Tri a{glm::dvec3{0, 0, 0}, {2, 0, 0}, {1, 2, 0}};
  const Tri b{glm::dvec3{1, 1, -1}, {1, 1, 1}, {1, 3, 0}};
  CHECK(pairs_of(a, b) == 1);
  // The same vertical triangle moved beside the floor triangle (past its hypotenuse x + y = 1).
  const Tri beside{glm::dvec3{0.6, 0.6, -0.5}, {0.7, 0.6, 0.5}, {0.6, 0.7, 0.5}};
  CHECK(pairs_of(floor, beside) == 0);
  // Parallel, separated: the floor triangle lifted by 1e-3 and by 1e-9 (far above the 1e-12 tolerance).
  for (double dz : {1e-3, 1e-9}) {
    CAPTURE(dz);
    Tri up = floor;
    for (auto& p : up)
      p.z += dz;
    CHECK(pairs_of(floor, up) == 0);
    CHECK(pairs_of(rotated(floor), rotated(up)) == 0);
  }
  // A triangle above the floor's plane crossing its line but not the triangle: the planes meet outside.
  const Tri tilted{glm::dvec3{2, 2, 0.1}, {3, 2, -0.1}, {2, 3, 0.1}};
  CHECK(pairs_of(floor, tilted) == 0);

  // Sharing a vertex: the triangles meet along a segment from the shared corner, but share an index.
  const Tri fan{
      glm::dvec3{0, 0, 0}, {0.6, 0.2, -1}, {0.2, 0.6, 1}}; // its far edge crosses z = 0 at (0.4, 0.4)
  CHECK(triangles_intersect(floor, fan));
  CHECK(pairs_of(floor, fan, true) == 0);
  CHECK(pairs_of(floor, fan, false) == 1); // the same corners with distinct indices intersect

  // Degenerate triangles (three collinear corners; a repeated corner) are skipped and counted.
  const Tri needle{glm::dvec3{0.2, 0.2, -1}, {0.2, 0.2, 0}, {0.2, 0.2, 1}};
  CHECK_FALSE(triangles_intersect(floor, needle));
  const std::vector<glm::dvec3> x{floor[0], floor[1], floor[2], needle[0], needle[1], needle[2]};
  const std::vector<std::uint32_t> tris{0, 1, 2, 3, 4, 5, 0, 1, 1};
  const auto r =
      intersecting_triangle_pairs(std::span<const std::uint32_t>(tris), std::span<const glm::dvec3>(x));
  REQUIRE(r.ok());
  CHECK(r->pairs == 0);
  CHECK(r->triangles == 3);
  CHECK(r->degenerate == 2);
}

TEST_CASE("intersections: coplanar triangles count when they overlap, including one inside the other") {
  const Tri t{glm::dvec3{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
  // Overlapping: a copy moved by (0.3, 0.3) in the plane (the edges cross).
  Tri moved = t;
  for (auto& p : moved)
    p += glm::dvec3(0.3, 0.3, 0.0);
  CHECK(pairs_of(t, moved) == 1);
  // Turned into a tilted plane: the rotation rounds the corners off the common plane by ~1e-16,
  // far inside the coplanar tolerance.
  CHECK(pairs_of(rotated(t), rotated(moved)) == 1);
  // One strictly inside the other: no edges cross.
  const Tri inner{glm::dvec3{0.1, 0.1, 0}, {0.4, 0.1, 0}, {0.1, 0.4, 0}};
  CHECK(pairs_of(t, inner) == 1);
  CHECK(pairs_of(inner, t) == 1);
  CHECK(pairs_of(rotated(t), rotated(inner)) == 1);
  // Disjoint in the same plane: moved past the hypotenuse; and the mirror image across it, which
  // would touch along the hypotenuse, moved 1e-6 away in x and y.
  Tri far = t;
  for (auto& p : far)
    p += glm::dvec3(0.6, 0.6, 0.0);
  CHECK(pairs_of(t, far) == 0);
  CHECK(pairs_of(rotated(t), rotated(far)) == 0);
  const Tri mirror{glm::dvec3{1 + 1e-6, 1e-6, 0}, {1e-6, 1 + 1e-6, 0}, {1 + 1e-6, 1 + 1e-6, 0}};
  CHECK(pairs_of(t, mirror) == 0);
  CHECK(pairs_of(rotated(t), rotated(mirror)) == 0);
  // Float positions give the same (the float overload widens them).
  const std::vector<glm::vec3> xf{glm::vec3(t[0]),     glm::vec3(t[1]),     glm::vec3(t[2]),
                                  glm::vec3(moved[0]), glm::vec3(moved[1]), glm::vec3(moved[2])};
  const std::vector<std::uint32_t> tris{0, 1, 2, 3, 4, 5};
  const auto r =
      intersecting_triangle_pairs(std::span<const std::uint32_t>(tris), std::span<const glm::vec3>(xf));
  REQUIRE(r.ok());
  CHECK(r->pairs == 1);
  CHECK(r->first_a == 0);
  CHECK(r->first_b == 1);
}

TEST_CASE(
    "intersections: a flat grid has none, folded through itself it has at least the crossed triangles") {
  const ParticleSystem s = flat_grid(20); // dx = 1/19: x = 0.25 and 0.75 are inside columns of cells
  const std::vector<glm::dvec3> rest = rest_positions(s);
  std::shared_ptr<const ClothTopology> topology;
  const auto tris = topology_triangles(s, topology);
  const auto flat = intersecting_triangle_pairs(s, std::span<const glm::dvec3>(rest));
  REQUIRE(flat.ok());
  CHECK(flat->pairs == 0);
  CHECK(flat->triangles == 2 * 19 * 19);
  CHECK(flat->degenerate == 0);

  std::vector<glm::dvec3> folded(rest.size());
  std::transform(rest.begin(), rest.end(), folded.begin(), fold_through);
  const IntersectionStats got = pairs(tris, folded);
  const std::size_t bound = fold_through_bound(tris, rest);
  CHECK(bound == 2 * 19); // the strip of cells between columns 4 and 5
  CHECK(got.pairs >= bound);
  check_same(got, brute_force(tris, folded));
  // The system overload takes the topology's triangles, in doubles and in floats.
  check_same(*intersecting_triangle_pairs(s, std::span<const glm::dvec3>(folded)), got);
  const std::vector<glm::vec3> folded_f(folded.begin(), folded.end());
  const auto from_floats = intersecting_triangle_pairs(s, std::span<const glm::vec3>(folded_f));
  REQUIRE(from_floats.ok());
  CHECK(from_floats->pairs >= bound);

  // The same cloth as a mesh (its quads, renumbered by make_mesh_cloth): none flat, and folded at
  // least the bound of its own triangles.
  auto mesh = make_mesh_cloth(surface_mesh(s, rest), MeshClothDesc{});
  REQUIRE(mesh.ok());
  const ParticleSystem& m = mesh->system;
  const std::vector<glm::dvec3> mesh_rest = rest_positions(m);
  REQUIRE(m.surface);
  const auto mesh_flat = intersecting_triangle_pairs(m, std::span<const glm::dvec3>(mesh_rest));
  REQUIRE(mesh_flat.ok());
  CHECK(mesh_flat->pairs == 0);
  CHECK(mesh_flat->triangles == 2 * 19 * 19);
  std::vector<glm::dvec3> mesh_folded(mesh_rest.size());
  std::transform(mesh_rest.begin(), mesh_rest.end(), mesh_folded.begin(), fold_through);
  const auto mesh_got = intersecting_triangle_pairs(m, std::span<const glm::dvec3>(mesh_folded));
  REQUIRE(mesh_got.ok());
  const std::size_t mesh_bound = fold_through_bound(m.surface->triangles, mesh_rest);
  CHECK(mesh_bound == 2 * 19);
  CHECK(mesh_got->pairs >= mesh_bound);
  check_same(*mesh_got, brute_force(m.surface->triangles, mesh_folded));

  // A chain has no triangles.
  auto chain = make_chain(ChainDesc{});
  REQUIRE(chain.ok());
  const auto none = intersecting_triangle_pairs(*chain, std::span<const glm::dvec3>(rest_positions(*chain)));
  REQUIRE(none.ok());
  CHECK(none->pairs == 0);
  CHECK(none->triangles == 0);
}

TEST_CASE("intersections: a grid folded flat onto itself (two exactly coplanar layers) overlaps everywhere") {
  const std::uint32_t n = 20; // columns 0-9 left, 10-19 right; mirrored, column i lands on column 19 - i
  const ParticleSystem s = flat_grid(n);
  std::vector<glm::dvec3> x = rest_positions(s);
  for (glm::dvec3& p : x)
    if (p.x > 0.5)
      p.x = 1.0 - p.x; // z stays 0: the two layers are in one plane
  std::shared_ptr<const ClothTopology> topology;
  const auto tris = topology_triangles(s, topology);
  const IntersectionStats got = pairs(tris, x);
  // Each triangle of the left half's 9 x 19 cells overlaps, with area, both triangles of the
  // mirrored cell (whose diagonal is the other one).
  CHECK(got.pairs >= 2 * 2 * (n / 2 - 1) * (n - 1));
  check_same(got, brute_force(tris, x));
}

TEST_CASE("intersections: a 256 x 256 flat grid has none (the broad phase)") {
  const ParticleSystem s = flat_grid(256);
  const std::vector<glm::dvec3> rest = rest_positions(s);
  const auto r = intersecting_triangle_pairs(s, std::span<const glm::dvec3>(rest));
  REQUIRE(r.ok());
  CHECK(r->pairs == 0);
  CHECK(r->triangles == 2 * 255 * 255);
  // Turned into a tilted plane, still none.
  std::vector<glm::dvec3> turned(rest.size());
  std::transform(rest.begin(), rest.end(), turned.begin(), [](const glm::dvec3& p) {
    return rotate(p, {0.5, 0.5, 0.0}, glm::normalize(glm::dvec3(1, 2, 3)), 0.7);
  });
  const auto t = intersecting_triangle_pairs(s, std::span<const glm::dvec3>(turned));
  REQUIRE(t.ok());
  CHECK(t->pairs == 0);
}

TEST_CASE("intersections: the broad phase finds what a brute force finds on crumpled cloths") {
  std::mt19937 rng(20240916);
  SUBCASE("12 x 12, every particle at random in a small box") {
    const ParticleSystem s = flat_grid(12);
    std::uniform_real_distribution<double> u(0.0, 0.2);
    std::vector<glm::dvec3> x(s.size());
    for (glm::dvec3& p : x)
      p = {u(rng), u(rng), u(rng)};
    std::shared_ptr<const ClothTopology> topology;
    const auto tris = topology_triangles(s, topology);
    const IntersectionStats want = brute_force(tris, x);
    CHECK(want.pairs > 100);
    check_same(pairs(tris, x), want);
  }
  SUBCASE("40 x 40, squeezed to a third along x and crumpled in z") {
    const ParticleSystem s = flat_grid(40);
    std::uniform_real_distribution<double> u(-1.0, 1.0);
    std::vector<glm::dvec3> x = rest_positions(s);
    const double dx = 1.0 / 39;
    for (glm::dvec3& p : x)
      p = {p.x / 3 + 0.3 * dx * u(rng), p.y + 0.3 * dx * u(rng), 0.05 * std::sin(40 * p.x) + 2 * dx * u(rng)};
    std::shared_ptr<const ClothTopology> topology;
    const auto tris = topology_triangles(s, topology);
    const IntersectionStats want = brute_force(tris, x);
    CHECK(want.pairs > 100);
    check_same(pairs(tris, x), want);
  }
  SUBCASE("a large tilted triangle through a fine grid (its box spans the grid: coarser cells)") {
    const ParticleSystem s = flat_grid(40);
    std::vector<glm::dvec3> x = rest_positions(s);
    std::shared_ptr<const ClothTopology> topology;
    const auto grid_tris = topology_triangles(s, topology);
    std::vector<std::uint32_t> tris(grid_tris.begin(), grid_tris.end());
    const auto big = static_cast<std::uint32_t>(x.size());
    x.insert(x.end(), {{-1.0, -1.0, -1.0}, {2.0, 2.0, 1.0}, {2.0, -1.0, 0.5}});
    tris.insert(tris.end(), {big, big + 1, big + 2});
    const IntersectionStats want = brute_force(tris, x);
    CHECK(want.pairs > 39); // its plane crosses z = 0 along a line across the grid
    check_same(pairs(tris, x), want);
  }
}

TEST_CASE("intersections: bad input is invalid_argument naming the value") {
  const std::vector<glm::dvec3> x{{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
  const auto call = [&](std::vector<std::uint32_t> tris, std::vector<glm::dvec3> at = {}) {
    if (at.empty())
      at = x;
    return intersecting_triangle_pairs(std::span<const std::uint32_t>(tris), std::span<const glm::dvec3>(at));
  };
  const auto count = call({0, 1, 2, 0});
  REQUIRE_FALSE(count.ok());
  CHECK(count.error().code == ErrorCode::invalid_argument);
  CHECK(count.error().message.find("4 triangle indices") != std::string::npos);
  const auto range = call({0, 1, 2, 2, 1, 7});
  REQUIRE_FALSE(range.ok());
  CHECK(range.error().code == ErrorCode::invalid_argument);
  CHECK(range.error().message.find("triangle 1 has vertex index 7, but there are 3 positions") !=
        std::string::npos);
  const auto nan = call({0, 1, 2}, {{0, 0, 0}, {1, std::numeric_limits<double>::quiet_NaN(), 0}, {0, 1, 0}});
  REQUIRE_FALSE(nan.ok());
  CHECK(nan.error().code == ErrorCode::invalid_argument);
  CHECK(nan.error().message.find("position 1 is not finite") != std::string::npos);
  const ParticleSystem s = flat_grid(3);
  const auto size = intersecting_triangle_pairs(s, std::span<const glm::dvec3>(x));
  REQUIRE_FALSE(size.ok());
  CHECK(size.error().message.find("3 positions for 9 particles") != std::string::npos);
  // No triangles: nothing to do.
  const auto empty = call({});
  REQUIRE(empty.ok());
  CHECK(empty->pairs == 0);
  CHECK(empty->triangles == 0);
}
