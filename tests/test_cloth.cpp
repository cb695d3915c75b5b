// Cloth (report §3-4): conservation, pins, rest state, collisions, wind, blow-up, determinism.
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>

#include <glm/geometric.hpp>
#include <random>

#include "vkcloth/vkcloth.hpp"

using namespace vkcloth;

namespace {

ParticleSystem cloth(ClothDesc d) {
  auto sys = make_cloth(d);
  REQUIRE(sys.ok());
  return *sys;
}

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
  auto sys = cloth(d);
  sys.particles[0].position = pos;
  sys.particles[0].velocity = vel;
  return sys;
}

} // namespace

TEST_CASE_TEMPLATE("a free cloth without gravity, damping or colliders keeps its total momentum", Real, float, double) {
  ClothDesc d;
  d.nx = 9;
  d.ny = 7;
  d.pin_default_corners = false;
  auto sys = cloth(d);
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-0.5, 0.5);
  glm::dvec3 p0{0.0};
  for (Particle& p : sys.particles) {
    p.velocity = {u(rng), u(rng), u(rng)};
    p0 += p.mass * p.velocity;
  }
  auto s = CpuSolver<Real>::create(sys, no_forces());
  REQUIRE(s.ok());
  REQUIRE(s->run(500).ok());
  glm::dvec3 p1{0.0};
  for (std::size_t k = 0; k < sys.size(); ++k) p1 += sys.particles[k].mass * glm::dvec3(s->velocities()[k]);
  const double tol = std::is_same_v<Real, float> ? 1e-5 : 1e-13;
  CHECK(std::abs(p1.x - p0.x) < tol);
  CHECK(std::abs(p1.y - p0.y) < tol);
  CHECK(std::abs(p1.z - p0.z) < tol);
  // Springs did work: the state actually changed.
  CHECK(glm::length(glm::dvec3(s->velocities()[0]) - sys.particles[0].velocity) > 1e-3);
}

TEST_CASE("pinned points never move (bit-exact) while the hanging cloth falls") {
  ClothDesc d;
  d.origin = {-0.5, 0.0, 0.5};
  auto sys = cloth(d);
  auto s = CpuSolver<float>::create(sys, SimParams{});
  REQUIRE(s.ok());
  REQUIRE(s->run(1000).ok());
  for (std::size_t k = 0; k < sys.size(); ++k)
    if (sys.particles[k].pinned) {
      CHECK(s->positions()[k] == glm::vec3(sys.particles[k].position));
      CHECK(s->velocities()[k] == glm::vec3(0.0f));
    }
  // ...and the rest did fall: the bottom row sank well below its start.
  CHECK(s->positions()[0].z < 0.5f - 0.1f);
}

TEST_CASE("a cloth at rest in its rest shape with no gravity stays there") {
  ClothDesc d;
  d.nx = 12;
  d.ny = 8;
  d.size = {1.3, 0.7};
  auto sys = cloth(d);
  auto s = CpuSolver<double>::create(sys, no_forces());
  REQUIRE(s.ok());
  REQUIRE(s->run(1000).ok());
  for (std::size_t k = 0; k < sys.size(); ++k) CHECK(glm::length(glm::dvec3(s->positions()[k]) - sys.particles[k].position) < 1e-12);
}

TEST_CASE("the hanging cloth settles: kinetic energy decays, no NaN (report defaults 40 / 8 / 8, dt 0.02)") {
  ClothDesc d;
  d.origin = {-0.5, 0.0, 0.5};
  auto s = CpuSolver<float>::create(cloth(d), SimParams{});
  REQUIRE(s.ok());
  REQUIRE(s->run(200).ok());
  const double ke_early = s->energy().kinetic;
  REQUIRE(s->run(3000).ok());
  CHECK(s->energy().kinetic < 1e-6 * ke_early);
}

TEST_CASE("structural springs alone diverge past K_struct ~ 50 at dt = 0.02 (report §3, Figure 7)") {
  for (double k : {40.0, 80.0}) {
    ClothDesc d;
    d.origin = {-0.5, 0.0, 0.5};
    d.stiffness = {k, 0.0, 0.0};
    auto s = CpuSolver<float>::create(cloth(d), SimParams{});
    auto r = s->run(3000);
    CAPTURE(k);
    CHECK(r.ok() == (k < 50.0));
    if (!r.ok()) CHECK(r.error().code == ErrorCode::diverged);
  }
}

TEST_CASE("plane and sphere collisions: no particle ends inside a collider") {
  // A frictionless sphere cannot hold a cloth (it slides off, an unstable balance), so the cloth
  // meets the sphere and then the floor: both contacts are exercised.
  ClothDesc d;
  d.nx = d.ny = 15;
  d.orientation = ClothOrientation::horizontal;
  d.origin = {-0.5, -0.5, 1.0};
  d.pin_default_corners = false;
  SimParams p;
  p.colliders = {Collider::plane({0, 0, 1}, 0.0), Collider::sphere({0.05, 0, 0.6}, 0.3)};
  auto s = CpuSolver<float>::create(cloth(d), p);
  REQUIRE(s.ok());
  float min_plane = 1e9f, min_sphere = 1e9f;
  int sphere_contacts = 0;
  for (int step = 0; step < 600; ++step) {
    REQUIRE(s->step().ok());
    for (const glm::vec3& x : s->positions()) {
      const float ds = glm::length(x - glm::vec3(0.05f, 0, 0.6f)) - 0.3f;
      min_plane = std::min(min_plane, x.z);
      min_sphere = std::min(min_sphere, ds);
      sphere_contacts += ds < 2e-3f;
    }
  }
  CHECK(min_plane >= 0.0f);
  CHECK(min_sphere >= -1e-6f); // float rounding of the projection onto r + eps
  CHECK(sphere_contacts > 100);
  float max_z = 0;
  for (const glm::vec3& x : s->positions()) max_z = std::max(max_z, x.z);
  CHECK(max_z < 0.05f); // slid off the sphere and lies on the floor
}

TEST_CASE("contact keeps the tangential velocity and removes only the inward normal part") {
  SimParams p = no_forces();
  p.colliders = {Collider::plane({0, 0, 1}, 0.0)};
  auto s = CpuSolver<double>::create(particle({0, 0, 0.0005}, {1.0, 0.5, -2.0}), p);
  REQUIRE(s.ok());
  REQUIRE(s->step().ok());
  CHECK(s->velocities()[0].x == 1.0);
  CHECK(s->velocities()[0].y == 0.5);
  CHECK(s->velocities()[0].z == 0.0);
  CHECK(s->positions()[0].z >= 0.0);
}

TEST_CASE("an outward velocity or force is not cancelled by a contact (the hand lifting the cloth, Figure 12)") {
  SimParams p = no_forces();
  p.colliders = {Collider::plane({0, 0, 1}, 0.0)};
  SUBCASE("outward velocity: the particle leaves the floor") {
    auto s = CpuSolver<double>::create(particle({0, 0, 0.001}, {0, 0, 1.0}), p);
    REQUIRE(s->run(10).ok());
    CHECK(s->velocities()[0].z == 1.0);
    CHECK(s->positions()[0].z == doctest::Approx(0.001 + 10 * 0.02 * 1.0));
  }
  SUBCASE("outward force (gravity pointing up): the particle accelerates away") {
    p.gravity = {0, 0, 9.81};
    auto s = CpuSolver<double>::create(particle({0, 0, 0.001}, {0, 0, 0}), p);
    REQUIRE(s->step().ok());
    CHECK(s->velocities()[0].z == doctest::Approx(9.81 * 0.02));
  }
  SUBCASE("inward force on a resting particle is removed: it stays on the floor") {
    p.gravity = {0, 0, -9.81};
    auto s = CpuSolver<double>::create(particle({0, 0, 0.001}, {0, 0, 0}), p);
    REQUIRE(s->run(100).ok());
    CHECK(s->positions()[0].z == doctest::Approx(0.001));
    CHECK(s->velocities()[0].z == 0.0);
  }
  SUBCASE("on the side of a sphere gravity's tangential part makes the particle slide, not stick") {
    p.gravity = {0, 0, -9.81};
    p.colliders = {Collider::sphere({0, 0, 0}, 1.0)};
    const glm::dvec3 start = glm::normalize(glm::dvec3{1, 0, 1}) * 1.001;
    auto s = CpuSolver<double>::create(particle(start, {0, 0, 0}), p);
    REQUIRE(s->run(10).ok());
    const glm::dvec3 x = s->positions()[0];
    CHECK(x.z < start.z - 1e-3);                       // slid down...
    CHECK(x.x > start.x);                              // ...around the sphere
    CHECK(glm::length(x) >= 1.0);                      // and stayed outside
  }
}

TEST_CASE("wind F = Kw <n, u> n: zero when the wind lies in the cloth plane, along the normal otherwise") {
  ClothDesc d;
  d.nx = 5;
  d.ny = 4;
  d.pin_default_corners = false; // vertical cloth in the x-z plane: normal +-y
  SimParams p = no_forces();
  p.wind = {0.05, {1, 0, 1}};
  auto in_plane = CpuSolver<double>::create(cloth(d), p);
  REQUIRE(in_plane->step().ok());
  for (const glm::dvec3& f : in_plane->forces()) CHECK(glm::length(f) < 1e-12);

  p.wind = {0.05, {1, 1, 0}}; // normalised to (1, 1, 0)/sqrt 2: <n, u> = -+1/sqrt 2
  auto across = CpuSolver<double>::create(cloth(d), p);
  REQUIRE(across->step().ok());
  for (std::size_t k = 0; k < across->forces().size(); ++k) {
    const glm::dvec3 f = across->forces()[k], n = across->normals()[k];
    CHECK(std::abs(std::abs(n.y) - 1.0) < 1e-12);
    CHECK(f.x == doctest::Approx(0.0));
    CHECK(f.z == doctest::Approx(0.0));
    CHECK(f.y == doctest::Approx(0.05 / std::sqrt(2.0))); // along the wind's normal component
  }
}

TEST_CASE("a blow-up is reported with the step and time, and runs are bit-identical") {
  ClothDesc d;
  d.origin = {-0.5, 0.0, 0.5};
  d.stiffness.structural = 200.0;
  auto s = CpuSolver<float>::create(cloth(d), SimParams{});
  auto r = s->run(1000);
  REQUIRE_FALSE(r.ok());
  CHECK(r.error().code == ErrorCode::diverged);
  CHECK(r.error().message.find("at step ") != std::string::npos);
  CHECK(r.error().message.find("t = ") != std::string::npos);

  d.stiffness.structural = 40.0;
  SimParams p;
  p.wind = {0.05, {0, 1, 0}};
  p.integrator = Integrator::rk4;
  auto a = CpuSolver<float>::create(cloth(d), p);
  auto b = CpuSolver<float>::create(cloth(d), p);
  REQUIRE(a->run(300).ok());
  REQUIRE(b->run(300).ok());
  for (std::size_t k = 0; k < a->positions().size(); ++k) CHECK(a->positions()[k] == b->positions()[k]);
}

TEST_CASE("the CPU solver gives bit-identical results for any thread count") {
  ClothDesc d;
  d.nx = 64;
  d.ny = 48;
  d.particle_mass = 0.2;
  d.origin = {-0.5, 0.0, 0.5};
  SimParams p;
  p.wind = {0.05, {0, 1, 0}};
  p.colliders = {Collider::sphere({0, 0.2, 0.2}, 0.3)};
  for (Integrator integ : {Integrator::semi_implicit_euler, Integrator::rk4}) {
    p.integrator = integ;
    auto one = CpuSolver<float>::create(cloth(d), p, {1});
    auto two = CpuSolver<float>::create(cloth(d), p, {2});
    REQUIRE(one.ok());
    REQUIRE(two.ok());
    CHECK(one->threads() == 1);
    CHECK(two->threads() == 2);
    REQUIRE(one->run(50).ok());
    REQUIRE(two->run(50).ok());
    std::size_t differ = 0;
    for (std::size_t k = 0; k < one->positions().size(); ++k)
      differ += one->positions()[k] != two->positions()[k] || one->velocities()[k] != two->velocities()[k];
    CHECK(differ == 0);
  }
}
