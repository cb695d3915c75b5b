// SPDX-License-Identifier: MIT
// Attachments and motion constraints (docs/model.md "Attachments"):
// pinned particles that follow a collider's frame or the host's targets, free particles held
// within reach of theirs, on every backend (CPU float, CPU double, Vulkan with validation).
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>

#include <glm/geometric.hpp>
#include <glm/gtc/matrix_transform.hpp>

#include "sim_backends.hpp"

using namespace vkcloth;
using namespace vkcloth::test;

namespace {

/// A vertical nx x nx cloth, 0.5 m wide, its top row (z = 0.5) pinned.
ParticleSystem hanging_cloth(std::uint32_t nx) {
  ClothDesc d;
  d.nx = d.ny = nx;
  d.size = {0.5, 0.5};
  d.origin = {-0.25, 0.0, 0.0};
  for (std::uint32_t i = 0; i < nx; ++i)
    d.pins.push_back({i, nx - 1});
  auto sys = make_cloth(d);
  REQUIRE(sys.ok());
  return *sys;
}

std::vector<glm::dvec3> rest_positions(const ParticleSystem& sys) {
  std::vector<glm::dvec3> x;
  for (const Particle& p : sys.particles)
    x.push_back(p.position);
  return x;
}

/// The point `offset` of `c`'s frame.
glm::dvec3 in_frame(const Collider& c, glm::dvec3 offset) {
  return c.centre() + c.rotation * offset;
}

} // namespace

TEST_CASE(
    "attachment: a pinned row follows a keyframed, turning capsule to 1e-5 m at every step, GPU = CPU") {
  // The capsule moves 0.5 m and turns 90 degrees in 0.5 s, then rises and turns on to 180 degrees;
  // the cloth's pinned top row keeps its rest offset in the capsule's frame.
  ValidationScope validation;
  const ParticleSystem cloth = hanging_cloth(10);
  auto rod = Collider::capsule({-0.3, 0, 0.6}, {0.3, 0, 0.6}, 0.05)
                 .with_keyframes({{0.0, {0, 0, 0}, {0, 0, 0}},
                                  {0.5, {0.5, 0, 0}, {0, 0, 90}},
                                  {1.0, {0.5, 0.5, 0.2}, {0, 0, 180}}});
  REQUIRE(rod.ok());
  std::vector<std::uint32_t> top;
  for (std::uint32_t i = 0; i < 10; ++i)
    top.push_back(90 + i);
  auto attach = Attachment::at_rest(*rod, 0, top, rest_positions(cloth));
  REQUIRE(attach.ok());
  for (Integrator method : {Integrator::semi_implicit_euler, Integrator::vbd}) {
    CAPTURE(to_string(method));
    SimParams p;
    p.integrator = method;
    p.dt = 0.005;
    p.substeps = 2;
    p.colliders = {*rod};
    p.attachments = {*attach};
    std::vector<std::vector<glm::dvec3>> ends;
    for (Backend b : backends()) {
      CAPTURE(to_string(b));
      auto s = make_sim(b, cloth, p);
      double worst = 0.0;
      for (int step = 1; step <= 240; ++step) {
        REQUIRE(s->step().ok());
        const Collider now = rod->path->at(step * p.dt);
        const auto x = s->positions();
        for (std::size_t i = 0; i < top.size(); ++i)
          worst = std::max(worst, glm::length(x[top[i]] - in_frame(now, attach->offsets[i])));
      }
      CHECK(worst < 1e-5);
      // The row turned 180 degrees: its first particle is now on the other side.
      CHECK(s->position(90).x == doctest::Approx(0.5 + 0.25).epsilon(1e-4));
      if (is_float(b))
        ends.push_back(s->positions());
    }
    const double gap = largest_gap(ends);
    MESSAGE("largest difference between backends: " << gap << " m");
    CHECK(gap < 1e-5);
  }
}

TEST_CASE("motion constraint: free particles held within max_distance of a spinning sphere's frame, "
          "released, they fall") {
  // Two corners of a free horizontal cloth attached at distance 0, the opposite edge's middle within
  // 0.05 m, to a sphere high above that moves at 0.5 m/s and spins at 1 rad/s.
  ValidationScope validation;
  ClothDesc d;
  d.nx = d.ny = 8;
  d.size = {0.4, 0.4};
  d.origin = {-0.2, -0.2, 0.0};
  d.orientation = ClothOrientation::horizontal;
  d.pin_default_corners = false;
  auto cloth = make_cloth(d);
  REQUIRE(cloth.ok());
  Collider ball = Collider::sphere({0, 0, 1}, 0.1);
  ball.linear_velocity = {0.5, 0, 0};
  ball.angular_velocity = {0, 0, 1};
  const auto rest = rest_positions(*cloth);
  auto held = Attachment::at_rest(ball, 0, {0, 7}, rest, 0.0);
  auto loose = Attachment::at_rest(ball, 0, {60}, rest, 0.05);
  REQUIRE(held.ok());
  REQUIRE(loose.ok());
  SimParams p;
  p.dt = 0.005;
  p.colliders = {ball};
  p.attachments = {*held, *loose};
  std::vector<std::vector<glm::dvec3>> ends;
  for (Backend b : backends()) {
    CAPTURE(to_string(b));
    auto s = make_sim(b, *cloth, p);
    double on_target = 0.0, past_reach = 0.0, velocity_gap = 0.0;
    for (int step = 1; step <= 100; ++step) {
      REQUIRE(s->step().ok());
      const double t = step * p.dt;
      Collider now = ball;
      now.center = ball.center + ball.linear_velocity * t;
      now.rotation = glm::dmat3(glm::rotate(glm::dmat4(1.0), t, glm::dvec3(0, 0, 1)));
      const auto x = s->positions();
      const auto v = s->velocities();
      for (std::size_t i = 0; i < 2; ++i) {
        const glm::dvec3 target = in_frame(now, held->offsets[i]);
        on_target = std::max(on_target, glm::length(x[held->particles[i]] - target));
        const glm::dvec3 target_v =
            ball.linear_velocity + glm::cross(ball.angular_velocity, target - now.center);
        velocity_gap = std::max(velocity_gap, glm::length(v[held->particles[i]] - target_v));
      }
      past_reach = std::max(past_reach, glm::length(x[60] - in_frame(now, loose->offsets[0])) - 0.05);
    }
    CHECK(on_target < 1e-5);
    CHECK(velocity_gap < 1e-4);
    CHECK(past_reach < 1e-6);
    if (is_float(b))
      ends.push_back(s->positions());
    // Released (the attachments left out): the corners fall freely from where they were.
    const double z0 = s->position(0).z;
    SimParams released = p;
    released.attachments.clear();
    REQUIRE(s->set_params(released).ok());
    REQUIRE(s->run(20).ok());
    CHECK(s->position(0).z < z0 - 0.01);
  }
  CHECK(largest_gap(ends) < 1e-5);
}

TEST_CASE("host pin targets: reached at the step's end, interpolated across its substeps, then held") {
  // A pinned corner first given its own position as target (a new target is reached at once),
  // then one 0.1 m away: after one step of 4 substeps it is there, moving at 0.1 / dt, the same as 4
  // steps of dt / 4 given the quarter targets; a step later it is held still.
  ValidationScope validation;
  const ParticleSystem cloth = hanging_cloth(6);
  const std::uint32_t corner = 30; // (0, ny - 1)
  const glm::dvec3 from = cloth.particles[corner].position, to = from + glm::dvec3(0.1, 0, 0);
  SimParams p;
  p.dt = 0.01;
  p.substeps = 4;
  const PinTarget start{corner, from, 0.0}, target{corner, to, 0.0};
  std::vector<std::vector<glm::dvec3>> ends;
  for (Backend b : backends()) {
    CAPTURE(to_string(b));
    auto s = make_sim(b, cloth, p);
    REQUIRE(s->set_pin_targets({&start, 1}).ok());
    REQUIRE(s->step().ok());
    CHECK(glm::length(s->velocity(corner)) == 0.0);
    REQUIRE(s->set_pin_targets({&target, 1}).ok());
    REQUIRE(s->step().ok());
    CHECK(glm::length(s->position(corner) - to) < 1e-6);
    CHECK(s->velocity(corner).x == doctest::Approx(0.1 / p.dt).epsilon(1e-5));
    if (is_float(b))
      ends.push_back(s->positions());
    REQUIRE(s->step().ok());
    CHECK(glm::length(s->position(corner) - to) < 1e-6);
    CHECK(glm::length(s->velocity(corner)) < 1e-6);
  }
  CHECK(largest_gap(ends) < 1e-5);
  // The substeps' targets: the same as quarter steps given the quarter points.
  SimParams quarter = p;
  quarter.dt = p.dt / 4;
  quarter.substeps = 1;
  auto whole = CpuSolver<double>::create(cloth, p);
  auto parts = CpuSolver<double>::create(cloth, quarter);
  REQUIRE(whole.ok());
  REQUIRE(parts.ok());
  REQUIRE(whole->set_pin_targets({&start, 1}).ok());
  REQUIRE(parts->set_pin_targets({&start, 1}).ok());
  REQUIRE(whole->step().ok());
  for (int k = 0; k < 4; ++k)
    REQUIRE(parts->step().ok());
  REQUIRE(whole->set_pin_targets({&target, 1}).ok());
  REQUIRE(whole->step().ok());
  for (int k = 1; k <= 4; ++k) {
    const PinTarget q{corner, from + (to - from) * (k / 4.0), 0.0};
    REQUIRE(parts->set_pin_targets({&q, 1}).ok());
    REQUIRE(parts->step().ok());
  }
  double gap = 0.0;
  for (std::size_t i = 0; i < cloth.size(); ++i)
    gap = std::max(gap, glm::length(whole->positions()[i] - parts->positions()[i]));
  CHECK(gap < 1e-12);
}

TEST_CASE("attachments and pin targets: bad input is an error naming the entry and the value") {
  const ParticleSystem cloth = hanging_cloth(4);
  const auto rest = rest_positions(cloth);
  SimParams p;
  p.colliders = {Collider::sphere({0, 0, 1}, 0.1), Collider::plane({0, 0, 1}, 0.0)};
  const auto message = [&](SimParams q) {
    auto s = CpuSolver<float>::create(cloth, q);
    REQUIRE_FALSE(s.ok());
    return s.error().message;
  };
  auto a = Attachment::at_rest(p.colliders[0], 0, {12, 13}, rest);
  REQUIRE(a.ok());
  SimParams bad = p;
  bad.attachments = {*a, *a};
  CHECK(message(bad).find("attachments[1].particles[0] is particle 12, which attachments[0].particles[0]") !=
        std::string::npos);
  bad.attachments = {*a};
  bad.attachments[0].particles[1] = 16;
  CHECK(message(bad).find("attachments[0].particles[1] is particle 16, past the cloth's 16 particles") !=
        std::string::npos);
  bad.attachments = {*a};
  bad.attachments[0].collider = 5;
  CHECK(message(bad).find("attachments[0].collider is 5, but there are 2 colliders") != std::string::npos);
  bad.attachments[0].collider = 1;
  CHECK(message(bad).find("attachments[0].collider 1 is a plane") != std::string::npos);
  bad.attachments = {*a};
  bad.attachments[0].offsets.pop_back();
  CHECK(message(bad).find("attachments[0] has 2 particles but 1 offsets") != std::string::npos);
  bad.attachments = {*a};
  bad.attachments[0].max_distance = -1.0;
  CHECK(message(bad).find("attachments[0].max_distance must be finite and >= 0, got -1") !=
        std::string::npos);
  CHECK_FALSE(Attachment::at_rest(p.colliders[1], 1, {0}, rest).ok());
  CHECK_FALSE(Attachment::at_rest(p.colliders[0], 0, {99}, rest).ok());

  p.attachments = {*a};
  auto s = CpuSolver<float>::create(cloth, p);
  REQUIRE(s.ok());
  const PinTarget twice[] = {{3, {0, 0, 0}, 0.0}, {3, {0, 0, 0}, 0.0}};
  auto r = s->set_pin_targets(twice);
  REQUIRE_FALSE(r.ok());
  CHECK(r.error().message.find("pin target 1 is particle 3, which pin target 0 targets already") !=
        std::string::npos);
  const PinTarget attached[] = {{13, {0, 0, 0}, 0.0}};
  r = s->set_pin_targets(attached);
  REQUIRE_FALSE(r.ok());
  CHECK(r.error().message.find("attachments[0].particles[1]") != std::string::npos);
  const PinTarget far[] = {{3, {0, 0, 0}, -0.5}};
  CHECK_FALSE(s->set_pin_targets(far).ok());
  const PinTarget nan[] = {{3, {std::nan(""), 0, 0}, 0.0}};
  CHECK_FALSE(s->set_pin_targets(nan).ok());
  // A host target first, then parameters that attach the same particle: refused, the old kept.
  const PinTarget three[] = {{3, {0, 0, 0.5}, 0.0}};
  REQUIRE(s->set_pin_targets(three).ok());
  SimParams clash = p;
  auto b = Attachment::at_rest(p.colliders[0], 0, {3}, rest);
  REQUIRE(b.ok());
  clash.attachments.push_back(*b);
  CHECK_FALSE(s->set_params(clash).ok());
  CHECK(s->params().attachments.size() == 1);
}
