// SPDX-License-Identifier: MIT
// The CPU solver's fast paths against its reference (engine/src/core: cpu_sweeps.cpp, the row and
// list kernels of row_kernel_simd.inl): the thread count, the grid stencil against the CSR gather
// lists, the row sweep's masked borders and finite check, and the SIMD row and list kernels (AVX2,
// AVX-512), each bit for bit.
#include <doctest/doctest.h>

#include <cmath>
#include <cstdlib>
#include <cstring>
#include <random>

#include <glm/geometric.hpp>

#include "grid_meshes.hpp"
#include "sim_backends.hpp"
#include "vkcloth/vkcloth.hpp"

using namespace vkcloth;
using namespace vkcloth::test;

namespace {

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
    auto one = CpuSolver<float>::create(grid_cloth(d), p, {1});
    auto two = CpuSolver<float>::create(grid_cloth(d), p, {2});
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
  ParticleSystem regular = grid_cloth(d);
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
  ParticleSystem masked = grid_cloth(d);
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
  const ParticleSystem sys = grid_cloth(d);
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

/// A bumpy height field of 2 x 16 x 16 triangles over [-0.6, 0.6]^2 (z = 0.03 sin(9x) cos(7y)): a mesh
/// collider with convex and concave edges for the SIMD finish's mesh lanes.
std::shared_ptr<const ColliderMesh> bumpy_mesh() {
  return grid_collider(
      16, 1.2, [](double x, double y) { return 0.03 * std::sin(9 * x) * std::cos(7 * y); }, "bumps");
}

} // namespace

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
  ParticleSystem sys = grid_cloth(d);
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
  // 4: a mesh collider whose bumps cut through the cloth (its lanes' search entries, the scalar
  // search where they miss) and the sphere.
  const Collider bumps =
      friction(Collider::triangle_mesh(bumpy_mesh(), {0, -0.005, 0.7},
                                       Collider::rotation_from_degrees({-90, 0, 0}), 0.004),
               0.3, -1.0);
  for (int colliders = 0; colliders < 5; ++colliders)
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
      else if (colliders == 4)
        p.colliders = {bumps, Collider::sphere({-0.2, 0.1, 0.7}, 0.12)};
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
