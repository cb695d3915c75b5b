// SPDX-License-Identifier: MIT
// Skinned mesh colliders (docs/model.md "Mesh contact"): ColliderMesh::deformed
// refits the same hierarchy over new vertex positions and gives each triangle corner its velocity,
// which the contact's friction carries, on every backend; a wrong update is an error naming it.
#include <doctest/doctest.h>

#include <cmath>
#include <vector>

#include "grid_meshes.hpp"
#include "sim_backends.hpp"
#include "vkcloth/collider_mesh.hpp"

using namespace vkcloth;
using namespace vkcloth::test;

namespace {

/// A single free particle (a 1 x 1 cloth) at `pos`.
ParticleSystem particle(glm::dvec3 pos) {
  ClothDesc d;
  d.nx = d.ny = 1;
  d.pin_default_corners = false;
  auto sys = make_cloth(d);
  REQUIRE(sys.ok());
  sys->particles[0].position = pos;
  return *sys;
}

} // namespace

TEST_CASE("skinned mesh: deformed() refits the same hierarchy and gives each corner its velocity") {
  GridMesh g = grid_mesh(8, 2.0, [](double, double) { return 0.0; });
  auto mesh = ColliderMesh::create(g.positions, g.triangles, "skin");
  REQUIRE(mesh.ok());
  CHECK((*mesh)->vertex_count() == 81);
  CHECK((*mesh)->triangle_velocities().empty());
  // Bend it: z = 0.3 x^2, each vertex moved within dt = 0.01 s.
  std::vector<glm::dvec3> bent = g.positions;
  for (glm::dvec3& p : bent)
    p.z = 0.3 * p.x * p.x;
  auto next = (*mesh)->deformed(bent, 0.01);
  REQUIRE(next.ok());
  const ColliderMesh& m = **next;
  REQUIRE(m.nodes().size() == (*mesh)->nodes().size());
  REQUIRE(m.triangle_velocities().size() == m.triangles().size());
  for (std::size_t i = 0; i < m.nodes().size(); ++i) { // the same tree, every box around its triangles
    const ColliderMesh::Node& n = m.nodes()[i];
    CHECK(n.first == (*mesh)->nodes()[i].first);
    CHECK(n.count == (*mesh)->nodes()[i].count);
    if (n.count > 0)
      for (std::uint32_t t = n.first; t < n.first + n.count; ++t)
        for (glm::vec3 v : {m.triangles()[t].a, m.triangles()[t].b, m.triangles()[t].c})
          CHECK((glm::all(glm::greaterThanEqual(v, n.lo)) && glm::all(glm::lessThanEqual(v, n.hi))));
  }
  CHECK(m.nodes()[0].hi.z == doctest::Approx(0.3)); // the root holds the bent edges (x = +-1)
  for (std::size_t t = 0; t < m.triangles().size(); ++t) {
    const ColliderMesh::Triangle& tri = m.triangles()[t];
    const ColliderMesh::Triangle& vel = m.triangle_velocities()[t];
    CHECK(tri.a.z == doctest::Approx(0.3 * tri.a.x * tri.a.x).epsilon(1e-6));
    CHECK(vel.a.z == doctest::Approx(tri.a.z / 0.01).epsilon(1e-4)); // (z - 0) / dt
    CHECK(vel.b.x == 0.0f);
  }

  // Bad updates: named, with the values.
  auto wrong = (*mesh)->deformed(std::vector<glm::dvec3>(80), 0.01);
  REQUIRE(!wrong.ok());
  CHECK(wrong.error().code == ErrorCode::invalid_argument);
  CHECK(wrong.error().message.find("skin") != std::string::npos);
  CHECK(wrong.error().message.find("80 vertices, but the mesh has 81") != std::string::npos);
  bent[5].y = NAN;
  auto nan = (*mesh)->deformed(bent, 0.01);
  REQUIRE(!nan.ok());
  CHECK(nan.error().message.find("skinned vertex 5 is not finite") != std::string::npos);
  auto zero_dt = (*mesh)->deformed(g.positions, 0.0);
  REQUIRE(!zero_dt.ok());
  CHECK(zero_dt.error().message.find("dt must be finite and > 0, got 0") != std::string::npos);
}

TEST_CASE(
    "skinned mesh: a sheet whose vertices slide carries a resting particle by friction, every backend") {
  // The host moves every vertex 0.3 m/s along x each step (ColliderMesh::deformed, then set_params):
  // the collider itself never moves, so only the corners' velocities can carry the particle. With
  // mu = 1 it picks up the sheet's 0.3 m/s (static friction) and keeps it; frictionless, it stays.
  ValidationScope validation;
  const GridMesh g = grid_mesh(4, 4.0, [](double, double) { return 0.0; });
  auto rest = ColliderMesh::create(g.positions, g.triangles, "sliding sheet");
  REQUIRE(rest.ok());
  for (Backend b : backends())
    for (double mu : {1.0, 0.0}) {
      CAPTURE(to_string(b));
      CAPTURE(mu);
      SimParams p;
      p.damping = 0.0;
      Collider sheet = Collider::triangle_mesh(*rest, {0, 0, 0}, glm::dmat3(1.0), 0.005);
      sheet.friction = mu;
      p.colliders = {sheet};
      auto s = make_sim(b, particle({0.1, 0.2, 0.005 + 0.0005}), p);
      std::shared_ptr<const ColliderMesh> mesh = *rest;
      std::vector<glm::dvec3> now = g.positions;
      for (int step = 0; step < 30; ++step) {
        for (glm::dvec3& v : now)
          v.x += 0.3 * p.dt;
        auto next = mesh->deformed(now, p.dt);
        REQUIRE(next.ok());
        mesh = *next;
        p.colliders[0].mesh = mesh;
        REQUIRE(s->set_params(p).ok());
        REQUIRE(s->step().ok());
        CHECK(s->position(0).z > 0.005); // never into the shell
      }
      if (mu > 0.0) {
        CHECK(s->velocity(0).x == doctest::Approx(0.3).epsilon(1e-5));
        CHECK(s->position(0).x == doctest::Approx(0.1 + 0.3 * 30 * p.dt).epsilon(0.05));
      } else {
        CHECK(s->velocity(0).x == 0.0);
      }
    }
}

TEST_CASE("skinned mesh: GPU = CPU for a cloth on a bending sheet, bit for bit on lavapipe") {
  ValidationScope validation;
  const GridMesh g = grid_mesh(11, 1.6, [](double, double) { return 0.0; });
  auto rest = ColliderMesh::create(g.positions, g.triangles, "bending sheet");
  REQUIRE(rest.ok());
  ClothDesc d;
  d.nx = d.ny = 16;
  d.size = {1.0, 1.0};
  d.origin = {-0.5, -0.5, 0.05};
  d.orientation = ClothOrientation::horizontal;
  d.pin_default_corners = false;
  auto cloth = make_cloth(d);
  REQUIRE(cloth.ok());
  SimParams p;
  Collider sheet = Collider::triangle_mesh(*rest, {0, 0, 0}, glm::dmat3(1.0), 0.01);
  sheet.friction = 0.5;
  p.colliders = {sheet};
  std::vector<std::unique_ptr<Sim>> sims;
  for (Backend b : float_backends())
    sims.push_back(make_sim(b, *cloth, p));
  std::shared_ptr<const ColliderMesh> mesh = *rest;
  for (int step = 0; step < 60; ++step) {
    std::vector<glm::dvec3> bent = g.positions; // rising ends: z = 0.2 sin(t) x^2, swaying along y
    const double t = (step + 1) * p.dt * 20.0;
    for (glm::dvec3& v : bent) {
      v.z = 0.2 * std::sin(t) * v.x * v.x;
      v.y += 0.05 * std::sin(t);
    }
    auto next = mesh->deformed(bent, p.dt);
    REQUIRE(next.ok());
    mesh = *next;
    p.colliders[0].mesh = mesh;
    for (auto& s : sims) {
      REQUIRE(s->set_params(p).ok());
      REQUIRE(s->step().ok());
    }
  }
  const auto cpu = sims[0]->positions();
  for (std::size_t k = 1; k < sims.size(); ++k) {
    const auto other = sims[k]->positions();
    double worst = 0.0;
    for (std::size_t i = 0; i < cpu.size(); ++i)
      worst = std::max(worst, glm::length(other[i] - cpu[i]));
    MESSAGE("bending sheet: max |dp| against the CPU float solver " << worst << " m");
    CHECK(worst <= 1e-5); // GPU = CPU within 1e-5 m
    if (vulkan_gives_cpu_bits())
      CHECK(other == cpu); // lavapipe: the CPU's bits
  }
}
