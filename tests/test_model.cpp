// SPDX-License-Identifier: MIT
// Builders and the system description: counts, rest lengths, index convention, gather order, errors.
#include <doctest/doctest.h>

#include <cmath>

#include <glm/geometric.hpp>

#include "vkcloth/vkcloth.hpp"

using namespace vkcloth;

namespace {
std::size_t count_kind(const ParticleSystem& s, SpringKind k) {
  std::size_t n = 0;
  for (const Spring& sp : s.springs)
    n += sp.kind == k;
  return n;
}
} // namespace

TEST_CASE("chain defaults are the report's single spring (K = 20, L0 = 0.4, m = 1, 0.4 below the anchor)") {
  auto sys = make_chain({});
  REQUIRE(sys.ok());
  REQUIRE(sys->particles.size() == 2);
  CHECK(sys->particles[0].pinned);
  CHECK_FALSE(sys->particles[1].pinned);
  CHECK(sys->particles[1].mass == 1.0);
  CHECK(sys->particles[1].position.z == doctest::Approx(-0.4));
  REQUIRE(sys->springs.size() == 1);
  CHECK(sys->springs[0].stiffness == 20.0);
  CHECK(sys->springs[0].rest_length == 0.4);
  CHECK_FALSE(sys->grid.has_value());
}

TEST_CASE("chain of two masses hangs straight down at rest length when positions are omitted") {
  ChainDesc d;
  d.masses = {1.0, 2.0};
  d.stiffness = {20.0, 30.0};
  d.rest_lengths = {0.4, 0.3};
  d.positions.clear();
  auto sys = make_chain(d);
  REQUIRE(sys.ok());
  REQUIRE(sys->particles.size() == 3);
  CHECK(sys->particles[2].position.z == doctest::Approx(-0.7));
  CHECK(sys->springs[1].a == 1);
  CHECK(sys->springs[1].b == 2);
  CHECK(sys->springs[1].stiffness == 30.0);
}

TEST_CASE("cloth spring counts and rest lengths follow the real, non-square spacing") {
  ClothDesc d;
  d.nx = 3;
  d.ny = 5;
  d.size = {1.0, 1.0}; // dx = 0.5, dy = 0.25
  auto sys = make_cloth(d);
  REQUIRE(sys.ok());
  const std::size_t nx = 3, ny = 5;
  CHECK(sys->particles.size() == nx * ny);
  CHECK(count_kind(*sys, SpringKind::structural) == (nx - 1) * ny + nx * (ny - 1));
  CHECK(count_kind(*sys, SpringKind::shear) == 2 * (nx - 1) * (ny - 1));
  CHECK(count_kind(*sys, SpringKind::bend) == (nx - 2) * ny + nx * (ny - 2));
  for (const Spring& s : sys->springs) {
    const double real = glm::length(sys->particles[s.b].position - sys->particles[s.a].position);
    CHECK(s.rest_length == doctest::Approx(real).epsilon(1e-12)); // starts in its rest shape
    const double expected = s.kind == SpringKind::structural ? (s.b - s.a == 1 ? 0.5 : 0.25)
                            : s.kind == SpringKind::shear    ? std::sqrt(0.5 * 0.5 + 0.25 * 0.25)
                                                             : (s.b - s.a == 2 ? 1.0 : 0.5);
    CHECK(s.rest_length == doctest::Approx(expected));
  }
  CHECK(sys->springs.front().stiffness == 40.0); // report defaults 40 / 8 / 8
  CHECK(sys->springs.back().stiffness == 8.0);
}

TEST_CASE("cloth index convention: particle (i, j) is j * nx + i, and vertical spans x-z, horizontal x-y") {
  ClothDesc d;
  d.nx = 4;
  d.ny = 3;
  d.size = {3.0, 2.0};
  d.origin = {1.0, 2.0, 3.0};
  auto v = make_cloth(d);
  REQUIRE(v.ok());
  const glm::dvec3 p21 = v->particles[1 * 4 + 2].position;
  CHECK(p21.x == doctest::Approx(3.0));
  CHECK(p21.y == doctest::Approx(2.0));
  CHECK(p21.z == doctest::Approx(4.0));
  // Default pins: the two corners of the top row j = ny - 1.
  for (std::size_t k = 0; k < v->particles.size(); ++k)
    CHECK(v->particles[k].pinned == (k == 2 * 4 + 0 || k == 2 * 4 + 3));
  d.orientation = ClothOrientation::horizontal;
  auto h = make_cloth(d);
  REQUIRE(h.ok());
  CHECK(h->particles[1 * 4 + 2].position.y == doctest::Approx(3.0));
  CHECK(h->particles[1 * 4 + 2].position.z == doctest::Approx(3.0));
}

TEST_CASE("cloth pins: an explicit list replaces the corners, and zero stiffness leaves a kind out") {
  ClothDesc d;
  d.nx = d.ny = 5;
  d.pins = {{2, 2}};
  d.stiffness.shear = 0.0;
  d.stiffness.bend = 0.0;
  auto sys = make_cloth(d);
  REQUIRE(sys.ok());
  for (std::size_t k = 0; k < sys->particles.size(); ++k)
    CHECK(sys->particles[k].pinned == (k == 12));
  CHECK(count_kind(*sys, SpringKind::shear) == 0);
  CHECK(count_kind(*sys, SpringKind::bend) == 0);
  d.pins.clear();
  d.pin_default_corners = false;
  auto free_cloth = make_cloth(d);
  REQUIRE(free_cloth.ok());
  for (const Particle& p : free_cloth->particles)
    CHECK_FALSE(p.pinned);
}

TEST_CASE("adjacency lists each spring at both ends, in increasing spring index (the gather order)") {
  ClothDesc d;
  d.nx = 6;
  d.ny = 5;
  auto sys = make_cloth(d);
  REQUIRE(sys.ok());
  const SpringAdjacency& adj = sys->adjacency;
  REQUIRE(adj.offsets.size() == sys->particles.size() + 1);
  CHECK(adj.refs.size() == 2 * sys->springs.size());
  for (std::size_t p = 0; p < sys->particles.size(); ++p)
    for (std::uint32_t e = adj.offsets[p]; e < adj.offsets[p + 1]; ++e) {
      const Spring& s = sys->springs[adj.refs[e].spring];
      CHECK(((s.a == p && s.b == adj.refs[e].other) || (s.b == p && s.a == adj.refs[e].other)));
      if (e > adj.offsets[p])
        CHECK(adj.refs[e - 1].spring < adj.refs[e].spring);
    }
  // An interior particle has 4 structural + 4 shear + 4 bend springs.
  const std::size_t interior = 2 * 6 + 2;
  CHECK(adj.offsets[interior + 1] - adj.offsets[interior] == 12);
}

TEST_CASE("bad builder input is an error naming the key and the value") {
  auto msg = [](const Result<ParticleSystem>& r) { return r.ok() ? std::string("(ok)") : r.error().message; };
  ClothDesc d;
  d.nx = 0;
  auto r = make_cloth(d);
  CHECK_FALSE(r.ok());
  CHECK(msg(r).find("cloth.resolution [0, 10]") != std::string::npos);
  d.nx = 100000;
  d.ny = 100000;
  CHECK(msg(make_cloth(d)).find("cloth.resolution [100000, 100000]") != std::string::npos);
  d = {};
  d.particle_mass = 0.0;
  CHECK(msg(make_cloth(d)).find("cloth.particle_mass") != std::string::npos);
  d = {};
  d.pins = {{10, 0}};
  CHECK(msg(make_cloth(d)).find("cloth.pins[0] = [10, 0]") != std::string::npos);
  d = {};
  d.stiffness.bend = -1.0;
  CHECK(msg(make_cloth(d)).find("cloth.stiffness.bend") != std::string::npos);
  ChainDesc c;
  c.masses = {1.0, 1.0};
  c.stiffness = {1.0, 2.0, 3.0};
  CHECK(msg(make_chain(c)).find("chain.stiffness must hold 1 or 2 values") != std::string::npos);
  c = {};
  c.masses = {-1.0};
  CHECK(msg(make_chain(c)).find("chain.masses[0] must be finite and > 0, got -1") != std::string::npos);
}

TEST_CASE("SimParams::validate names the field, rejects non-finite values and normalises directions") {
  SimParams p;
  CHECK(p.validate().ok());
  p.dt = 0.0;
  CHECK(p.validate().error().message.find("integrator.dt") != std::string::npos);
  p = {};
  p.damping = -1.0;
  CHECK(p.validate().error().message.find("physics.damping") != std::string::npos);
  p = {};
  p.gravity.z = INFINITY;
  CHECK_FALSE(p.validate().ok());
  p = {};
  p.colliders = {Collider::sphere({0, 0, 0}, 0.0)};
  CHECK(p.validate().error().message.find("colliders[0].radius") != std::string::npos);
  p = {};
  p.colliders = {Collider::plane({0, 0, 0}, 0.0)};
  CHECK(p.validate().error().message.find("colliders[0].normal") != std::string::npos);
  p = {};
  p.colliders = {Collider::plane({0, 0, 2}, 0.0)};
  p.wind = {0.1, {3, 4, 0}};
  REQUIRE(p.validate().ok());
  CHECK(p.colliders[0].normal.z == doctest::Approx(1.0));
  CHECK(p.wind.direction.x == doctest::Approx(0.6));
  CHECK(parse_integrator("rk4") == Integrator::rk4);
  CHECK_FALSE(parse_integrator("verlet").has_value());
}

TEST_CASE("ParticleSystem::validate refuses what no solver can run, naming the problem") {
  auto sys = make_cloth({});
  REQUIRE(sys.ok());
  CHECK(sys->validate().ok());
  ParticleSystem empty;
  CHECK(empty.validate().error().message.find("empty") != std::string::npos);
  ParticleSystem raw;
  raw.particles.resize(2);
  CHECK(raw.validate().error().message.find("not finalized") != std::string::npos);
  ParticleSystem edited = *sys;
  edited.springs.push_back(Spring{0, 100, 1.0, 1.0, SpringKind::plain});
  edited.finalize(); // leaves the bad spring out of the gather lists; validate() names it
  CHECK(edited.validate().error().message.find("joins particles 0 and 100, but there are 100") !=
        std::string::npos);
  ParticleSystem massless = *sys;
  massless.particles[0].mass = 0.0;
  CHECK(massless.validate().error().message.find("particle 0 has mass 0") != std::string::npos);
  // Every solver refuses it the same way.
  CHECK_FALSE(CpuSolver<float>::create(massless, SimParams{}).ok());
}
