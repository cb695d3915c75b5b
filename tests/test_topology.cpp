// SPDX-License-Identifier: MIT
// ClothTopology: the gather lists, normal fans, triangles, uvs and grid stencil every solver and
// renderer reads, prepared once from a ParticleSystem.
#include <doctest/doctest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <string>
#include <tuple>
#include <utility>

#include "vkcloth/gpu/world.hpp"
#include "vkcloth/vkcloth.hpp"

using namespace vkcloth;

namespace {

ParticleSystem cloth(std::uint32_t nx, std::uint32_t ny) {
  ClothDesc d;
  d.nx = nx;
  d.ny = ny;
  d.size = {1.3, 0.7}; // dx != dy: the stencil's rest lengths differ per direction
  auto s = make_cloth(d);
  REQUIRE(s.ok());
  return std::move(s.value());
}

std::shared_ptr<const ClothTopology> prepare(const ParticleSystem& s) {
  auto t = ClothTopology::create(s);
  REQUIRE(t.ok());
  return *t;
}

/// The stencil offset k as a grid step (di, dj).
std::pair<int, int> step_of(std::int32_t offset, int nx) {
  for (int dj = -2; dj <= 2; ++dj)
    for (int di = -2; di <= 2; ++di)
      if (dj * nx + di == offset)
        return {di, dj};
  FAIL("offset ", offset, " is no step within 2 cells");
  return {0, 0};
}

} // namespace

TEST_CASE("a make_cloth grid's topology: gather lists, stencil and masks, triangles, fans, uvs") {
  for (auto [nx, ny] : {std::pair<std::uint32_t, std::uint32_t>{9, 7}, {37, 23}}) {
    CAPTURE(nx);
    CAPTURE(ny);
    const ParticleSystem s = cloth(nx, ny);
    const auto t = prepare(s);
    const std::size_t n = s.size();
    REQUIRE(t->size() == n);
    REQUIRE(t->grid().has_value());
    CHECK(t->has_surface());

    // The gather lists are the adjacency's, in its order, with the springs' constants.
    REQUIRE(std::equal(t->edge_offsets().begin(), t->edge_offsets().end(), s.adjacency.offsets.begin(),
                       s.adjacency.offsets.end()));
    REQUIRE(t->edges().size() == s.adjacency.refs.size());
    for (std::size_t e = 0; e < t->edges().size(); ++e) {
      const SpringRef& r = s.adjacency.refs[e];
      CHECK(t->edges()[e].other == r.other);
      CHECK(t->edges()[e].rest_length == s.springs[r.spring].rest_length);
      CHECK(t->edges()[e].stiffness == s.springs[r.spring].stiffness);
    }

    // The stencil: 12 springs, masks with exactly the in-grid springs, fan bits per the grid fan.
    const GridStencil* st = t->stencil();
    REQUIRE(st != nullptr);
    CHECK(st->border_geometric);
    CHECK(st->reach == 2 * nx); // the bend springs two rows away
    REQUIRE(st->masks.size() == n);
    const int inx = int(nx), iny = int(ny);
    for (int j = 0; j < iny; ++j)
      for (int i = 0; i < inx; ++i) {
        const std::size_t p = std::size_t(j * inx + i);
        unsigned want = 0;
        for (int k = 0; k < 12; ++k) {
          const auto [di, dj] = step_of(st->offset[std::size_t(k)], inx);
          if (i + di >= 0 && i + di < inx && j + dj >= 0 && j + dj < iny)
            want |= 1u << k;
        }
        const bool has[4] = {i + 1 < inx, j + 1 < iny, i > 0, j > 0};
        for (int k = 0; k < 4; ++k)
          if (has[k] && has[(k + 1) & 3])
            want |= 1u << (12 + k);
        CHECK(st->masks[p] == want);
      }
    CHECK((st->masks[0] >> 12) == 0x1u);                   // corner (0, 0): fan term right/up only
    CHECK(st->masks[std::size_t(2 * inx + 2)] == 0xFFFFu); // first interior particle: everything

    // Triangles: the renderer's and the GPU batch's list.
    const auto grid_tris = gpu::grid_triangle_indices(nx, ny);
    CHECK(std::equal(t->triangles().begin(), t->triangles().end(), grid_tris.begin(), grid_tris.end()));

    // Fans: right/up/left/down, one triangle per present adjacent pair, in that order.
    REQUIRE(t->fan_offsets().size() == n + 1);
    for (int j = 0; j < iny; ++j)
      for (int i = 0; i < inx; ++i) {
        const std::uint32_t p = std::uint32_t(j * inx + i);
        const bool has[4] = {i + 1 < inx, j + 1 < iny, i > 0, j > 0};
        const std::uint32_t nb[4] = {p + 1, p + nx, p - 1, p - nx};
        std::vector<std::pair<std::uint32_t, std::uint32_t>> want;
        for (int k = 0; k < 4; ++k)
          if (has[k] && has[(k + 1) & 3])
            want.emplace_back(nb[k], nb[(k + 1) & 3]);
        const bool corner = (i == 0 || i == inx - 1) && (j == 0 || j == iny - 1);
        const bool edge = !corner && (i == 0 || i == inx - 1 || j == 0 || j == iny - 1);
        // Neighbours 2 / 3 / 4 (corner / edge / inside): triangles 1 / 2 / 4.
        CHECK(want.size() == (corner ? 1u : edge ? 2u : 4u));
        const auto first = t->fan_offsets()[p], last = t->fan_offsets()[p + 1];
        REQUIRE(last - first == want.size());
        for (std::size_t k = 0; k < want.size(); ++k) {
          CHECK(t->fans()[first + k].a == want[k].first);
          CHECK(t->fans()[first + k].b == want[k].second);
        }
      }

    // Uvs: (i / (nx-1), j / (ny-1)) in float.
    REQUIRE(t->uvs().size() == n);
    CHECK(t->uvs()[0] == glm::vec2(0.0f));
    CHECK(t->uvs()[n - 1] == glm::vec2(1.0f));
    CHECK(t->uvs()[nx + 3] == glm::vec2(3.0f / float(nx - 1), 1.0f / float(ny - 1)));
  }
}

TEST_CASE("a chain has no grid, no stencil, no surface and empty fans") {
  ChainDesc d;
  d.masses = {1.0, 2.0, 1.5};
  d.stiffness = {20.0, 30.0, 25.0};
  d.rest_lengths = {0.4, 0.3, 0.2};
  d.positions.clear();
  auto s = make_chain(d);
  REQUIRE(s.ok());
  const auto t = prepare(*s);
  CHECK(t->size() == 4);
  CHECK_FALSE(t->grid().has_value());
  CHECK(t->stencil() == nullptr);
  CHECK(t->triangles().empty());
  CHECK_FALSE(t->has_surface());
  CHECK(t->fans().empty());
  REQUIRE(t->fan_offsets().size() == 5);
  CHECK(
      std::all_of(t->fan_offsets().begin(), t->fan_offsets().end(), [](std::uint32_t o) { return o == 0; }));
  CHECK(t->edges().size() == 6);
  CHECK(t->system().particles[0].pinned);
}

TEST_CASE("the grid stencil needs 5 x 5 and identical interior gather lists") {
  CHECK(prepare(cloth(4, 9))->stencil() == nullptr);
  CHECK(prepare(cloth(9, 4))->stencil() == nullptr);
  CHECK(prepare(cloth(5, 5))->stencil() != nullptr);

  SUBCASE("one interior spring with another stiffness") {
    ParticleSystem s = cloth(9, 7);
    const std::uint32_t p = 3 * 9 + 4; // interior
    const SpringRef r = s.adjacency.refs[s.adjacency.offsets[p] + 5];
    s.springs[r.spring].stiffness *= 1.5;
    const auto t = prepare(s);
    CHECK(t->stencil() == nullptr);
    CHECK(t->edges()[s.adjacency.offsets[p] + 5].stiffness == s.springs[r.spring].stiffness);
  }
  SUBCASE("a spring kind left out: 8 springs per interior particle, no stencil") {
    ClothDesc d;
    d.nx = 9;
    d.ny = 9;
    d.stiffness.shear = 0.0;
    auto s = make_cloth(d);
    REQUIRE(s.ok());
    CHECK(prepare(*s)->stencil() == nullptr);
  }
  SUBCASE("a border spring missing: masks still apply, SC_BORDER does not") {
    ParticleSystem s = cloth(9, 7);
    // The bend spring along the bottom row from (0, 0) to (2, 0).
    const auto it = std::find_if(s.springs.begin(), s.springs.end(), [](const Spring& sp) {
      return sp.kind == SpringKind::bend && std::min(sp.a, sp.b) == 0 && std::max(sp.a, sp.b) == 2;
    });
    REQUIRE(it != s.springs.end());
    s.springs.erase(it);
    s.finalize();
    const auto t = prepare(s);
    REQUIRE(t->stencil() != nullptr);
    CHECK(t->stencil()->masks.size() == s.size());
    CHECK_FALSE(t->stencil()->border_geometric);
  }
}

TEST_CASE("an invalid system is an error naming the problem") {
  auto empty = ClothTopology::create(ParticleSystem{});
  REQUIRE_FALSE(empty.ok());
  CHECK(empty.error().code == ErrorCode::invalid_argument);
  CHECK(empty.error().message.find("empty") != std::string::npos);

  ParticleSystem s = cloth(6, 6);
  s.adjacency = {};
  auto unfinalized = ClothTopology::create(s);
  REQUIRE_FALSE(unfinalized.ok());
  CHECK(unfinalized.error().message.find("finalize") != std::string::npos);

  ParticleSystem g = cloth(6, 6);
  g.grid->nx = 7;
  auto mismatch = ClothTopology::create(g);
  REQUIRE_FALSE(mismatch.ok());
  CHECK(mismatch.error().message.find("7 x 6") != std::string::npos);
}

TEST_CASE("grid uvs: the default, a uv_transform, the caller's own, and bad ones refused") {
  ClothDesc d;
  d.nx = 5;
  d.ny = 3;
  const auto plain = prepare(make_cloth(d).value());
  CHECK(plain->uvs()[0] == glm::vec2(0.0f, 0.0f));
  CHECK(plain->uvs()[4] == glm::vec2(1.0f, 0.0f));
  CHECK(plain->uvs()[14] == glm::vec2(1.0f, 1.0f));

  // Swap u and v and flip the new v: (s, t) -> (t, 1 - s), a quarter turn of the texture.
  d.uv_transform = UvTransform{{0.0f, 1.0f}, {0.0f, -1.0f}, {1.0f, 0.0f}};
  const auto turned = prepare(make_cloth(d).value());
  for (std::uint32_t j = 0; j < d.ny; ++j)
    for (std::uint32_t i = 0; i < d.nx; ++i) {
      const glm::vec2 st = plain->uvs()[j * d.nx + i];
      CHECK(turned->uvs()[j * d.nx + i] == glm::vec2(st.y, 1.0f - st.x));
    }
  // The identity transform leaves the default bits (every image drawn so far depends on them).
  d.uv_transform = UvTransform{};
  CHECK(std::ranges::equal(prepare(make_cloth(d).value())->uvs(), plain->uvs()));

  std::vector<glm::vec2> own(15);
  for (std::size_t k = 0; k < own.size(); ++k)
    own[k] = {0.1f * float(k), -0.5f};
  d.uvs = own;
  CHECK(std::ranges::equal(prepare(make_cloth(d).value())->uvs(), own));

  d.uvs.pop_back();
  auto wrong_count = make_cloth(d);
  REQUIRE_FALSE(wrong_count.ok());
  CHECK(wrong_count.error().message.find("14 texture coordinates for a 5 x 3 grid of 15") !=
        std::string::npos);
  d.uvs = own;
  d.uvs[7].y = std::numeric_limits<float>::quiet_NaN();
  auto not_finite = make_cloth(d);
  REQUIRE_FALSE(not_finite.ok());
  CHECK(not_finite.error().message.find("texture coordinate 7 is not finite") != std::string::npos);
  d.uvs.clear();
  d.uv_transform.u_axis.x = std::numeric_limits<float>::infinity();
  REQUIRE_FALSE(make_cloth(d).ok());
}

TEST_CASE("the grid's triangle strip with restart holds the triangle list's triangles, same winding") {
  for (auto [nx, ny] : {std::pair{2u, 2u}, std::pair{5u, 3u}, std::pair{4u, 7u}}) {
    const auto strip = gpu::grid_triangle_strip_indices(nx, ny);
    CHECK(strip.size() == std::size_t(ny - 1) * (2 * nx + 1) - 1);
    // Decode as Vulkan does: triangle k of a strip is (v_k, v_k+1, v_k+2), odd k (v_k, v_k+2, v_k+1)
    // (the spec's counting restarts with every strip); rotate each so its smallest index is first.
    using Tri = std::array<std::uint32_t, 3>;
    auto canonical = [](Tri t) {
      std::rotate(t.begin(), std::min_element(t.begin(), t.end()), t.end());
      return t;
    };
    std::vector<Tri> from_strip, from_list;
    std::size_t start = 0;
    for (std::size_t e = 0; e <= strip.size(); ++e) {
      if (e < strip.size() && strip[e] != gpu::strip_restart_index)
        continue;
      for (std::size_t k = start; k + 2 < e; ++k) {
        const bool odd = (k - start) % 2 == 1;
        from_strip.push_back(canonical(odd ? Tri{strip[k], strip[k + 2], strip[k + 1]}
                                           : Tri{strip[k], strip[k + 1], strip[k + 2]}));
      }
      start = e + 1;
    }
    const auto list = gpu::grid_triangle_indices(nx, ny);
    for (std::size_t k = 0; k < list.size(); k += 3)
      from_list.push_back(canonical({list[k], list[k + 1], list[k + 2]}));
    std::ranges::sort(from_strip);
    std::ranges::sort(from_list);
    CHECK(from_strip == from_list);
  }
  CHECK(gpu::grid_triangle_strip_indices(1, 5).empty());
}

namespace {

/// A surface from triangles (or polygons with `face_offsets`), springs along the given pairs.
ParticleSystem surface_system(std::size_t n, std::vector<std::uint32_t> triangles,
                              std::vector<std::pair<std::uint32_t, std::uint32_t>> springs,
                              std::vector<std::uint32_t> face_offsets = {},
                              std::vector<std::uint32_t> faces = {}) {
  ParticleSystem s;
  for (std::size_t p = 0; p < n; ++p) {
    Particle q;
    const double angle = 0.7 * double(p);
    q.position = {std::cos(angle) * (1.0 + 0.1 * double(p)), std::sin(angle), 0.01 * double(p)};
    q.mass = 0.1;
    s.particles.push_back(q);
  }
  for (auto [a, b] : springs)
    s.springs.push_back(Spring{a, b, 0.5 + 0.01 * double(a + b), 10.0 + double(a), SpringKind::structural});
  s.surface = Surface{};
  s.surface->triangles = std::move(triangles);
  s.surface->face_offsets = std::move(face_offsets);
  s.surface->faces = std::move(faces);
  s.surface->uvs.assign(n, glm::vec2(0.0f));
  s.finalize();
  return s;
}

/// Particle p's fan triangles as its ring bits spell them (cloth_kernel.h add_ring_term's walk).
std::vector<std::pair<std::uint32_t, std::uint32_t>> ring_triangles(const ClothTopology& t, std::uint32_t p) {
  std::vector<std::pair<std::uint32_t, std::uint32_t>> out;
  std::uint32_t prev = ~0u, first = ~0u;
  for (std::uint32_t e = t.edge_offsets()[p]; e < t.edge_offsets()[p + 1]; ++e) {
    const GatherEdge& g = t.edges()[e];
    if (g.ring & ring_start)
      first = g.other;
    if (g.ring & ring_prev)
      out.emplace_back(prev, g.other);
    if (g.ring & ring_close)
      out.emplace_back(g.other, first);
    prev = g.other;
  }
  return out;
}

/// Every particle: the ring bits spell exactly its fan's triangles (those with p twice left out:
/// they add zero); the ring entries come first; the gather list holds the adjacency's springs
/// (other end and constants) plus a zero-stiffness entry per fan neighbour no spring reaches.
void check_rings(const ParticleSystem& s, std::size_t zero_entries_expected) {
  const auto t = prepare(s);
  REQUIRE(t->ring_normals());
  std::size_t zero_entries = 0;
  for (std::uint32_t p = 0; p < s.size(); ++p) {
    CAPTURE(p);
    std::vector<std::pair<std::uint32_t, std::uint32_t>> fan;
    for (std::uint32_t k = t->fan_offsets()[p]; k < t->fan_offsets()[p + 1]; ++k)
      if (t->fans()[k].a != p && t->fans()[k].b != p)
        fan.emplace_back(t->fans()[k].a, t->fans()[k].b);
    auto spelled = ring_triangles(*t, p);
    std::sort(fan.begin(), fan.end());
    std::sort(spelled.begin(), spelled.end());
    CHECK(spelled == fan);

    bool ring_part = true;
    std::vector<std::tuple<std::uint32_t, double, double>> got, want;
    for (std::uint32_t e = t->edge_offsets()[p]; e < t->edge_offsets()[p + 1]; ++e) {
      const GatherEdge& g = t->edges()[e];
      CHECK((g.ring == 0 || ring_part)); // no ring entry after a plain one
      ring_part = ring_part && g.ring != 0;
      CHECK((e < t->fan_ends()[p]) == ring_part); // fan_ends: the end of that prefix
      if (g.stiffness == 0.0 && g.rest_length == 0.0)
        ++zero_entries;
      else
        got.emplace_back(g.other, g.rest_length, g.stiffness);
    }
    for (std::uint32_t e = s.adjacency.offsets[p]; e < s.adjacency.offsets[p + 1]; ++e) {
      const Spring& sp = s.springs[s.adjacency.refs[e].spring];
      want.emplace_back(s.adjacency.refs[e].other, sp.rest_length, sp.stiffness);
    }
    std::sort(got.begin(), got.end());
    std::sort(want.begin(), want.end());
    CHECK(got == want);
  }
  CHECK(zero_entries == zero_entries_expected);
}

} // namespace

TEST_CASE("a surface's gather lists carry its normal fans: ring bits spell every fan triangle") {
  SUBCASE("a hexagon around a centre: one closed ring inside, open chains on the rim") {
    // Centre 0, rim 1..6 counter-clockwise; springs along every triangle edge.
    std::vector<std::uint32_t> tris;
    std::vector<std::pair<std::uint32_t, std::uint32_t>> springs;
    for (std::uint32_t k = 1; k <= 6; ++k) {
      const std::uint32_t next = k % 6 + 1;
      tris.insert(tris.end(), {0, k, next});
      springs.emplace_back(0, k);
      springs.emplace_back(k, next);
    }
    const ParticleSystem s = surface_system(7, tris, springs);
    check_rings(s, 0);
    const auto t = prepare(s);
    // The centre: its 6 neighbours in ring order, one chain that closes.
    REQUIRE(t->edge_offsets()[1] - t->edge_offsets()[0] == 6);
    CHECK(t->edges()[0].ring == ring_start);
    for (int k = 1; k < 5; ++k)
      CHECK(t->edges()[std::size_t(k)].ring == ring_prev);
    CHECK(t->edges()[5].ring == (ring_prev | ring_close));
    // A rim particle: an open chain of 3 (its two triangles).
    const std::uint32_t rim = t->edge_offsets()[1];
    CHECK(t->edges()[rim].ring == ring_start);
    CHECK(t->edges()[rim + 1].ring == ring_prev);
    CHECK(t->edges()[rim + 2].ring == ring_prev);
  }
  SUBCASE("a bowtie: two chains at the shared corner") {
    check_rings(surface_system(5, {0, 1, 2, 0, 3, 4}, {{0, 1}, {1, 2}, {2, 0}, {0, 3}, {3, 4}, {4, 0}}), 0);
  }
  SUBCASE("fan neighbours no spring reaches get zero-stiffness entries") {
    // Triangle (0, 1, 2) with a single spring 0-1: particle 0 lacks 2, 1 lacks 2, 2 lacks 0 and 1.
    check_rings(surface_system(3, {0, 1, 2}, {{0, 1}}), 4);
  }
  SUBCASE("a neighbour twice in one fan (two triangles on one edge pair) and a degenerate triangle") {
    // (0, 1, 2) and (0, 2, 1): particle 0's chain 1 -> 2 -> 1 closes; (0, 0, 3) adds nothing.
    check_rings(surface_system(4, {0, 1, 2, 0, 2, 1, 0, 0, 3}, {{0, 1}, {1, 2}, {2, 0}, {0, 3}}), 0);
  }
  SUBCASE("quads: each corner's edge neighbours") {
    // A 3 x 2 strip of two quads, 0 1 2 / 3 4 5, counter-clockwise.
    check_rings(surface_system(6, {0, 1, 4, 0, 4, 3, 1, 2, 5, 1, 5, 4},
                               {{0, 1}, {1, 2}, {3, 4}, {4, 5}, {0, 3}, {1, 4}, {2, 5}, {0, 4}, {1, 5}},
                               {0, 4, 8}, {0, 1, 4, 3, 1, 2, 5, 4}),
                0);
  }
  SUBCASE("a grid keeps its adjacency order and its fan lists") {
    const auto t = prepare(cloth(4, 6)); // no stencil under 5 x 5 either
    CHECK_FALSE(t->ring_normals());
    for (const GatherEdge& g : t->edges())
      CHECK(g.ring == 0);
  }
}
