// SPDX-License-Identifier: MIT
// samples/scenes/tablecloth_on_table.json on every backend (CPU float, CPU double, Vulkan with
// validation): with its friction (0.6) the tablecloth drapes over the table and comes to rest, and
// no particle is ever deeper inside a collider than contact_epsilon after a step; without friction
// the same cloth slides off (so it is the friction that holds it).
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>

#include "sim_backends.hpp"

using namespace vkcloth;
using namespace vkcloth::test;

namespace {

Scene tablecloth(std::span<const std::string> overrides = {}) {
  auto scene =
      load_scene_file(std::filesystem::path(VKCLOTH_SCENES_DIR) / "tablecloth_on_table.json", overrides);
  REQUIRE_MESSAGE(scene.ok(), (scene.ok() ? "" : scene.error().message));
  return std::move(*scene);
}

/// The table top's height (collider 0, a box) and the grid's centre particle.
double table_top(const Scene& s) {
  const Collider& table = s.params.colliders.at(0);
  REQUIRE(table.type == Collider::Type::box);
  return table.center.z + table.half_extents.z;
}
std::size_t centre_particle(const Scene& s) {
  const Grid g = *s.system.grid;
  return std::size_t(g.ny / 2) * g.nx + g.nx / 2;
}

} // namespace

TEST_CASE(
    "tablecloth_on_table: friction 0.6 holds the tablecloth, at rest (< 1e-3 m/s), never deeper than eps") {
  ValidationScope validation;
  const Scene scene = tablecloth();
  const SimParams& p = scene.params;
  REQUIRE(p.colliders.at(0).friction == 0.6);
  const double eps = p.contact_epsilon, top = table_top(scene);
  const std::size_t centre = centre_particle(scene);
  const auto last_second = static_cast<std::uint64_t>(std::ceil(1.0 / p.dt - 1e-9));
  REQUIRE(scene.steps > 3 * last_second); // settled: the last second starts well after the landing
  for (Backend b : backends()) {
    CAPTURE(to_string(b));
    auto s = make_sim(b, scene.system, p);
    double deepest = -1.0, calm = 0.0;
    for (std::uint64_t step = 1; step <= scene.steps; ++step) {
      REQUIRE(s->step().ok());
      // The colliders do not move here: the scene's poses are the solver's.
      const auto depth = penetration(scene.system, p.colliders, s->positions());
      REQUIRE(depth.ok());
      deepest = std::max(deepest, depth->depth);
      if (step > scene.steps - last_second)
        calm = std::max(calm, max_free_speed(scene.system, s->velocities()));
    }
    const auto pos = s->positions();
    std::size_t on_top = 0, off_floor = 0;
    for (const glm::dvec3& x : pos) {
      on_top += x.z > top - 0.01;
      off_floor += x.z > 0.1;
    }
    const glm::dvec3 slide = pos[centre] - scene.system.particles[centre].position;
    MESSAGE(std::string(to_string(b))
            << ": largest speed over the last second " << calm << " m/s, deepest penetration " << deepest
            << " m, " << on_top << " of " << pos.size() << " points on the top, centre moved "
            << std::hypot(slide.x, slide.y) << " m");
    CHECK(calm < 1e-3);                                // at rest
    CHECK(deepest <= eps);                             // after every step
    CHECK(off_floor == pos.size());                    // all of it on the table or hanging from it
    CHECK(double(on_top) > 0.25 * double(pos.size())); // a third lies on the top
    CHECK(std::hypot(slide.x, slide.y) < 0.01);        // where it landed
  }
}

TEST_CASE("tablecloth_on_table without friction: the overhang pulls the same cloth off the table") {
  const std::string frictionless[] = {"colliders.0.friction=0"};
  const Scene scene = tablecloth(frictionless);
  const std::size_t centre = centre_particle(scene);
  auto s = make_sim(Backend::cpu_float, scene.system, scene.params);
  REQUIRE(s->run(scene.steps).ok());
  const auto pos = s->positions();
  const glm::dvec3 slide = pos[centre] - scene.system.particles[centre].position;
  double highest = -1.0;
  for (const glm::dvec3& x : pos)
    highest = std::max(highest, x.z);
  MESSAGE("without friction: highest point " << highest << " m, centre moved " << std::hypot(slide.x, slide.y)
                                             << " m");
  CHECK(highest < 0.5 * table_top(scene)); // on the floor
  CHECK(slide.x > 0.3);                    // towards the long overhang (+x)
}
