// SPDX-License-Identifier: MIT
// Cloth (report §3-4): conservation, pins, rest state, collisions, wind, blow-up, determinism.
// Every test runs on each backend (CPU float, CPU double, Vulkan) with a tolerance stated for float.
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <random>

#include <fmt/format.h>
#include <glm/geometric.hpp>

#include "sim_backends.hpp"
#include "vkcloth/vkcloth.hpp"

using namespace vkcloth;
using namespace vkcloth::test;

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

/// The initial position as the backend stores it (rounded to float on float backends).
glm::dvec3 stored(Backend b, glm::dvec3 p) {
  return is_float(b) ? glm::dvec3(glm::vec3(p)) : p;
}

/// Moves every particle by up to `amplitude` along each axis and gives each free one a velocity of
/// up to 10 x `amplitude` per axis, from a seeded generator (the same jitter on every run), so that
/// no lane of a SIMD kernel sees a symmetric configuration.
void jitter_state(ParticleSystem& s, double amplitude, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> jitter(-amplitude, amplitude);
  for (Particle& q : s.particles) {
    q.position += glm::dvec3{jitter(rng), jitter(rng), jitter(rng)};
    if (!q.pinned)
      q.velocity = glm::dvec3{jitter(rng), jitter(rng), jitter(rng)} * 10.0;
  }
}

} // namespace

TEST_CASE("a free cloth without gravity, damping or colliders keeps its total momentum") {
  ValidationScope validation;
  ClothDesc d;
  d.nx = 9;
  d.ny = 7;
  d.pin_default_corners = false;
  auto sys = cloth(d);
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
  auto sys = cloth(d);
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
  auto sys = cloth(d);
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
  auto sys = cloth(d);
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
      auto s = make_sim(b, cloth(d), SimParams{});
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
    auto s = make_sim(b, cloth(d), p);
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
    auto in_plane = make_sim(b, cloth(d), p);
    REQUIRE(in_plane->step().ok());
    for (const glm::dvec3& f : in_plane->forces())
      CHECK(glm::length(f) < tol);

    p.wind = {0.05, {1, 1, 0}}; // normalised to (1, 1, 0)/sqrt 2: <n, u> = -+1/sqrt 2
    auto across = make_sim(b, cloth(d), p);
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
    auto s = make_sim(b, cloth(d), SimParams{});
    auto r = s->run(1000);
    REQUIRE_FALSE(r.ok());
    CHECK(r.error().code == ErrorCode::diverged);
    CHECK(r.error().message.find("at step ") != std::string::npos);
    CHECK(r.error().message.find("t = ") != std::string::npos);

    d.stiffness.structural = 40.0;
    SimParams p;
    p.wind = {0.05, {0, 1, 0}};
    p.integrator = Integrator::rk4;
    auto first = make_sim(b, cloth(d), p);
    auto second = make_sim(b, cloth(d), p);
    REQUIRE(first->run(300).ok());
    REQUIRE(second->run(300).ok());
    CHECK(first->positions() == second->positions());
  }
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

TEST_CASE("the CPU grid stencil gives the same results as the CSR gather lists") {
  // A zero-stiffness extra spring makes one interior gather list irregular, so that solver falls
  // back to the CSR lists everywhere; the spring adds u * 0 = 0 last, which changes no value.
  ClothDesc d;
  d.nx = 23;
  d.ny = 17;
  d.origin = {-0.5, 0.0, 0.5};
  SimParams p;
  p.wind = {0.05, {0.2, 1, 0}};
  p.colliders = {Collider::sphere({0, 0.2, 0.2}, 0.3)};
  ParticleSystem regular = cloth(d);
  ParticleSystem irregular = regular;
  irregular.springs.push_back(Spring{5 * d.nx + 5, 6 * d.nx + 7, 0.1, 0.0, SpringKind::plain});
  irregular.finalize();
  // With and without colliders: without, the vectorised row kernel also integrates.
  for (int colliders = 0; colliders < 2; ++colliders)
    for (Integrator integ : {Integrator::explicit_euler, Integrator::semi_implicit_euler, Integrator::rk4}) {
      CAPTURE(to_string(integ));
      CAPTURE(colliders);
      p.integrator = integ;
      p.dt = integ == Integrator::explicit_euler ? 0.005 : 0.02;
      if (colliders == 0)
        p.colliders.clear();
      else
        p.colliders = {Collider::sphere({0, 0.2, 0.2}, 0.3)};
      auto a = CpuSolver<float>::create(regular, p, {1});
      auto b = CpuSolver<float>::create(irregular, p, {2});
      REQUIRE(a.ok());
      REQUIRE(b.ok());
      REQUIRE(a->run(60).ok());
      REQUIRE(b->run(60).ok());
      std::size_t differ = 0;
      for (std::size_t k = 0; k < a->positions().size(); ++k)
        differ += a->positions()[k] != b->positions()[k] || a->velocities()[k] != b->velocities()[k] ||
                  a->normals()[k] != b->normals()[k];
      CHECK(differ == 0);
    }
}

TEST_CASE("the CPU row sweep: masked border rows and the per-particle border give the CSR lists' bits") {
  // Three solvers on one jittered cloth: `masked` (make_cloth's lists: every particle takes the
  // row kernel, border particles with their stencil masks), `border` (a zero-stiffness spring
  // between two border particles makes their lists irregular: no masks, the border particles
  // take the per-particle code) and `csr` (the same between interior particles: no stencil, the
  // CSR lists everywhere). A zero-stiffness spring adds u * 0 = 0 last, which changes no value.
  // Midway, set_particle and a few RK4 steps change the positions outside the row sweep: the
  // sweep's SoA copy must be rebuilt from them.
  ClothDesc d;
  d.nx = 41;
  d.ny = 19;
  d.particle_mass = 0.3;
  d.origin = {-0.5, 0.0, 0.5};
  ParticleSystem masked = cloth(d);
  masked.particles[std::size_t(1 * d.nx + 20)].pinned = true; // a pinned border particle
  jitter_state(masked, 0.004, 11);
  ParticleSystem border = masked;
  border.springs.push_back(Spring{0, d.nx + 3, 0.1, 0.0, SpringKind::plain});
  border.finalize();
  ParticleSystem csr = masked;
  csr.springs.push_back(Spring{5 * d.nx + 5, 6 * d.nx + 7, 0.1, 0.0, SpringKind::plain});
  csr.finalize();
  SimParams p;
  p.wind = {0.07, {0.2, 1, 0.1}};
  for (int colliders = 0; colliders < 2; ++colliders)
    for (Integrator integ : {Integrator::explicit_euler, Integrator::semi_implicit_euler})
      for (unsigned threads : {1u, 2u}) {
        CAPTURE(colliders);
        CAPTURE(to_string(integ));
        CAPTURE(threads);
        p.integrator = integ;
        p.dt = integ == Integrator::explicit_euler ? 0.004 : 0.02;
        if (colliders == 0)
          p.colliders.clear();
        else
          p.colliders = {Collider::sphere({0, 0.2, 0.2}, 0.3)};
        std::vector<CpuSolver<float>> s;
        for (const ParticleSystem* sys : {&masked, &border, &csr}) {
          auto c = CpuSolver<float>::create(*sys, p, {threads});
          REQUIRE(c.ok());
          s.push_back(std::move(*c));
        }
        for (CpuSolver<float>& c : s) {
          REQUIRE(c.run(15).ok());
          // A border and an interior particle moved by a "hand".
          REQUIRE(
              c.set_particle(std::uint32_t(d.nx + 7), glm::vec3(-0.3f, 0.01f, 0.45f), glm::vec3(0.1f, 0, 0))
                  .ok());
          REQUIRE(
              c.set_particle(std::uint32_t(9 * d.nx + 20), glm::vec3(0.02f, 0.05f, 0.2f), glm::vec3(0)).ok());
          REQUIRE(c.run(10).ok());
          SimParams rk = p;
          rk.integrator = Integrator::rk4;
          REQUIRE(c.set_params(rk).ok());
          REQUIRE(c.run(3).ok());
          REQUIRE(c.set_params(p).ok());
          REQUIRE(c.run(10).ok());
        }
        for (std::size_t k = 1; k < s.size(); ++k) {
          CAPTURE(k);
          std::size_t differ = 0;
          for (std::size_t q = 0; q < s[0].positions().size(); ++q)
            differ += std::memcmp(&s[0].positions()[q], &s[k].positions()[q], sizeof(glm::vec3)) != 0 ||
                      std::memcmp(&s[0].velocities()[q], &s[k].velocities()[q], sizeof(glm::vec3)) != 0 ||
                      std::memcmp(&s[0].forces()[q], &s[k].forces()[q], sizeof(glm::vec3)) != 0 ||
                      std::memcmp(&s[0].normals()[q], &s[k].normals()[q], sizeof(glm::vec3)) != 0;
          CHECK(differ == 0);
        }
      }
}

TEST_CASE("the CPU row sweep's finite check catches a bad particle in any lane, border or interior") {
  // One particle thrown with a huge velocity leaves the divergence limit in one step; the springs
  // read the positions from before the step, so no other particle is bad yet and the error must
  // name that one. Every particle of 8 rows in turn (every SIMD lane, tail vectors, border and
  // interior, around the 2-thread chunk boundary in row 23), with and without colliders (the
  // kernel's own check, and the check after the per-particle contact code).
  ClothDesc d;
  d.nx = 45;
  d.ny = 47; // 2115 particles: enough for 2 threads
  d.origin = {-0.5, 0.0, 0.5};
  d.pin_default_corners = false;
  const ParticleSystem sys = cloth(d);
  SimParams p;
  p.wind = {0.05, {0.2, 1, 0}};
  for (int colliders = 0; colliders < 2; ++colliders) {
    if (colliders)
      p.colliders = {Collider::plane({0, 0, 1}, -5.0)};
    for (unsigned threads : {1u, 2u}) {
      CAPTURE(colliders);
      CAPTURE(threads);
      std::size_t named = 0, tried = 0;
      for (std::uint32_t k = 0; k < sys.particles.size(); ++k) {
        const std::uint32_t row = k / d.nx;
        if (!(row <= 2 || (row >= 22 && row <= 24) || row >= d.ny - 2))
          continue;
        ++tried;
        auto s = CpuSolver<float>::create(sys, p, {threads});
        REQUIRE(s.ok());
        REQUIRE(s->threads() == threads);
        REQUIRE(s->step().ok());
        const glm::vec3 x = s->positions()[k];
        REQUIRE(s->set_particle(k, x, glm::vec3(0, 1e30f, 0)).ok());
        auto r = s->step();
        REQUIRE_FALSE(r.ok());
        CHECK(r.error().code == ErrorCode::diverged);
        named += r.error().message.find(fmt::format("particle {} is at", k)) != std::string::npos;
      }
      CHECK(tried == 8 * d.nx);
      CHECK(named == tried);
    }
  }
}

namespace {
/// Runs `steps` steps of a CpuSolver<Real> created while VKCLOTH_CPU_SIMD = `isa` (the row kernel's
/// ISA is chosen at creation; "scalar": every particle through the shared kernel, cloth_kernel.h),
/// returning positions, velocities, forces and normals end to end.
template <typename Real>
std::vector<glm::vec<3, Real>> run_with_isa(const char* isa, const ParticleSystem& sys, const SimParams& p,
                                            unsigned threads, int steps) {
  ::setenv("VKCLOTH_CPU_SIMD", isa, 1);
  auto s = CpuSolver<Real>::create(sys, p, {threads});
  ::unsetenv("VKCLOTH_CPU_SIMD");
  REQUIRE(s.ok());
  REQUIRE(s->run(std::uint64_t(steps)).ok());
  std::vector<glm::vec<3, Real>> out;
  for (auto span : {s->positions(), s->velocities(), s->forces(), s->normals()})
    out.insert(out.end(), span.begin(), span.end());
  return out;
}

template <typename Real>
std::size_t bitwise_differences(const std::vector<glm::vec<3, Real>>& a,
                                const std::vector<glm::vec<3, Real>>& b) {
  REQUIRE(a.size() == b.size());
  std::size_t differ = 0;
  for (std::size_t k = 0; k < a.size(); ++k)
    differ += std::memcmp(&a[k], &b[k], sizeof a[k]) != 0; // bits, so -0 vs +0 and NaN count too
  return differ;
}
} // namespace

TEST_CASE_TEMPLATE("the SIMD row kernels (AVX2, AVX-512) give the shared reference's bits", Real, float,
                   double) {
  // Odd sizes: interior runs of 33 particles = whole vectors plus a scalar remainder, and chunk
  // boundaries of the 2-thread split fall mid-row (vbd: colours of 214-215 particles, whole vectors
  // and a remainder each). Wind on, an interior pinned particle (the
  // kernel's pin select), a perturbed start so no lane sees a symmetric configuration. On a CPU
  // without AVX-512 / AVX2 the variable caps the ISA, and the comparison is trivially equal.
  ClothDesc d;
  d.nx = 37;
  d.ny = 29;
  d.particle_mass = 0.3;
  d.origin = {-0.5, 0.0, 0.5};
  ParticleSystem sys = cloth(d);
  sys.particles[std::size_t(10 * d.nx + 17)].pinned = true;
  jitter_state(sys, 0.004, 7);
  SimParams p;
  p.wind = {0.07, {0.2, 1, 0.1}};
  // Colliders 2 and 3 (the SIMD finish, row_kernel_simd.inl simd_finish): every shape it takes,
  // each cutting through the cloth from the first step (projections) with particles in the band
  // around it: a turned, spinning box with friction; a capsule with static > kinetic friction; a
  // plane moving along itself with friction; a still, frictionless sphere (the report's filter);
  // 3: the same with contact_inward_only false (Figure 12's variant).
  auto friction = [](Collider c, double kinetic, double stat) {
    c.friction = kinetic;
    c.static_friction = stat;
    return c;
  };
  Collider box =
      Collider::box({0.2, 0.05, 0.8}, {0.15, 0.06, 0.1}, Collider::rotation_from_degrees({10, 20, 30}));
  box.angular_velocity = {0, 0, 0.7};
  Collider floor = Collider::plane({0, 1, 0}, -0.002);
  floor.linear_velocity = {0.1, 0, 0};
  const std::vector<Collider> shapes = {
      friction(box, 0.4, -1.0),
      friction(Collider::capsule({-0.4, 0.02, 1.2}, {0.0, -0.03, 1.0}, 0.05), 0.3, 0.5),
      friction(floor, 0.5, -1.0), Collider::sphere({-0.2, 0.1, 0.7}, 0.12)};
  for (int colliders = 0; colliders < 4; ++colliders)
    for (Integrator integ : {Integrator::explicit_euler, Integrator::semi_implicit_euler, Integrator::vbd}) {
      CAPTURE(to_string(integ));
      CAPTURE(colliders);
      p.integrator = integ; // vbd: its colour kernel (simd_vbd_colour) on the same lanes
      p.dt = integ == Integrator::explicit_euler ? 0.004 : 0.02;
      p.contact_inward_only = colliders != 3;
      if (colliders == 0)
        p.colliders.clear();
      else if (colliders == 1)
        p.colliders = {Collider::sphere({0, 0.2, 0.2}, 0.3)};
      else
        p.colliders = shapes;
      for (unsigned threads : {1u, 2u}) {
        CAPTURE(threads);
        const auto scalar = run_with_isa<Real>("scalar", sys, p, threads, 40);
        CHECK(bitwise_differences(scalar, run_with_isa<Real>("avx2", sys, p, threads, 40)) == 0);
        CHECK(bitwise_differences(scalar, run_with_isa<Real>("avx512", sys, p, threads, 40)) == 0);
      }
    }
}

TEST_CASE_TEMPLATE(
    "the SIMD list kernel (meshes: padded gather and fan lists) gives the shared reference's bits", Real,
    float, double) {
  // The sample meshes: irregular triangles (601 particles: whole vectors plus a remainder of 1 for
  // 8 and 4 lanes) and a flag with a hole (border fans of every length). Wind on, pins, jittered
  // positions and velocities; no colliders (the kernel integrates), a sphere and a plane (its
  // forces go through euler_finish), both Euler variants, 1 and 2 threads.
  for (const char* file : {"tablecloth.obj", "flag_with_hole.obj"}) {
    CAPTURE(std::string(file));
    auto mesh = read_mesh(std::filesystem::path(VKCLOTH_SCENES_DIR) / "../meshes" / file);
    REQUIRE(mesh.ok());
    MeshClothDesc desc;
    desc.pin_vertices = {0, 5};
    auto made = make_mesh_cloth(*mesh, desc);
    REQUIRE(made.ok());
    ParticleSystem sys = made->system;
    jitter_state(sys, 0.003, 11);
    glm::dvec3 low(1e9);
    for (const Particle& q : sys.particles)
      low = glm::min(low, q.position);
    SimParams p;
    p.wind = {0.07, {0.2, 1, 0.1}};
    for (int colliders = 0; colliders < 2; ++colliders)
      for (Integrator integ :
           {Integrator::explicit_euler, Integrator::semi_implicit_euler, Integrator::vbd}) {
        CAPTURE(to_string(integ));
        CAPTURE(colliders);
        p.integrator = integ; // vbd: the colour kernel walks the gather lists, of every length here
        p.dt = integ == Integrator::explicit_euler ? 0.002 : 0.01;
        p.colliders.clear();
        if (colliders == 1)
          p.colliders = {
              Collider::sphere(sys.particles[sys.size() / 2].position - glm::dvec3{0, 0.05, 0}, 0.1),
              Collider::plane({0, 1, 0}, low.y + 0.01)};
        for (unsigned threads : {1u, 2u}) {
          CAPTURE(threads);
          const auto scalar = run_with_isa<Real>("scalar", sys, p, threads, 40);
          CHECK(bitwise_differences(scalar, run_with_isa<Real>("avx2", sys, p, threads, 40)) == 0);
          CHECK(bitwise_differences(scalar, run_with_isa<Real>("avx512", sys, p, threads, 40)) == 0);
        }
      }
  }
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
