// SPDX-License-Identifier: MIT
// Vertex block descent (Integrator::vbd, docs/model.md "Vertex block descent"): the colouring, the
// variational energy over the iterations, convergence to a tightly solved implicit step, stability
// of a stiff material at a large step, contact inside the solve, friction bringing a tablecloth to
// rest, and the scene keys.
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <set>
#include <span>
#include <string>
#include <vector>

#include <glm/geometric.hpp>

#include "sim_backends.hpp"
#include "vkcloth/material.hpp"
#include "rest_positions.hpp"

using namespace vkcloth;
using namespace vkcloth::test;

namespace {

SimParams vbd_params(double dt, std::uint32_t iterations, double damping = 0.5) {
  SimParams p;
  p.integrator = Integrator::vbd;
  p.dt = dt;
  p.vbd_iterations = iterations;
  p.damping = damping;
  return p;
}

/// A material cloth (two corners pinned unless `free`), n x n over 1 m.
ParticleSystem material_cloth(const char* material, std::uint32_t n, ClothOrientation o, glm::dvec3 origin,
                              bool free = false) {
  ClothDesc d;
  d.nx = d.ny = n;
  d.size = {1.0, 1.0};
  d.origin = origin;
  d.orientation = o;
  d.material = *material_preset(material);
  d.pin_default_corners = !free;
  return *make_cloth(d);
}

/// Implicit Euler's variational energy of one step from rest positions x0 at velocity v0 (the test's
/// own sum, in double): sum m / (2 h^2) |x - y|^2 + mu m / (2 h) |x - x0|^2 + the springs' energies.
double variational_energy(const ParticleSystem& s, const SimParams& p, const std::vector<glm::dvec3>& x0,
                          const std::vector<glm::dvec3>& v0, std::span<const glm::dvec3> x) {
  const double h = p.dt;
  double e = 0.0;
  for (std::size_t i = 0; i < x.size(); ++i) {
    if (s.particles[i].pinned)
      continue;
    const double m = s.particles[i].mass;
    const glm::dvec3 y = x0[i] + h * v0[i] + h * h * p.gravity;
    e += m / (2.0 * h * h) * glm::dot(x[i] - y, x[i] - y) +
         p.damping * m / (2.0 * h) * glm::dot(x[i] - x0[i], x[i] - x0[i]);
  }
  for (const Spring& sp : s.springs) {
    const double stretch = glm::length(x[sp.b] - x[sp.a]) - sp.rest_length;
    e += 0.5 * sp.stiffness * stretch * stretch;
  }
  return e;
}

} // namespace

TEST_CASE("vbd: the topology's colours separate every spring, five on a grid") {
  struct Case {
    const char* name;
    ParticleSystem system;
    std::size_t max_colours;
  };
  ChainDesc chain; // the report's two coupled springs
  chain.masses = {1.0, 1.0};
  chain.stiffness = {20.0, 20.0};
  chain.rest_lengths = {0.4, 0.4};
  chain.positions = {{0.0, 0.0, -0.4}, {0.0, 0.0, -0.8}};
  auto mesh_scene = load_scene_file(std::string(VKCLOTH_SCENES_DIR) + "/flag_with_hole.json");
  REQUIRE(mesh_scene.ok());
  Case cases[] = {{"grid 64 x 64", material_cloth("cotton", 64, ClothOrientation::horizontal, {0, 0, 0}), 5},
                  {"grid 7 x 3", material_cloth("cotton", 7, ClothOrientation::horizontal, {0, 0, 0}), 5},
                  {"chain of 3", *make_chain(chain), 2},
                  {"mesh (flag with a hole)", mesh_scene->system, 16}};
  for (const Case& c : cases) {
    CAPTURE(std::string(c.name));
    auto t = ClothTopology::create(c.system);
    REQUIRE(t.ok());
    const auto order = (*t)->vertex_order();
    const auto offsets = (*t)->vertex_colour_offsets();
    REQUIRE(order.size() == c.system.particles.size());
    CHECK(std::set<std::uint32_t>(order.begin(), order.end()).size() == order.size()); // a permutation
    std::vector<std::size_t> colour(order.size());
    for (std::size_t k = 0; k + 1 < offsets.size(); ++k)
      for (std::uint32_t i = offsets[k]; i < offsets[k + 1]; ++i) {
        colour[order[i]] = k;
        if (i > offsets[k])
          CHECK(order[i - 1] < order[i]); // index order within a colour
      }
    for (const Spring& s : c.system.springs)
      CHECK(colour[s.a] != colour[s.b]);
    MESSAGE(std::string(c.name) << ": " << offsets.size() - 1 << " colours");
    CHECK(offsets.size() - 1 <= c.max_colours);
  }
}

TEST_CASE("vbd: the variational energy does not increase over an iteration") {
  // A stiff cotton cloth hanging from two corners, one step of 1/60 s from rest: the energy after
  // k sweeps (k = 0: the first guess, the inertia target) for k = 0..40.
  const ParticleSystem s = material_cloth("cotton", 16, ClothOrientation::vertical, {-0.5, 0.0, 0.5});
  const auto x0 = rest_positions(s);
  const std::vector<glm::dvec3> v0(x0.size(), glm::dvec3(0.0));
  double previous = INFINITY;
  for (std::uint32_t k = 1; k <= 40; ++k) {
    auto solver = CpuSolver<double>::create(s, vbd_params(1.0 / 60.0, k));
    REQUIRE(solver.ok());
    REQUIRE(solver->step().ok());
    const double e = variational_energy(s, solver->params(), x0, v0, solver->positions());
    CAPTURE(k);
    CHECK(e <= previous * (1.0 + 1e-12));
    previous = e;
  }
}

TEST_CASE("vbd: as the sweeps grow it converges to the tightly solved implicit step") {
  // A small stiff cloth (cotton, 10 x 10, two corners pinned) with an initial swing, one step of
  // 1/100 s: implicit Euler by CG at tolerance 1e-8 (double) against vbd with more and more sweeps.
  ParticleSystem s = material_cloth("cotton", 10, ClothOrientation::vertical, {-0.5, 0.0, 0.5});
  for (Particle& q : s.particles)
    if (!q.pinned)
      q.velocity = {0.0, 0.2 * q.position.x, 0.0};
  SimParams cg = vbd_params(0.01, 1);
  cg.integrator = Integrator::implicit_euler;
  cg.cg_tolerance = 1e-8;
  cg.cg_max_iterations = 10000;
  auto reference = CpuSolver<double>::create(s, cg);
  REQUIRE(reference.ok());
  REQUIRE(reference->step().ok());
  double last = INFINITY;
  for (std::uint32_t iterations : {1u, 10u, 100u, 1000u}) {
    auto solver = CpuSolver<double>::create(s, vbd_params(0.01, iterations));
    REQUIRE(solver.ok());
    REQUIRE(solver->step().ok());
    double d = 0.0;
    for (std::size_t p = 0; p < s.particles.size(); ++p)
      d = std::max(d, glm::length(solver->positions()[p] - reference->positions()[p]));
    MESSAGE(iterations << " sweeps: max |x_vbd - x_cg| = " << d << " m");
    // Closer with every tenfold of sweeps, until vbd has converged: then what is left (6e-5 m) is
    // the difference between backward Euler (vbd) and its linearisation (CG's system).
    CHECK(d <= last + 1e-6);
    last = d;
  }
  CHECK(last < 1e-4);
}

TEST_CASE("vbd: leather at 64 x 64 and dt = 1/30 stays stable") {
  // leather: 10 000 N/m stretch, 0.8 kg/m^2: (k / m) dt^2 ~ 5e4 per step, where semi-implicit Euler
  // needs < 4. Hanging from its top corners (z = 0.5 .. 1.5) for 3 s at the default sweeps, on every
  // backend: no divergence, nearly still at the end, and sagging by less than 10 cm.
  const ParticleSystem s = material_cloth("leather", 64, ClothOrientation::vertical, {-0.5, 0.0, 0.5});
  for (Backend b : backends()) {
    CAPTURE(std::string(to_string(b)));
    ValidationScope vs;
    auto sim = make_sim(b, s, vbd_params(1.0 / 30.0, SimParams{}.vbd_iterations));
    REQUIRE(sim->run(90).ok());
    double speed = 0.0, lowest = INFINITY;
    for (const auto& v : sim->velocities())
      speed = std::max(speed, glm::length(v));
    for (const auto& x : sim->positions())
      lowest = std::min(lowest, x.z);
    MESSAGE(std::string(to_string(b)) << ": leather 64 x 64, dt 1/30, after 3 s: largest speed " << speed
                                      << " m/s, lowest point z = " << lowest << " m");
    CHECK(speed < 0.1);
    CHECK(lowest > 0.4);
  }
  SimParams semi = vbd_params(1.0 / 30.0, 1);
  semi.integrator = Integrator::semi_implicit_euler;
  auto explicit_solver = CpuSolver<float>::create(s, semi);
  REQUIRE(explicit_solver.ok());
  CHECK(explicit_solver->run(90).error().code == ErrorCode::diverged);
}

TEST_CASE("vbd: no particle ends a step inside the sphere (cotton drop)") {
  // The issue's drop at 32 x 32: 1 m of cotton 0.25 m above a sphere of radius 0.25 (friction 0.5),
  // dt 1/300; after every step each particle is outside the sphere (to 1e-6 m of float rounding; the
  // issue asks for no deeper than contact_epsilon). A sweep's projection puts a particle that crossed
  // the surface at surface + eps; one whose step ends within eps of the surface stays there.
  const ParticleSystem s =
      material_cloth("cotton", 32, ClothOrientation::horizontal, {-0.5, -0.5, 0.5}, true);
  SimParams p = vbd_params(1.0 / 300.0, 10);
  Collider sphere;
  sphere.type = Collider::Type::sphere;
  sphere.center = {0.0, 0.0, 0.0};
  sphere.radius = 0.25;
  sphere.friction = 0.5;
  p.colliders = {sphere};
  for (Backend b : backends()) {
    CAPTURE(std::string(to_string(b)));
    ValidationScope vs;
    auto sim = make_sim(b, s, p);
    double closest = INFINITY;
    for (int step = 0; step < (b == Backend::vulkan ? 120 : 300); ++step) { // past the impact (~step 70)
      REQUIRE(sim->step().ok());
      for (const glm::dvec3& x : sim->positions())
        closest = std::min(closest, glm::length(x) - sphere.radius);
    }
    MESSAGE(std::string(to_string(b)) << ": closest particle " << closest << " m from the sphere");
    CHECK(closest >= -1e-6);
  }
}

TEST_CASE("vbd: a free cotton cloth falls as backward Euler's free body, from x0 + h v0") {
  // No damping, no collider: backward Euler moves a free cloth as a rigid body, z_n = z_0 - g h^2
  // n (n + 1) / 2 with every spring at rest. The first guess x0 + h v0 leaves out the step's h^2 g,
  // which the sweeps add (a translation stretches no spring): within 1e-3 of the fall after 30
  // steps (measured 0.050679 m of 0.050685 in float, exact in double).
  const ParticleSystem s =
      material_cloth("cotton", 32, ClothOrientation::horizontal, {-0.5, -0.5, 0.5}, true);
  const SimParams p = vbd_params(1.0 / 300.0, 5, 0.0);
  for (Backend b : backends()) {
    CAPTURE(std::string(to_string(b)));
    ValidationScope vs;
    auto sim = make_sim(b, s, p);
    const int n = 30;
    REQUIRE(sim->run(n).ok());
    double mean_drop = 0.0;
    const auto x = sim->positions();
    for (std::size_t i = 0; i < x.size(); ++i)
      mean_drop += (s.particles[i].position.z - x[i].z) / double(x.size());
    const double expected = 9.81 * p.dt * p.dt * n * (n + 1) / 2.0;
    MESSAGE(std::string(to_string(b)) << ": fell " << mean_drop << " m of backward Euler's " << expected);
    CHECK(std::abs(mean_drop - expected) < 1e-3 * expected);
    auto strain = structural_strain(s, sim->positions());
    REQUIRE(strain.ok());
    CHECK(strain->max < 1e-3); // it falls flat
  }
}

TEST_CASE("vbd: the tablecloth with friction 0.6 comes to rest on the table top") {
  auto scene = load_scene_file(std::string(VKCLOTH_SCENES_DIR) + "/tablecloth_on_table.json",
                               std::vector<std::string>{"integrator.method=vbd"});
  REQUIRE(scene.ok());
  auto solver = CpuSolver<float>::create(scene->system, scene->params);
  REQUIRE(solver.ok());
  REQUIRE(solver->run(scene->steps).ok());
  const Collider& table = scene->params.colliders[0];
  double fastest = 0.0;
  std::size_t on_top = 0;
  for (std::size_t p = 0; p < scene->system.particles.size(); ++p) {
    const glm::vec3 x = solver->positions()[p];
    const bool top = std::abs(x.x - table.center.x) < table.half_extents.x &&
                     std::abs(x.y - table.center.y) < table.half_extents.y &&
                     x.z > table.center.z + table.half_extents.z;
    if (!top)
      continue;
    ++on_top;
    fastest = std::max(fastest, double(glm::length(solver->velocities()[p])));
  }
  MESSAGE(on_top << " particles on the table top after " << scene->steps << " steps, fastest " << fastest
                 << " m/s");
  CHECK(on_top > 100);
  CHECK(fastest < 1e-3);
}

TEST_CASE("vbd: the scene's integrator.iterations, with its range") {
  const std::string base = R"({"system": "chain", "integrator": {"method": "vbd", "iterations": )";
  auto ok = parse_scene(base + "25}}", "vbd.json");
  REQUIRE_MESSAGE(ok.ok(), (ok.ok() ? "" : ok.error().message));
  CHECK(ok->params.integrator == Integrator::vbd);
  CHECK(ok->params.vbd_iterations == 25);
  for (const char* bad : {"0}}", "1001}}", "2.5}}"}) {
    auto r = parse_scene(base + bad, "vbd.json");
    REQUIRE_FALSE(r.ok());
    CAPTURE(r.error().message);
    CHECK(r.error().message.find("integrator.iterations") != std::string::npos);
  }
  CHECK(SimParams{}.vbd_iterations == 5);
}

TEST_CASE("the cotton drop at 64 x 64 and 128 x 128 (samples/bench): strain within 10 % at every step") {
  // The drop the peer comparison times (docs/performance.md "Vertex block descent"): 64 x 64 with
  // vbd's 5 sweeps and no limit (measured 9.7 %); 128 x 128 with one sweep and 6 of Provot's sweeps
  // in chain order to 3 % (9.1 %). The same 128 x 128 run with its sweeps colour by colour stretches
  // 26 %, and with vbd's 5 sweeps and no limit 43 %: the check can fail.
  struct Run {
    const char* file;
    const char* override_;
    bool within;
  };
  const Run runs[] = {{"cotton_drop.json", "integrator.iterations=5", true},
                      {"cotton_drop_128.json", "stretch_limit.order=chains", true},
                      {"cotton_drop_128.json", "stretch_limit.order=colours", false}};
  for (const Run& r : runs) {
    const std::string o = r.override_;
    CAPTURE(r.file);
    CAPTURE(o);
    auto scene = load_scene_file(std::string(VKCLOTH_SCENES_DIR) + "/../bench/" + r.file,
                                 std::span<const std::string>(&o, 1));
    REQUIRE_MESSAGE(scene.ok(), (scene.ok() ? "" : scene.error().message));
    auto s = CpuSolver<float>::create(scene->system, scene->params);
    REQUIRE(s.ok());
    const double largest = largest_strain_over_steps(*scene, *s);
    MESSAGE(std::string(r.file) << " (" << o << "): largest structural strain over the run " << largest);
    if (r.within)
      CHECK(largest <= 0.10);
    else
      CHECK(largest > 0.15);
  }
}

TEST_CASE("implicit solvers on the cotton drop onto a sphere: strain within 10 % without friction (vbd "
          "also with it), no particle flung with friction") {
  // The cotton drop at 32 x 32 and dt 1/300 for 2 s, for both implicit solvers (CG, vbd). CG used to
  // fling particles at 10-18 m/s here (278 % strain at 64 x 64, now 58 %): its solve pulled contact
  // particles into the sphere; Baraff-Witkin's contact filter (cloth_kernel.h contact_axis) keeps
  // them on it. Frictionless: at most 10 % strain over the run (measured CG 4.8 %, vbd 8.1 %; the
  // cloth then slides off the sphere). With friction 0.5: vbd, whose friction acts in the vertex
  // step, at most 10 % (6.5 %); CG, whose Coulomb step after the solve holds stretched springs,
  // under 30 % (22 %; docs/model.md); and no particle faster than 8 m/s over the run (the fall reaches
  // 2.2 m/s at the impact, the corners wrapping under the sphere whip at up to ~5 m/s).
  const ParticleSystem s =
      material_cloth("cotton", 32, ClothOrientation::horizontal, {-0.5, -0.5, 0.5}, true);
  for (double friction : {0.0, 0.5})
    for (Integrator integrator : {Integrator::implicit_euler, Integrator::vbd}) {
      SimParams p = vbd_params(1.0 / 300.0, SimParams{}.vbd_iterations);
      p.integrator = integrator;
      Collider sphere = Collider::sphere({0.0, 0.0, 0.0}, 0.25);
      sphere.friction = friction;
      p.colliders = {sphere};
      auto solver = CpuSolver<float>::create(s, p);
      REQUIRE(solver.ok());
      double strain = 0.0, speed = 0.0;
      for (int step = 0; step < 600; ++step) {
        REQUIRE(solver->step().ok());
        if (step % 5 == 4) {
          auto st = structural_strain(s, solver->positions());
          REQUIRE(st.ok());
          strain = std::max(strain, st->max);
        }
        for (const auto& v : solver->velocities())
          speed = std::max(speed, double(glm::length(v)));
      }
      MESSAGE(std::string(to_string(integrator)) << ", friction " << friction << ": largest strain " << strain
                                                 << ", fastest particle " << speed << " m/s");
      if (friction == 0.0 || integrator == Integrator::vbd) {
        CHECK(strain <= 0.10);
      } else {
        CHECK(strain <= 0.30);
      }
      if (friction > 0.0) // frictionless, the cloth slides off and falls freely for the rest of the 2 s
        CHECK(speed < 8.0);
    }
}
