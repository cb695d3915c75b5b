// SPDX-License-Identifier: MIT
// The cloth's frame (docs/model.md "Inertia and teleport"): inertia scales, the
// keyframes' teleport and the host's, on every backend (CPU float, CPU double, Vulkan with
// validation).
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <numbers>

#include <glm/geometric.hpp>
#include <glm/gtc/matrix_transform.hpp>

#include "sim_backends.hpp"

using namespace vkcloth;
using namespace vkcloth::test;

namespace {

/// A free horizontal 6 x 6 cloth, 0.5 m wide, centred on the origin at z = 0.
ParticleSystem free_cloth(glm::dvec3 velocity = glm::dvec3(0.0)) {
  ClothDesc d;
  d.nx = d.ny = 6;
  d.size = {0.5, 0.5};
  d.origin = {-0.25, -0.25, 0.0};
  d.orientation = ClothOrientation::horizontal;
  d.pin_default_corners = false;
  auto sys = make_cloth(d);
  REQUIRE(sys.ok());
  for (Particle& p : sys->particles)
    p.velocity = velocity;
  return *sys;
}

/// No gravity, no damping: only the frame moves the cloth.
SimParams weightless() {
  SimParams p;
  p.gravity = glm::dvec3(0.0);
  p.damping = 0.0;
  return p;
}

} // namespace

TEST_CASE("inertia: a frame that starts moving at 1 m/s carries the cloth by 1 - linear, linear 1 is "
          "world space, bit for bit") {
  const ParticleSystem cloth = free_cloth();
  auto frame = Collider::sphere({0, 0, 5}, 0.1).with_keyframes({{0.0, {}, {}}, {10.0, {10, 0, 0}, {}}});
  REQUIRE(frame.ok());
  ValidationScope validation;
  for (double linear : {0.0, 0.5, 1.0}) {
    CAPTURE(linear);
    SimParams p = weightless();
    p.dt = 0.01;
    p.colliders = {*frame};
    p.inertia.collider = 0;
    p.inertia.linear = linear;
    std::vector<std::vector<glm::dvec3>> ends;
    for (Backend b : backends()) {
      CAPTURE(to_string(b));
      auto s = make_sim(b, cloth, p);
      REQUIRE(s->run(50).ok());
      // The first substep gives the velocity; the positions follow from the second.
      const double carried = 1.0 - linear;
      for (std::size_t i = 0; i < cloth.size(); ++i) {
        CHECK(s->velocity(i).x == doctest::Approx(carried).epsilon(1e-5));
        CHECK(s->position(i).x - cloth.particles[i].position.x ==
              doctest::Approx(carried * 0.49).epsilon(1e-5));
      }
      if (linear == 1.0) { // world space: the same bits as without a frame
        SimParams world = p;
        world.inertia = Inertia{};
        auto w = make_sim(b, cloth, world);
        REQUIRE(w->run(50).ok());
        CHECK(s->positions() == w->positions());
      }
      if (is_float(b))
        ends.push_back(s->positions());
    }
    CHECK(largest_gap(ends) < 1e-5);
  }
}

TEST_CASE("inertia: angular 0 turns the cloth with a frame spinning at pi rad/s (an eighth of a turn in "
          "0.25 s), keeping its radius") {
  const ParticleSystem cloth = free_cloth();
  auto frame = Collider::sphere({0, 0, 5}, 0.1)
                   .with_keyframes({{0.0, {}, {}}, {1.0, {}, {0, 0, 180}}, {2.0, {}, {0, 0, 360}}});
  REQUIRE(frame.ok());
  ValidationScope validation;
  SimParams p = weightless();
  p.dt = 0.001;
  p.colliders = {*frame};
  p.inertia.collider = 0;
  p.inertia.angular = 0.0;
  std::vector<std::vector<glm::dvec3>> ends;
  for (Backend b : backends()) {
    CAPTURE(to_string(b));
    auto s = make_sim(b, cloth, p);
    REQUIRE(s->run(250).ok());
    double worst_angle = 0.0, worst_radius = 0.0;
    for (std::size_t i = 0; i < cloth.size(); ++i) {
      const glm::dvec3 x0 = cloth.particles[i].position, x = s->position(i);
      const double turned = std::atan2(x.y, x.x) - std::atan2(x0.y, x0.x);
      const double angle = std::remainder(turned - std::numbers::pi / 4, 2 * std::numbers::pi);
      worst_angle = std::max(worst_angle, std::abs(angle));
      worst_radius =
          std::max(worst_radius, std::abs(glm::length(glm::dvec2(x)) - glm::length(glm::dvec2(x0))));
    }
    MESSAGE(to_string(b) << ": off an eighth of a turn by " << worst_angle << " rad, radius by "
                         << worst_radius << " m");
    CHECK(worst_angle < 0.01);
    CHECK(worst_radius < 0.005);
    if (is_float(b))
      ends.push_back(s->positions());
  }
  CHECK(largest_gap(ends) < 1e-5);
}

TEST_CASE("inertia: a host frame (no collider) that the host sets moving carries the cloth by 1 - linear") {
  // The host's transform starts at rest, then the host gives it 2 m/s along y (set_params, as each
  // frame would): with linear 0.25 the cloth takes 0.75 of that change and keeps it.
  const ParticleSystem cloth = free_cloth();
  SimParams p = weightless();
  p.dt = 0.01;
  p.inertia.frame = ColliderPose{};
  p.inertia.linear = 0.25;
  ValidationScope validation;
  std::vector<std::vector<glm::dvec3>> ends;
  for (Backend b : backends()) {
    CAPTURE(to_string(b));
    auto s = make_sim(b, cloth, p);
    REQUIRE(s->run(5).ok());
    CHECK(glm::length(s->velocity(0)) < 1e-5); // the springs' rounding only
    SimParams moving = p;
    moving.inertia.frame->linear_velocity = {0, 2, 0};
    REQUIRE(s->set_params(moving).ok());
    REQUIRE(s->run(10).ok());
    // The frame itself moved on by its velocity (params() as the steps left it, for a host's next
    // set_step_params).
    CHECK(s->params().inertia.frame->position.y == doctest::Approx(2.0 * 10 * p.dt).epsilon(1e-9));
    for (std::size_t i = 0; i < cloth.size(); ++i) {
      CHECK(s->velocity(i).y == doctest::Approx(1.5).epsilon(1e-5));
      CHECK(s->position(i).y - cloth.particles[i].position.y ==
            doctest::Approx(1.5 * 9 * p.dt).epsilon(1e-4));
    }
    if (is_float(b))
      ends.push_back(s->positions());
  }
  CHECK(largest_gap(ends) < 1e-5);
  SimParams both = p;
  both.colliders = {Collider::sphere({0, 0, 1}, 0.1)};
  both.inertia.collider = 0;
  auto s = CpuSolver<float>::create(cloth, both);
  REQUIRE_FALSE(s.ok());
  CHECK(s.error().message.find("inertia: give a collider or a frame, not both") != std::string::npos);
  both.inertia.collider.reset();
  both.inertia.frame->rotation = glm::dmat3(3.0);
  s = CpuSolver<float>::create(cloth, both);
  REQUIRE_FALSE(s.ok());
  CHECK(s.error().message.find("inertia.frame: pose.rotation") != std::string::npos);
}

TEST_CASE("teleport: a keyframe's jump moves an attached cloth 10 m unfelt (as its twin that stays), no "
          "particle then faster than its twin, GPU = CPU") {
  // A vertical cloth hangs from a capsule by its pinned top row; the capsule walks at 1 m/s for
  // 0.5 s, stands 0.1 s, then jumps 10 m. Its twin
  // stands where it stopped: the two cloths move alike, 10 m apart.
  ClothDesc d;
  d.nx = d.ny = 8;
  d.size = {0.4, 0.4};
  d.origin = {-0.2, -0.15, 0.5};
  for (std::uint32_t i = 0; i < 8; ++i)
    d.pins.push_back({i, 7});
  auto cloth = make_cloth(d);
  REQUIRE(cloth.ok());
  const Collider capsule = Collider::capsule({0, 0, 0.5}, {0, 0, 1.0}, 0.1);
  auto body = capsule.with_keyframes({{0.0, {}, {}}, {0.5, {0.5, 0, 0}, {}}, {0.6, {10.5, 0, 0}, {}, true}});
  auto twin = capsule.with_keyframes({{0.0, {}, {}}, {0.5, {0.5, 0, 0}, {}}});
  REQUIRE(body.ok());
  REQUIRE(twin.ok());
  std::vector<glm::dvec3> rest;
  for (const Particle& q : cloth->particles)
    rest.push_back(q.position);
  std::vector<std::uint32_t> top;
  for (std::uint32_t i = 0; i < 8; ++i)
    top.push_back(56 + i);
  auto attach = Attachment::at_rest(*body, 0, top, rest);
  REQUIRE(attach.ok());
  SimParams p;
  p.dt = 0.005;
  p.substeps = 2;
  p.damping = 2.0; // the swing of the walk's start and stop settles
  p.colliders = {*body};
  p.attachments = {*attach};
  p.inertia.collider = 0;
  ValidationScope validation;
  std::vector<std::vector<glm::dvec3>> ends;
  for (Backend b : backends()) {
    CAPTURE(to_string(b));
    auto s = make_sim(b, *cloth, p);
    SimParams stays = p;
    stays.colliders = {*twin};
    auto t = make_sim(b, *cloth, stays);
    double fastest_after = 0.0, twin_fastest = 0.0, apart = 0.0, velocity_gap = 0.0;
    for (int step = 1; step <= 200; ++step) {
      REQUIRE(s->step().ok());
      REQUIRE(t->step().ok());
      if (step * p.dt <= 0.6)
        continue;
      const auto x = s->positions(), v = s->velocities(), tx = t->positions(), tv = t->velocities();
      for (std::size_t i = 0; i < x.size(); ++i) {
        fastest_after = std::max(fastest_after, glm::length(v[i]));
        twin_fastest = std::max(twin_fastest, glm::length(tv[i]));
        apart = std::max(apart, glm::length(x[i] - tx[i] - glm::dvec3(10, 0, 0)));
        velocity_gap = std::max(velocity_gap, glm::length(v[i] - tv[i]));
      }
    }
    MESSAGE(to_string(b) << ": fastest particle after the jump " << fastest_after << " m/s (its twin "
                         << twin_fastest << " m/s); from the twin " << apart << " m, " << velocity_gap
                         << " m/s");
    CHECK(fastest_after < twin_fastest + 1e-3);
    CHECK(apart < 1e-4);        // float rounding at x = 10 m
    CHECK(velocity_gap < 1e-3); // the jump was not felt
    if (is_float(b))
      ends.push_back(s->positions());
  }
  CHECK(largest_gap(ends) < 1e-5);
}

TEST_CASE("teleport: the host's jump moves and turns the cloth and its velocity, and is not felt") {
  // A weightless cloth gliding at 1 m/s along x is teleported 5 m and turned a quarter about z:
  // after the step it glides along y from the jumped place (CpuSolver::teleport, the GPU's).
  const ParticleSystem cloth = free_cloth({1, 0, 0});
  SimParams p = weightless();
  p.dt = 0.01;
  RigidJump jump;
  jump.pivot = {0, 0, 0};
  jump.translation = {5, 0, 0};
  jump.rotation = glm::dmat3(glm::rotate(glm::dmat4(1.0), std::numbers::pi / 2, glm::dvec3(0, 0, 1)));
  ValidationScope validation;
  std::vector<std::vector<glm::dvec3>> ends;
  for (Backend b : backends()) {
    CAPTURE(to_string(b));
    auto s = make_sim(b, cloth, p);
    REQUIRE(s->teleport(jump).ok());
    REQUIRE(s->step().ok());
    for (std::size_t i = 0; i < cloth.size(); ++i) {
      const glm::dvec3 expected = jump.apply(cloth.particles[i].position) + glm::dvec3(0, 1, 0) * p.dt;
      CHECK(glm::length(s->position(i) - expected) < 1e-5);
      CHECK(glm::length(s->velocity(i) - glm::dvec3(0, 1, 0)) < 1e-5);
    }
    if (is_float(b))
      ends.push_back(s->positions());
  }
  CHECK(largest_gap(ends) < 1e-5);
  RigidJump bad = jump;
  bad.rotation = glm::dmat3(2.0);
  auto s = CpuSolver<float>::create(cloth, p);
  REQUIRE(s.ok());
  auto r = s->teleport(bad);
  REQUIRE_FALSE(r.ok());
  CHECK(r.error().message.find("teleport: rotation must be a rotation matrix") != std::string::npos);
}

TEST_CASE("inertia and teleport: bad input is an error naming the key and the value") {
  const ParticleSystem cloth = free_cloth();
  SimParams p;
  p.colliders = {Collider::sphere({0, 0, 1}, 0.1), Collider::plane({0, 0, 1}, -1.0)};
  const auto message = [&](SimParams q) {
    auto s = CpuSolver<float>::create(cloth, q);
    REQUIRE_FALSE(s.ok());
    return s.error().message;
  };
  SimParams bad = p;
  bad.inertia.collider = 4;
  CHECK(message(bad).find("inertia.collider is 4, but there are 2 colliders") != std::string::npos);
  bad.inertia.collider = 1;
  CHECK(message(bad).find("inertia.collider 1 is a plane") != std::string::npos);
  bad.inertia.collider = 0;
  bad.inertia.linear = 1.5;
  CHECK(message(bad).find("inertia.linear must be in [0, 1], got 1.5") != std::string::npos);
  bad.inertia.linear = 1.0;
  bad.inertia.angular = -0.1;
  CHECK(message(bad).find("inertia.angular must be in [0, 1], got -0.1") != std::string::npos);
  auto first = Collider::sphere({0, 0, 1}, 0.1).with_keyframes({{0.0, {}, {}, true}});
  REQUIRE_FALSE(first.ok());
  CHECK(first.error().message.find("keyframes[0].teleport") != std::string::npos);
}

TEST_CASE("sample character_cape: the walk, the 180-degree turn in 0.5 s and the 10 m teleport keep the cape "
          "out of the body, on its shoulders, and calm after the jump") {
  // samples/scenes/character_cape.json : a torso and two arms
  // (capsules) walk 1.5 m at 1 m/s, turn 180 degrees in 0.5 s, walk back 0.5 m, stand, and teleport
  // 10 m at t = 4 s; a cotton cape hangs from the torso by its top row (pinned, attached), in the
  // torso's frame. Every step, on the CPU (float): no particle deeper than contact_epsilon in a body
  // capsule; the attached row on its targets; after the jump no particle faster than the
  // character's 1 m/s + 1 m/s; the largest strain over the run at most 10 %.
  auto scene = load_scene_file(std::filesystem::path(VKCLOTH_SCENES_DIR) / "character_cape.json");
  REQUIRE_MESSAGE(scene.ok(), (scene.ok() ? "" : scene.error().message));
  auto s = CpuSolver<float>::create(scene->system, scene->params);
  REQUIRE(s.ok());
  const Attachment& shoulders = scene->params.attachments.at(0);
  const double eps = scene->params.contact_epsilon;
  double deepest = 0.0, off_target = 0.0, fastest_after = 0.0, strain = 0.0;
  for (std::uint64_t step = 1; step <= scene->steps; ++step) {
    REQUIRE(s->step().ok());
    const auto x = s->positions();
    for (std::size_t k = 0; k < 3; ++k) { // torso, arms
      const Collider& c = s->params().colliders[k];
      for (const glm::vec3& p32 : x) {
        const glm::dvec3 p(p32), ab = c.b - c.a;
        const double u = std::clamp(glm::dot(p - c.a, ab) / glm::dot(ab, ab), 0.0, 1.0);
        deepest = std::max(deepest, c.radius - glm::length(p - (c.a + ab * u)));
      }
    }
    const Collider& torso = s->params().colliders[0];
    for (std::size_t i = 0; i < shoulders.particles.size(); ++i)
      off_target =
          std::max(off_target, glm::length(glm::dvec3(x[shoulders.particles[i]]) -
                                           (torso.centre() + torso.rotation * shoulders.offsets[i])));
    if (double(step) * scene->params.dt > 4.0)
      for (const glm::vec3& v : s->velocities())
        fastest_after = std::max(fastest_after, double(glm::length(v)));
    strain = std::max(strain, structural_strain(scene->system, x)->max);
  }
  MESSAGE("deepest in a body capsule " << deepest << " m, shoulders off their targets " << off_target
                                       << " m, fastest after the teleport " << fastest_after
                                       << " m/s, largest strain " << strain);
  CHECK(deepest <= eps);
  CHECK(off_target < 1e-5);
  CHECK(fastest_after < 1.0 + 1.0);
  CHECK(s->positions()[0].x > 9.0); // the cape came along
  // The cape's bound; the scene's 6 substeps of 5 sweeps reach 9.7 % in the turn (1 x 5: 36 %, 2 x 5:
  // 15.5 %, 4 x 5: 11 %; docs/performance.md).
  CHECK(strain <= 0.10);
}
