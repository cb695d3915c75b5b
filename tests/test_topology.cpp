// SPDX-License-Identifier: MIT
// ClothTopology: the gather lists, normal fans, triangles, uvs and grid stencil every solver and
// renderer reads, prepared once from a ParticleSystem.
#include <doctest/doctest.h>

#include <algorithm>
#include <array>
#include <limits>
#include <string>
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
