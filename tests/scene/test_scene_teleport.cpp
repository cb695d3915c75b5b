// SPDX-License-Identifier: MIT
// A teleport key on a collider the cloth is attached to carries the cloth with it, unfelt, even
// when the scene sets no inertia frame (the collider becomes the frame, at full inertia); a scene
// whose frame is another collider, or with several cloths and no frame, is refused naming both keys.
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <iterator>
#include <string>

#include <glm/geometric.hpp>

#include "scene/scene_errors_util.hpp"
#include "vkcloth/vkcloth.hpp"

using namespace vkcloth;
using namespace vkcloth::test;

namespace {

// A 6 x 6 cloth hanging from a box by its top row; the box jumps 10 m along x at t = 0.1 s.
std::string hanging_from_a_teleport(const std::string& extra) {
  return R"({"system": "cloth", "integrator": {"method": "vbd", "dt": 0.005},
    "cloth": {"resolution": [6, 6], "size": [0.3, 0.3], "origin": [-0.15, 0, 0.5], "pins": [],
              "attach": [{"collider": 0, "region": {"min": [-1, -1, 0.79], "max": [1, 1, 1]}}]},
    "colliders": [{"type": "box", "center": [0, 0, 0.85], "half_extents": [0.2, 0.05, 0.05],
                   "keyframes": [{"t": 0}, {"t": 0.1, "translate": [10, 0, 0], "teleport": true}]},
                  {"type": "sphere", "center": [3, 0, 0], "radius": 0.1,
                   "keyframes": [{"t": 0}, {"t": 0.1, "translate": [1, 0, 0], "teleport": true}]}])" +
         extra + "}";
}

/// The fastest free particle over 0.1 s after the jump (steps 21 ... 40).
double fastest_after_jump(const Scene& s, bool jumped = true) {
  auto solver = CpuSolver<float>::create(s.system, s.params);
  REQUIRE(solver.ok());
  REQUIRE(solver->run(20).ok());
  double fastest = 0.0;
  for (int k = 0; k < 20; ++k) {
    REQUIRE(solver->step().ok());
    for (std::size_t p = 0; p < s.system.size(); ++p)
      if (!s.system.particles[p].pinned)
        fastest = std::max(fastest, double(glm::length(solver->velocities()[p])));
  }
  CHECK((solver->positions()[0].x > 9.0) == jumped); // the cloth came along
  return fastest;
}

} // namespace

TEST_CASE("a teleport of the collider a cloth hangs from carries the cloth, unfelt, without an inertia key") {
  auto s = parse_scene(hanging_from_a_teleport(""), "teleport.json");
  REQUIRE_MESSAGE(s.ok(), s.error().message);
  REQUIRE(s->params.inertia.collider == 0u); // the attached collider, not the other teleporting one
  CHECK(s->params.inertia.linear == 1.0);
  CHECK(s->params.inertia.angular == 1.0);
  // Unfelt: after the jump it swings as the same cloth on a collider that does not jump.
  std::string still = hanging_from_a_teleport("");
  still.replace(still.find("\"translate\": [10, 0, 0], "), 25, "");
  auto s_still = parse_scene(still, "still.json");
  REQUIRE_MESSAGE(s_still.ok(), s_still.error().message);
  const double jumped = fastest_after_jump(*s), unmoved = fastest_after_jump(*s_still, false);
  CHECK(unmoved > 0.1);
  CHECK(std::abs(jumped - unmoved) < 0.02 * unmoved);
  // The same scene in world space (the rule off) is yanked: the attached row jumps 10 m alone.
  Scene world = *s;
  world.params.inertia = Inertia{};
  auto solver = CpuSolver<float>::create(world.system, world.params);
  REQUIRE(solver.ok());
  REQUIRE(solver->run(25).ok());
  double fastest = 0.0;
  for (const glm::vec3& v : solver->velocities())
    fastest = std::max(fastest, double(glm::length(v)));
  CHECK(fastest > 50.0);
}

TEST_CASE("the cape without its inertia key is the cape with it: the same frame, the same bits") {
  const std::string path = std::string(VKCLOTH_SCENES_DIR) + "/character_cape.json";
  auto with = load_scene_file(path);
  REQUIRE(with.ok());
  std::ifstream f(path);
  std::string json((std::istreambuf_iterator<char>(f)), std::istreambuf_iterator<char>());
  const auto at = json.find("\"inertia\"");
  REQUIRE(at != std::string::npos);
  json.erase(at, json.find('\n', at) - at + 1); // the line "inertia": {...},
  auto without = parse_scene(json, "character_cape_without_inertia.json");
  REQUIRE_MESSAGE(without.ok(), without.error().message);
  CHECK(without->params.inertia.collider == with->params.inertia.collider);
  auto a = CpuSolver<float>::create(with->system, with->params);
  auto b = CpuSolver<float>::create(without->system, without->params);
  REQUIRE(a.ok());
  REQUIRE(b.ok());
  REQUIRE(a->run(30).ok());
  REQUIRE(b->run(30).ok());
  CHECK(std::equal(a->positions().begin(), a->positions().end(), b->positions().begin()));
}

TEST_CASE("a teleport the cloth cannot follow is refused, naming both keys") {
  expect_error(hanging_from_a_teleport(R"(, "inertia": {"collider": 1})"),
               {"colliders[0].keyframes[1].teleport", "cloth.attach[0]", "inertia.collider is 1"});
  // Hanging from two colliders that both jump, with no frame named.
  std::string two = hanging_from_a_teleport("");
  two.replace(two.find(R"(}}]},)"), 5,
              R"(}}, {"collider": 1, "region": {"min": [-1, -1, 0.49], "max": [1, 1, 0.51]}}]},)");
  expect_error(two, {"colliders[0].keyframes[1].teleport and colliders[1].keyframes[1].teleport"});
  expect_error(R"({"system": "cloth", "cloths": [
      {"resolution": [4, 4], "size": [0.3, 0.3], "origin": [-0.15, 0, 0.5], "pins": [],
       "attach": [{"collider": 0, "region": {"min": [-1, -1, 0.79], "max": [1, 1, 1]}}]}, {}],
    "colliders": [{"type": "box", "center": [0, 0, 0.85], "half_extents": [0.2, 0.05, 0.05],
                   "keyframes": [{"t": 0}, {"t": 0.1, "translate": [10, 0, 0], "teleport": true}]}]})",
               {"colliders[0].keyframes[1].teleport", "several cloths", "inertia.collider"});
}
