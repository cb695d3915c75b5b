// SPDX-License-Identifier: MIT
// "cloths": several cloths in one scene, joined into one system whose particles run on cloth by
// cloth. Their particles, springs, faces and attachments are each cloth's own, shifted; one entry
// moves as the same "cloth" does; self-collision keeps two dropped cloths apart, which pass through
// each other without it; the outputs list every cloth; bad entries name cloths[k].
#include <doctest/doctest.h>

#include <cmath>
#include <string>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "cli_util.hpp"
#include "scene/scene_errors_util.hpp"
#include "vkcloth/export.hpp"
#include "vkcloth/vkcloth.hpp"

using namespace vkcloth;
using namespace vkcloth::test;

namespace {

Scene parsed(const std::string& text, const std::string& source = "cloths.json") {
  auto s = parse_scene(text, source);
  REQUIRE_MESSAGE(s.ok(), s.error().message);
  return std::move(*s);
}

const std::string grid_a =
    R"({"resolution": [6, 5], "size": [0.5, 0.4], "origin": [0, 0, 1], "orientation": "horizontal"})";
const std::string grid_b =
    R"({"resolution": [4, 4], "size": [0.3, 0.3], "origin": [0.1, 0.1, 1.2], "orientation": "horizontal",
  "material": "cotton", "pins": [], "attach": [{"collider": 0, "vertices": [[0, 0], [3, 3]]}]})";
const std::string box = R"({"type": "box", "center": [0, 0, 2], "half_extents": [0.1, 0.1, 0.1]})";

} // namespace

TEST_CASE("cloths: the entries' particles, springs, faces and attachments, shifted and in order") {
  const Scene a = parsed(R"({"system": "cloth", "colliders": [)" + box + R"(], "cloth": )" + grid_a + "}");
  const Scene b = parsed(R"({"system": "cloth", "colliders": [)" + box + R"(], "cloth": )" + grid_b + "}");
  const Scene both = parsed(R"({"system": "cloth", "colliders": [)" + box + R"(], "cloths": [)" + grid_a +
                            ", " + grid_b + "]}");
  const std::size_t na = a.system.size(), nb = b.system.size();
  REQUIRE(both.system.size() == na + nb);
  REQUIRE(both.system.springs.size() == a.system.springs.size() + b.system.springs.size());
  for (std::size_t p = 0; p < na + nb; ++p) {
    const Particle& want = p < na ? a.system.particles[p] : b.system.particles[p - na];
    CHECK(both.system.particles[p].position == want.position);
    CHECK(both.system.particles[p].mass == want.mass); // the cotton masses of the second
    CHECK(both.system.particles[p].pinned == want.pinned);
  }
  for (std::size_t k = 0; k < b.system.springs.size(); ++k) {
    const Spring& s = both.system.springs[a.system.springs.size() + k];
    CHECK(s.a == b.system.springs[k].a + na);
    CHECK(s.b == b.system.springs[k].b + na);
    CHECK(s.stiffness == b.system.springs[k].stiffness);
    CHECK(s.rest_length == b.system.springs[k].rest_length);
  }
  REQUIRE(both.system.surface);
  CHECK(!both.system.grid);
  CHECK(both.system.surface->triangles.size() == 3 * (2 * 5 * 4 + 2 * 3 * 3));
  CHECK(both.system.surface->face_offsets.size() == 1 + 5 * 4 + 3 * 3); // the grids' quads
  CHECK(both.params.damping == b.params.damping);                       // the material's mu
  CHECK(both.cloths ==
        std::vector<std::uint32_t>{0, static_cast<std::uint32_t>(na), static_cast<std::uint32_t>(na + nb)});
  CHECK(a.cloths.empty());
  REQUIRE(both.params.attachments.size() == 1);
  CHECK(both.params.attachments[0].particles ==
        std::vector<std::uint32_t>{static_cast<std::uint32_t>(na), static_cast<std::uint32_t>(na + 15)});
  CHECK(both.system.particles[na].pinned);
  // outputs number the particles on: the file vertex of the second cloth's first particle is na
  CHECK(file_vertex(both.system, static_cast<std::uint32_t>(na)) == na);
}

TEST_CASE("cloths: one entry moves as the same cloth does, a quad surface giving the grid's normals") {
  // Semi-implicit Euler, whose steps do not depend on the particles' order (vbd's Gauss-Seidel
  // sweeps follow the colouring, a grid's and a surface's differ), with wind (the normals).
  const std::string body = R"({"resolution": [9, 7], "size": [0.8, 0.6], "origin": [-0.4, -0.3, 0.5],
    "orientation": "horizontal"})";
  const std::string rest = R"("integrator": {"method": "semi_implicit_euler", "dt": 0.005},
    "colliders": [{"type": "sphere", "center": [0, 0, 0], "radius": 0.3, "friction": 0.3}], "wind": {"strength": 0.02})";
  const Scene one = parsed(R"({"system": "cloth", )" + rest + R"(, "cloth": )" + body + "}");
  const Scene list = parsed(R"({"system": "cloth", )" + rest + R"(, "cloths": [)" + body + "]}");
  auto s1 = CpuSolver<double>::create(one.system, one.params);
  auto s2 = CpuSolver<double>::create(list.system, list.params);
  REQUIRE(s1.ok());
  REQUIRE(s2.ok());
  REQUIRE(s1->run(300).ok());
  REQUIRE(s2->run(300).ok());
  double worst = 0.0, moved = 0.0;
  for (std::size_t p = 0; p < one.system.size(); ++p) {
    worst = std::max(worst, glm::length(s1->positions()[p] - s2->positions()[p]));
    moved = std::max(moved, glm::length(s1->positions()[p] - one.system.particles[p].position));
  }
  CHECK(moved > 0.1);
  CHECK(worst < 1e-9); // double: the same physics, summed in another order
}

TEST_CASE("cloths: self-collision keeps two dropped cloths apart, without it they pass through") {
  // Two 12 x 12 cloths of 0.4 m (spacing 3.6 cm) 6 cm apart, dropped onto a small sphere; the
  // thickness is the spacing.
  const auto layer = [](double dx, double z) {
    return fmt::format(R"({{"resolution": [12, 12], "size": [0.4, 0.4], "origin": [{}, -0.2, {}],
      "orientation": "horizontal", "material": "cotton", "pins": []}})",
                       -0.2 + dx, z);
  };
  const std::string scene =
      R"({"system": "cloth", "integrator": {"method": "vbd", "dt": 0.0033333333333333335},
    "colliders": [{"type": "sphere", "center": [0, 0, 0], "radius": 0.12, "friction": 0.5}],
    "self_collision": {"enabled": true, "thickness": 0.04, "skin": 0.03, "stiffness": 150},
    "cloths": [)" +
      layer(0.0, 0.2) + ", " + layer(0.05, 0.26) + "]}";
  for (const bool enabled : {true, false}) {
    CAPTURE(enabled);
    Scene s = parsed(scene);
    s.params.self_collision.enabled = enabled;
    auto solver = CpuSolver<float>::create(s.system, s.params);
    REQUIRE(solver.ok());
    std::size_t most = 0;
    for (int k = 0; k < 30; ++k) { // 1 s, checked every 10 steps
      REQUIRE(solver->run(10).ok());
      auto pairs = intersecting_triangle_pairs(s.system, solver->positions());
      REQUIRE(pairs.ok());
      most = std::max(most, pairs->pairs);
    }
    if (enabled)
      CHECK(most == 0);
    else
      CHECK(most > 20);
  }
}

TEST_CASE("cli: a cloths scene's outputs list every cloth, numbered on") {
  const fs::path dir = tmp_dir() / "cloths_cli";
  fs::create_directories(dir);
  const fs::path scene = dir / "two.json";
  {
    std::ofstream f(scene);
    f << R"({"system": "cloth", "integrator": {"steps": 5}, "cloths": [)" << grid_a << R"(,
      {"mesh": ")"
      << (fs::path(VKCLOTH_SCENES_DIR) / "../meshes/flag_with_hole.obj").string()
      << R"(", "particle_mass": 0.01}]})";
  }
  const Scene s = parsed(slurp(scene), scene.string());
  const fs::path positions = dir / "positions.csv", glb = dir / "two.glb";
  const Outcome o = run_cli("cloths_cli", "run '" + scene.string() + "' --positions '" + positions.string() +
                                              "' --export '" + glb.string() + "' --check-intersections");
  REQUIRE(o.code == 0);
  const std::string csv = slurp(positions);
  std::size_t rows = 0, last = 0;
  for (std::size_t at = csv.find('\n'); at != std::string::npos && at + 1 < csv.size();
       at = csv.find('\n', at + 1)) {
    last = std::stoul(csv.substr(at + 1, csv.find(',', at + 1) - at - 1));
    ++rows;
  }
  CHECK(rows == s.system.size());
  CHECK(last >= s.system.size() - 1); // the mesh's file vertices come after the grid's 30 particles
  CHECK(csv.find("\n30,") != std::string::npos);
  CHECK(fs::file_size(glb) > 1000);
  CHECK(o.out.find(fmt::format("(of {} triangles)", s.system.surface->triangles.size() / 3)) !=
        std::string::npos);
}

TEST_CASE("cloths: bad input names the key") {
  expect_error(R"({"system": "cloth", "cloth": {}, "cloths": [{}]})",
               {"cloth and cloths exclude each other"});
  expect_error(R"({"system": "cloth", "cloths": []})", {"cloths is empty"});
  expect_error(R"({"system": "cloth", "cloths": {}})", {"cloths"});
  expect_error(R"({"system": "chain", "cloths": [{}]})", {"\"cloths\" section is not allowed", "chain"});
  expect_error(R"({"system": "cloth", "cloths": [{}, {"resolution": [0, 3]}]})", {"cloths[1].resolution"});
  expect_error(R"({"system": "cloth", "cloths": [{}, {"bogus": 1}]})", {"cloths[1].bogus"});
  expect_error(R"({"system": "cloth", "cloths": [{}, 3]})", {"cloths[1] must be an object"});
  // a file name is not a key: cloths[0]'s missing mesh is named as it is
  expect_error(R"({"system": "cloth", "cloths": [{"mesh": "no/such/cloth.obj"}]})", {"no/such/cloth.obj"});
  expect_error(R"({"system": "cloth", "cloths": [{"material": "cotton"},
    {"material": {"density": 0.1, "stretch": 500, "shear": 50, "bend": 1e-5, "damping": 0.3}}]})",
               {"cloths[1].material's damping", "cloths[0]"});
  expect_error(R"({"system": "cloth", "cloths": [{"attach": [{"collider": 2, "vertices": [[0, 0]]}]}]})",
               {"cloths[0].attach[0].collider is 2"});
  expect_error(R"({"system": "cloth", "physics": {"damping": 0.1}, "cloths": [{"material": "cotton"}]})",
               {"physics.damping and cloths[k].material exclude each other"});
}
