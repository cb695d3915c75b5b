// SPDX-License-Identifier: MIT
// Cloth (report §3-4): conservation, pins, rest state, collisions, wind, blow-up, the up axis.
// Every test runs on each backend (CPU float, CPU double, Vulkan) with a tolerance stated for float.
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <random>

#include <fmt/format.h>
#include <glm/geometric.hpp>

#include "sim_backends.hpp"
#include "vkcloth/vkcloth.hpp"

using namespace vkcloth;
using namespace vkcloth::test;

namespace {

SimParams no_forces() {
  SimParams p;
  p.gravity = {0, 0, 0};
  p.damping = 0.0;
  return p;
}

/// A single free particle (a 1 x 1 cloth) at `pos` with velocity `vel`.
ParticleSystem particle(glm::dvec3 pos, glm::dvec3 vel) {
  ClothDesc d;
  d.nx = d.ny = 1;
  d.pin_default_corners = false;
  auto sys = grid_cloth(d);
  sys.particles[0].position = pos;
  sys.particles[0].velocity = vel;
  return sys;
}

/// The initial position as the backend stores it (rounded to float on float backends).
glm::dvec3 stored(Backend b, glm::dvec3 p) {
  return is_float(b) ? glm::dvec3(glm::vec3(p)) : p;
}

} // namespace

TEST_CASE("a free cloth without gravity, damping or colliders keeps its total momentum") {
  ValidationScope validation;
  ClothDesc d;
  d.nx = 9;
  d.ny = 7;
  d.pin_default_corners = false;
  auto sys = grid_cloth(d);
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-0.5, 0.5);
  for (Particle& p : sys.particles)
    p.velocity = {u(rng), u(rng), u(rng)};
  for (Backend b : backends()) {
    CAPTURE(to_string(b));
    auto s = make_sim(b, sys, no_forces());
    glm::dvec3 p0{0.0}, p1{0.0};
    const auto v0 = s->velocities();
    for (std::size_t k = 0; k < sys.size(); ++k)
      p0 += sys.particles[k].mass * v0[k];
    REQUIRE(s->run(500).ok());
    const auto v1 = s->velocities();
    for (std::size_t k = 0; k < sys.size(); ++k)
      p1 += sys.particles[k].mass * v1[k];
    const double tol = is_float(b) ? 1e-5 : 1e-13; // float: rounding of 63 x 500 spring sums
    CHECK(std::abs(p1.x - p0.x) < tol);
    CHECK(std::abs(p1.y - p0.y) < tol);
    CHECK(std::abs(p1.z - p0.z) < tol);
    CHECK(glm::length(v1[0] - v0[0]) > 1e-3); // springs did work: the state changed
  }
}

TEST_CASE("pinned points never move (bit-exact) while the hanging cloth falls") {
  ValidationScope validation;
  ClothDesc d;
  d.origin = {-0.5, 0.0, 0.5};
  auto sys = grid_cloth(d);
  for (Backend b : backends()) {
    CAPTURE(to_string(b));
    auto s = make_sim(b, sys, SimParams{});
    REQUIRE(s->run(1000).ok());
    const auto x = s->positions(), v = s->velocities();
    for (std::size_t k = 0; k < sys.size(); ++k)
      if (sys.particles[k].pinned) {
        CHECK(x[k] == stored(b, sys.particles[k].position));
        CHECK(v[k] == glm::dvec3(0.0));
      }
    CHECK(x[0].z < 0.5 - 0.1); // ...and the rest did fall: the bottom row sank well below its start
  }
}

TEST_CASE("a cloth at rest in its rest shape with no gravity stays there") {
  ValidationScope validation;
  ClothDesc d;
  d.nx = 12;
  d.ny = 8;
  d.size = {1.3, 0.7};
  auto sys = grid_cloth(d);
  for (Backend b : backends()) {
    CAPTURE(to_string(b));
    auto s = make_sim(b, sys, no_forces());
    REQUIRE(s->run(1000).ok());
    const auto x = s->positions();
    // float: rest lengths and spacings round differently, leaving forces of K * 1e-8 that,
    // undamped, move the particles by about 1e-6 over 1000 steps.
    const double tol = is_float(b) ? 1e-5 : 1e-12;
    for (std::size_t k = 0; k < sys.size(); ++k)
      CHECK(glm::length(x[k] - sys.particles[k].position) < tol);
  }
}

TEST_CASE("the hanging cloth settles: kinetic energy decays, no NaN (report defaults 40 / 8 / 8, dt 0.02)") {
  ValidationScope validation;
  ClothDesc d;
  d.origin = {-0.5, 0.0, 0.5};
  auto sys = grid_cloth(d);
  const auto kinetic = [&](Sim& s) {
    double e = 0;
    for (const glm::dvec3& v : s.velocities())
      e += 0.5 * d.particle_mass * glm::dot(v, v);
    return e;
  };
  for (Backend b : backends()) {
    CAPTURE(to_string(b));
    auto s = make_sim(b, sys, SimParams{});
    REQUIRE(s->run(200).ok());
    const double ke_early = kinetic(*s);
    REQUIRE(s->run(3000).ok());
    CHECK(kinetic(*s) < 1e-6 * ke_early);
  }
}

TEST_CASE("structural springs alone diverge past K_struct ~ 50 at dt = 0.02 (report §3, Figure 7)") {
  ValidationScope validation;
  for (Backend b : backends())
    for (double k : {40.0, 80.0}) {
      CAPTURE(to_string(b));
      CAPTURE(k);
      ClothDesc d;
      d.origin = {-0.5, 0.0, 0.5};
      d.stiffness = {k, 0.0, 0.0};
      auto s = make_sim(b, grid_cloth(d), SimParams{});
      auto r = s->run(3000);
      CHECK(r.ok() == (k < 50.0));
      if (!r.ok())
        CHECK(r.error().code == ErrorCode::diverged);
    }
}

TEST_CASE("plane and sphere collisions: no particle ends inside a collider") {
  // A frictionless sphere cannot hold a cloth (it slides off, an unstable balance), so the cloth
  // meets the sphere and then the floor: both contacts are exercised.
  ValidationScope validation;
  ClothDesc d;
  d.nx = d.ny = 15;
  d.orientation = ClothOrientation::horizontal;
  d.origin = {-0.5, -0.5, 1.0};
  d.pin_default_corners = false;
  SimParams p;
  p.colliders = {Collider::plane({0, 0, 1}, 0.0), Collider::sphere({0.05, 0, 0.6}, 0.3)};
  const glm::dvec3 centre{0.05, 0, 0.6};
  for (Backend b : backends()) {
    CAPTURE(to_string(b));
    auto s = make_sim(b, grid_cloth(d), p);
    double min_plane = 1e9, min_sphere = 1e9;
    int sphere_contacts = 0;
    for (int block = 0; block < 120; ++block) {
      REQUIRE(s->run(5).ok());
      for (const glm::dvec3& x : s->positions()) {
        const double ds = glm::length(x - centre) - 0.3;
        min_plane = std::min(min_plane, x.z);
        min_sphere = std::min(min_sphere, ds);
        sphere_contacts += ds < 2e-3;
      }
    }
    CHECK(min_plane >= 0.0);
    CHECK(min_sphere >= -1e-6); // float rounding of the projection onto r + eps
    CHECK(sphere_contacts > 20);
    double max_z = 0;
    for (const glm::dvec3& x : s->positions())
      max_z = std::max(max_z, x.z);
    CHECK(max_z < 0.05); // slid off the sphere and lies on the floor
  }
}

TEST_CASE("contact keeps the tangential velocity and removes only the inward normal part") {
  ValidationScope validation;
  SimParams p = no_forces();
  p.colliders = {Collider::plane({0, 0, 1}, 0.0)};
  for (Backend b : backends()) {
    CAPTURE(to_string(b));
    auto s = make_sim(b, particle({0, 0, 0.0005}, {1.0, 0.5, -2.0}), p);
    REQUIRE(s->step().ok());
    const glm::dvec3 v = s->velocity(0);
    CHECK(v.x == 1.0);
    CHECK(v.y == 0.5);
    CHECK(v.z == 0.0);
    CHECK(s->position(0).z >= 0.0);
  }
}

TEST_CASE(
    "an outward velocity or force is not cancelled by a contact (the hand lifting the cloth, Figure 12)") {
  ValidationScope validation;
  for (Backend b : backends()) {
    CAPTURE(to_string(b));
    const double tol = is_float(b) ? 1e-6 : 1e-12;
    SimParams p = no_forces();
    p.colliders = {Collider::plane({0, 0, 1}, 0.0)};
    {
      INFO("outward velocity: the particle leaves the floor");
      auto s = make_sim(b, particle({0, 0, 0.001}, {0, 0, 1.0}), p);
      REQUIRE(s->run(10).ok());
      CHECK(s->velocity(0).z == 1.0);
      CHECK(std::abs(s->position(0).z - (0.001 + 10 * 0.02 * 1.0)) < tol);
    }
    {
      INFO("outward force (gravity pointing up): the particle accelerates away");
      p.gravity = {0, 0, 9.81};
      auto s = make_sim(b, particle({0, 0, 0.001}, {0, 0, 0}), p);
      REQUIRE(s->step().ok());
      CHECK(std::abs(s->velocity(0).z - 9.81 * 0.02) < tol);
    }
    {
      INFO("inward force on a resting particle is removed: it stays on the floor");
      p.gravity = {0, 0, -9.81};
      auto s = make_sim(b, particle({0, 0, 0.001}, {0, 0, 0}), p);
      REQUIRE(s->run(100).ok());
      CHECK(std::abs(s->position(0).z - 0.001) < tol);
      CHECK(s->velocity(0).z == 0.0);
    }
    {
      INFO("on the side of a sphere gravity's tangential part makes the particle slide, not stick");
      p.colliders = {Collider::sphere({0, 0, 0}, 1.0)};
      const glm::dvec3 start = glm::normalize(glm::dvec3{1, 0, 1}) * 1.001;
      auto s = make_sim(b, particle(start, {0, 0, 0}), p);
      REQUIRE(s->run(10).ok());
      const glm::dvec3 x = s->position(0);
      CHECK(x.z < start.z - 1e-3);         // slid down...
      CHECK(x.x > start.x);                // ...around the sphere
      CHECK(glm::length(x) >= 1.0 - 1e-7); // and stayed outside (float: r + eps rounded)
    }
  }
}

TEST_CASE(
    "contact_inward_only = false (Figure 12's variant) also cancels outward parts: the particle sticks") {
  ValidationScope validation;
  for (Backend b : backends()) {
    CAPTURE(to_string(b));
    SimParams p = no_forces();
    p.colliders = {Collider::plane({0, 0, 1}, 0.0)};
    p.contact_inward_only = false;
    auto s = make_sim(b, particle({0, 0, 0.001}, {0.5, 0, 1.0}), p);
    REQUIRE(s->run(10).ok());
    CHECK(s->velocity(0).z == 0.0); // the outward velocity was removed...
    CHECK(s->velocity(0).x == 0.5); // ...the tangential part kept
    CHECK(std::abs(s->position(0).z - 0.001) < 1e-7);
  }
}

TEST_CASE("wind F = Kw <n, u> n: zero when the wind lies in the cloth plane, along the normal otherwise") {
  ValidationScope validation;
  ClothDesc d;
  d.nx = 5;
  d.ny = 4;
  d.pin_default_corners = false; // vertical cloth in the x-z plane: normal +-y
  for (Backend b : backends()) {
    CAPTURE(to_string(b));
    // float: the cloth's rest spacing rounds, leaving spring forces of about K * 1e-8.
    const double tol = is_float(b) ? 1e-5 : 1e-12;
    SimParams p = no_forces();
    p.wind = {0.05, {1, 0, 1}};
    auto in_plane = make_sim(b, grid_cloth(d), p);
    REQUIRE(in_plane->step().ok());
    for (const glm::dvec3& f : in_plane->forces())
      CHECK(glm::length(f) < tol);

    p.wind = {0.05, {1, 1, 0}}; // normalised to (1, 1, 0)/sqrt 2: <n, u> = -+1/sqrt 2
    auto across = make_sim(b, grid_cloth(d), p);
    REQUIRE(across->step().ok());
    const auto forces = across->forces(), normals = across->normals();
    for (std::size_t k = 0; k < forces.size(); ++k) {
      CHECK(std::abs(std::abs(normals[k].y) - 1.0) < tol);
      CHECK(std::abs(forces[k].x) < tol);
      CHECK(std::abs(forces[k].z) < tol);
      CHECK(std::abs(forces[k].y - 0.05 / std::sqrt(2.0)) < tol); // along the wind's normal part
    }
  }
}

TEST_CASE("a blow-up is reported with the step and time, and runs are bit-identical") {
  ValidationScope validation;
  ClothDesc d;
  d.origin = {-0.5, 0.0, 0.5};
  for (Backend b : backends()) {
    CAPTURE(to_string(b));
    d.stiffness.structural = 200.0;
    auto s = make_sim(b, grid_cloth(d), SimParams{});
    auto r = s->run(1000);
    REQUIRE_FALSE(r.ok());
    CHECK(r.error().code == ErrorCode::diverged);
    CHECK(r.error().message.find("at step ") != std::string::npos);
    CHECK(r.error().message.find("t = ") != std::string::npos);

    d.stiffness.structural = 40.0;
    SimParams p;
    p.wind = {0.05, {0, 1, 0}};
    p.integrator = Integrator::rk4;
    auto first = make_sim(b, grid_cloth(d), p);
    auto second = make_sim(b, grid_cloth(d), p);
    REQUIRE(first->run(300).ok());
    REQUIRE(second->run(300).ok());
    CHECK(first->positions() == second->positions());
  }
}

TEST_CASE("a blow-up at a step under a microsecond advises a longer step, not a shorter one") {
  // vbd's m / h^2 overflows float at dt = 1e-12: NaN at the first step, on every float backend.
  ClothDesc d;
  d.nx = d.ny = 4;
  SimParams p;
  p.integrator = Integrator::vbd;
  p.dt = 1e-12;
  for (Backend b : float_backends()) {
    CAPTURE(to_string(b));
    ValidationScope validation;
    auto s = make_sim(b, grid_cloth(d), p);
    auto r = s->run(2);
    REQUIRE_FALSE(r.ok());
    CHECK(r.error().code == ErrorCode::diverged);
    CHECK(r.error().message.find("integrator.dt = 1e-12 s is under a microsecond") != std::string::npos);
    CHECK(r.error().message.find("smaller integrator.dt") == std::string::npos);
  }
}

TEST_CASE("a free particle's mass below float's smallest normal: the float solvers refuse it, naming it") {
  // It rounds to zero (or a denormal) in float and the first step divided by it: a NaN reported as
  // a divergence, with the advice to shorten dt. The double solver takes it.
  ClothDesc d;
  d.nx = d.ny = 3;
  ParticleSystem s = grid_cloth(d);
  s.particles[4].mass = 1e-46;
  auto cpu = CpuSolver<float>::create(s, SimParams{});
  REQUIRE_FALSE(cpu.ok());
  CHECK(cpu.error().code == ErrorCode::invalid_argument);
  CHECK(cpu.error().message.find("particle 4 has mass 1e-46 kg, below float's smallest normal") !=
        std::string::npos);
  CHECK(CpuSolver<double>::create(s, SimParams{}).ok());
  s.particles[4].mass = 2e-38; // normal in float: taken
  CHECK(CpuSolver<float>::create(s, SimParams{}).ok());
  s.particles[4].mass = 1e-46;
  auto& shared = gpu::test::shared_context();
  if (!shared.context) {
    backends(); // fails on CI without a device, else says the Vulkan backend is left out
    return;
  }
  auto g = gpu::GpuSolver::create(*shared.context, s, SimParams{});
  REQUIRE_FALSE(g.ok());
  CHECK(g.error().message.find("particle 4 has mass 1e-46 kg") != std::string::npos);
}

TEST_CASE("up axis y: the y-up sheet drapes as the z-up one, turned by z_up_to(y), within 1e-6 m") {
  const glm::dmat3 turn = z_up_to(UpAxis::y);
  CHECK(turn * glm::dvec3(1, 2, 3) == glm::dvec3(1, 3, -2)); // (x, y, z) -> (x, z, -y)
  CHECK(up_vector(UpAxis::y) == glm::dvec3(0, 1, 0));
  CHECK(default_gravity(UpAxis::y) == glm::dvec3(0, -9.81, 0));
  CHECK(default_gravity(UpAxis::z) == SimParams{}.gravity);

  for (ClothOrientation orientation : {ClothOrientation::horizontal, ClothOrientation::vertical}) {
    CAPTURE(int(orientation));
    const bool flat = orientation == ClothOrientation::horizontal;
    ClothDesc z_desc;
    z_desc.nx = 13;
    z_desc.ny = 11;
    z_desc.orientation = orientation;
    z_desc.origin = flat ? glm::dvec3(-0.5, -0.45, 0.4) : glm::dvec3(-0.5, -0.1, 0.0);
    z_desc.pin_default_corners = !flat; // the flat sheet falls on a sphere, the other hangs
    SimParams z_params;
    Collider sphere = Collider::sphere({0.05, 0.02, 0.15}, 0.2);
    sphere.friction = 0.4;
    z_params.colliders = {Collider::plane({0, 0, 1}, 0.0), sphere};
    z_params.wind.strength = 0.03;
    z_params.wind.direction = {0.3, 1.0, 0.1};

    ClothDesc y_desc = z_desc; // the same scene in a y-up host's coordinates
    y_desc.up = UpAxis::y;
    y_desc.origin = turn * z_desc.origin;
    SimParams y_params = z_params;
    y_params.gravity = default_gravity(UpAxis::y);
    y_params.colliders[0] = Collider::plane(up_vector(UpAxis::y), 0.0);
    y_params.colliders[1].center = turn * sphere.center;
    y_params.wind.direction = turn * z_params.wind.direction;

    const ParticleSystem z_sys = make_cloth(z_desc).value();
    const ParticleSystem y_sys = make_cloth(y_desc).value();
    for (std::size_t p = 0; p < z_sys.size(); ++p)
      REQUIRE(glm::length(y_sys.particles[p].position - turn * z_sys.particles[p].position) < 1e-15);
    auto z_run = CpuSolver<double>::create(z_sys, z_params);
    auto y_run = CpuSolver<double>::create(y_sys, y_params);
    REQUIRE((z_run && y_run));
    REQUIRE(z_run->run(150));
    REQUIRE(y_run->run(150));
    double worst = 0.0, moved = 0.0;
    for (std::size_t p = 0; p < z_sys.size(); ++p) {
      worst = std::max(worst, glm::length(y_run->positions()[p] - turn * z_run->positions()[p]));
      moved = std::max(moved, glm::length(z_run->positions()[p] - z_sys.particles[p].position));
      // Normals turn with the sheet: a horizontal one's point up in both frames.
      CHECK(glm::length(y_run->normals()[p] - turn * z_run->normals()[p]) < 1e-6);
    }
    MESSAGE("y up vs z up, turned: max |dp| = " << worst << " m after 150 steps (cloth moved " << moved
                                                << " m)");
    CHECK(worst <= 1e-6);
    CHECK(moved > 0.1);
    if (flat)
      CHECK(glm::dot(glm::dvec3(y_run->normals()[z_desc.nx / 2]), up_vector(UpAxis::y)) > 0.0);
  }

  // Bad values name themselves.
  ClothDesc bad;
  bad.up = UpAxis(7);
  auto r = make_cloth(bad);
  REQUIRE_FALSE(r.ok());
  CHECK_MESSAGE(r.error().message.find("cloth.up: unknown up axis 7") != std::string::npos,
                r.error().message);
  ChainDesc chain;
  chain.up = UpAxis(2);
  auto c = make_chain(chain);
  REQUIRE_FALSE(c.ok());
  CHECK_MESSAGE(c.error().message.find("chain.up: unknown up axis 2") != std::string::npos,
                c.error().message);
  CHECK(parse_up_axis("y") == UpAxis::y);
  CHECK(parse_up_axis("Y") == std::nullopt);
  // A chain without positions hangs along -up.
  chain.up = UpAxis::y;
  chain.positions.clear();
  const ParticleSystem hung = make_chain(chain).value();
  CHECK(hung.particles[1].position == glm::dvec3(0.0, -0.4, 0.0));
}
