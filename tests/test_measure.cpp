// SPDX-License-Identifier: MIT
// structural_strain (vkcloth/measure.hpp): closed-form strains of stretched and edited grids.
#include <doctest/doctest.h>

#include <limits>
#include <vector>

#include "vkcloth/vkcloth.hpp"
#include "rest_positions.hpp"

using namespace vkcloth;
using vkcloth::test::rest_positions;

namespace {

ParticleSystem grid(std::uint32_t nx, std::uint32_t ny) {
  ClothDesc d;
  d.nx = nx;
  d.ny = ny;
  d.size = {1.3, 0.7}; // dx = 0.325, dy = 0.7/3: two rest lengths
  d.origin = {0.2, -0.4, 0.9};
  auto s = make_cloth(d);
  REQUIRE(s.ok());
  return std::move(s.value());
}

std::uint32_t spring_between(const ParticleSystem& s, std::uint32_t a, std::uint32_t b) {
  for (std::uint32_t k = 0; k < s.springs.size(); ++k)
    if (s.springs[k].kind == SpringKind::structural && s.springs[k].a == a && s.springs[k].b == b)
      return k;
  FAIL("no structural spring ", a, "-", b);
  return 0;
}

} // namespace

TEST_CASE("structural strain of a grid stretched uniformly by 10% is 0.1 on every structural spring") {
  const ParticleSystem s = grid(5, 4);
  std::vector<glm::dvec3> p = rest_positions(s);
  const glm::dvec3 c{0.3, 0.1, -0.2}; // any centre: a uniform scale about it stretches every length by 1.1
  for (glm::dvec3& x : p)
    x = c + 1.1 * (x - c);
  const auto r = structural_strain(s, std::span<const glm::dvec3>(p));
  REQUIRE(r.ok());
  CHECK(r->count == 4 * 4 + 5 * 3); // (nx-1) ny horizontal + nx (ny-1) vertical
  CHECK(std::abs(r->max - 0.1) < 1e-12);
  CHECK(s.springs[r->spring].kind == SpringKind::structural);

  // The float overload, on the same positions rounded to float (rounding ~ 6e-8 relative).
  std::vector<glm::vec3> pf(p.begin(), p.end());
  const auto rf = structural_strain(s, std::span<const glm::vec3>(pf));
  REQUIRE(rf.ok());
  CHECK(rf->count == r->count);
  CHECK(std::abs(rf->max - 0.1) < 1e-6);

  // Compressed by 10% everywhere: the largest strain is -0.1.
  p = rest_positions(s);
  for (glm::dvec3& x : p)
    x = c + 0.9 * (x - c);
  const auto rc = structural_strain(s, std::span<const glm::dvec3>(p));
  REQUIRE(rc.ok());
  CHECK(std::abs(rc->max + 0.1) < 1e-12);
}

TEST_CASE("structural strain names the most stretched spring and its particles") {
  const ParticleSystem s = grid(5, 4);
  const double dx = 1.3 / 4, dy = 0.7 / 3;
  std::vector<glm::dvec3> p = rest_positions(s);
  // Particle (2, 1) = 7 moved 5% of dx along +x (vertical cloth: i runs along x): the spring
  // 6-7 is stretched by 0.05, 7-8 compressed by 0.05, the vertical ones 2-7 and 7-12 by
  // sqrt(1 + (0.05 dx / dy)^2) - 1 = 0.0024.
  p[7].x += 0.05 * dx;
  const auto r = structural_strain(s, std::span<const glm::dvec3>(p));
  REQUIRE(r.ok());
  CHECK(std::abs(r->max - 0.05) < 1e-12);
  CHECK(r->spring == spring_between(s, 6, 7));
  CHECK(s.springs[r->spring].a == 6);
  CHECK(s.springs[r->spring].b == 7);
  CHECK(0.05 * dx / dy == doctest::Approx(0.0696428571).epsilon(1e-9)); // so 0.0024 < 0.05 above

  // At rest: 0 (to rounding), the first spring.
  const std::vector<glm::dvec3> rest = rest_positions(s);
  const auto r0 = structural_strain(s, std::span<const glm::dvec3>(rest));
  REQUIRE(r0.ok());
  CHECK(std::abs(r0->max) < 1e-12);
}

TEST_CASE("structural strain ignores shear, bend and chain springs, and bad sizes are errors") {
  ParticleSystem s = grid(4, 4);
  // Every non-structural spring at half its rest length's worth of rest: strain 1 there.
  for (Spring& sp : s.springs)
    if (sp.kind != SpringKind::structural)
      sp.rest_length *= 0.5;
  const std::vector<glm::dvec3> p = rest_positions(s);
  const auto r = structural_strain(s, std::span<const glm::dvec3>(p));
  REQUIRE(r.ok());
  CHECK(r->count == 3 * 4 + 4 * 3);
  CHECK(std::abs(r->max) < 1e-12);

  // A chain has no structural spring: count 0, max 0, whatever its stretch.
  ChainDesc cd;
  cd.positions = {{0.0, 0.0, -0.8}}; // the spring at twice its rest length 0.4
  auto chain = make_chain(cd);
  REQUIRE(chain.ok());
  const std::vector<glm::dvec3> cp = rest_positions(*chain);
  const auto rc = structural_strain(*chain, std::span<const glm::dvec3>(cp));
  REQUIRE(rc.ok());
  CHECK(rc->count == 0);
  CHECK(rc->max == 0.0);

  const std::vector<glm::dvec3> short_list(p.begin(), p.end() - 1);
  const auto bad = structural_strain(s, std::span<const glm::dvec3>(short_list));
  REQUIRE_FALSE(bad.ok());
  CHECK(bad.error().code == ErrorCode::invalid_argument);
  CHECK(bad.error().message.find("15 positions for 16 particles") != std::string::npos);
}

TEST_CASE("penetration and max_free_speed: depths inside each collider, pinned particles left out") {
  ClothDesc d;
  d.nx = 3;
  d.ny = 1;
  d.pin_default_corners = false;
  auto s = make_cloth(d);
  REQUIRE(s.ok());
  s->particles[2].pinned = true;
  const std::vector<Collider> colliders = {Collider::plane({0, 0, 1}, 0.0), Collider::sphere({5, 0, 0}, 1.0)};
  // Particle 0 0.02 below the floor, particle 1 0.3 inside the sphere, the pinned one deeper still.
  const std::vector<glm::dvec3> x = {{0, 0, -0.02}, {5.7, 0, 0.0}, {5, 0, 0.5}};
  auto p = penetration(*s, colliders, x);
  REQUIRE(p.ok());
  CHECK(p->depth == doctest::Approx(0.3));
  CHECK(p->particle == 1);
  CHECK(p->collider == 1);
  auto outside = penetration(*s, colliders, std::vector<glm::dvec3>{{0, 0, 0.5}, {0, 0, 0.25}, {0, 0, -1}});
  REQUIRE(outside.ok());
  CHECK(outside->depth == doctest::Approx(-0.25)); // the nearest free particle is 0.25 outside
  CHECK(penetration(*s, {}, x)->depth == -std::numeric_limits<double>::infinity());
  CHECK(penetration(*s, colliders, std::vector<glm::dvec3>(2)).error().code == ErrorCode::invalid_argument);
  CHECK(max_free_speed(*s, std::vector<glm::dvec3>{{3, 4, 0}, {0, 1, 0}, {100, 0, 0}}) == 5.0);
}
