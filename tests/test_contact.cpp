// SPDX-License-Identifier: MIT
// Contact beyond the report (docs/model.md "Collisions"): Coulomb friction against its closed
// forms, moving colliders, and the capsule, box and mesh shapes, on every backend (CPU float,
// CPU double, Vulkan with validation), plus the shapes' distances from cloth_kernel.h itself.
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <limits>

#include <glm/geometric.hpp>

#include "internal/kernel.hpp"
#include "grid_meshes.hpp"
#include "sim_backends.hpp"

using namespace vkcloth;
using namespace vkcloth::test;

namespace {

constexpr double g = 9.81;

/// A single free particle (a 1 x 1 cloth) at `pos` with velocity `vel`.
ParticleSystem particle(glm::dvec3 pos, glm::dvec3 vel) {
  ClothDesc d;
  d.nx = d.ny = 1;
  d.pin_default_corners = false;
  auto sys = make_cloth(d);
  REQUIRE(sys.ok());
  sys->particles[0].position = pos;
  sys->particles[0].velocity = vel;
  return *sys;
}

SimParams gravity_only() {
  SimParams p;
  p.damping = 0.0;
  return p;
}

Collider with_friction(Collider c, double kinetic, double stat = -1.0) {
  c.friction = kinetic;
  c.static_friction = stat;
  return c;
}

/// A small closed mesh: a tetrahedron with its base on z = 0, apex up, faces outward.
std::shared_ptr<const ColliderMesh> tetrahedron() {
  const glm::dvec3 v[] = {{-0.4, -0.3, 0.0}, {0.4, -0.3, 0.0}, {0.0, 0.4, 0.0}, {0.0, 0.0, 0.5}};
  const std::uint32_t t[] = {0, 2, 1, 0, 1, 3, 1, 2, 3, 2, 0, 3};
  auto m = ColliderMesh::create(v, t, "tetrahedron");
  REQUIRE(m.ok());
  return *m;
}

/// An open square sheet of 2 n^2 triangles at z = 0, side `size`, centred on the origin.
std::shared_ptr<const ColliderMesh> sheet(int n, double size) {
  return grid_collider(
      n, size, [](double, double) { return 0.0; }, "sheet");
}

/// The signed distance of p to a collider (cloth_kernel.h in double; p_side = p).
double distance_to(const Collider& c, glm::dvec3 p) {
  kernel::MeshData md;
  if (c.mesh) {
    md.nodes = c.mesh->nodes().data();
    md.triangles = c.mesh->triangles().data();
  }
  double d;
  glm::dvec3 n, deform;
  kernel::collider_contact(md, kernel::kernel_shape<double>(c), p, p, 1.0, d, n, deform);
  return d;
}

} // namespace

TEST_CASE("kernel: box, capsule and mesh distances and normals, edges and corners included") {
  const Collider box =
      Collider::box({1, 2, 3}, {0.5, 0.25, 1.0}, Collider::rotation_from_degrees({0, 0, 90}));
  // The box turned 90 degrees about z: its x half extent (0.5) lies along world y.
  CHECK(distance_to(box, {1, 2.5 + 0.1, 3}) == doctest::Approx(0.1));
  CHECK(distance_to(box, {1 + 0.25 + 0.2, 2, 3}) == doctest::Approx(0.2));
  CHECK(distance_to(box, {1, 2, 3 + 0.9}) == doctest::Approx(-0.1)); // inside: nearest face
  // Beyond a corner: the distance to the corner, the normal along the diagonal.
  const glm::dvec3 corner{1 + 0.25, 2 + 0.5, 3 + 1.0};
  CHECK(distance_to(box, corner + glm::dvec3{0.3, 0.4, 1.2}) == doctest::Approx(1.3));
  // Beyond an edge (x and z out, y within).
  CHECK(distance_to(box, {1 + 0.25 + 0.3, 2, 3 + 1.0 + 0.4}) == doctest::Approx(0.5));

  const Collider capsule = Collider::capsule({0, 0, 0}, {0, 0, 2}, 0.25);
  CHECK(distance_to(capsule, {1, 0, 1}) == doctest::Approx(0.75));          // beside the segment
  CHECK(distance_to(capsule, {0, 0.6, 2.8}) == doctest::Approx(0.75));      // beyond end b: a sphere cap
  CHECK(distance_to(capsule, {0, 0.1, -0.1}) < 0.0);                        // inside cap a
  const Collider degenerate = Collider::capsule({1, 1, 1}, {1, 1, 1}, 0.5); // a == b: a sphere
  CHECK(distance_to(degenerate, {1, 1, 2}) == doctest::Approx(0.5));

  Collider tet = Collider::triangle_mesh(tetrahedron(), {0, 0, 1}, glm::dmat3(1.0), 0.01);
  CHECK(distance_to(tet, {0, 0, 1 - 0.1}) == doctest::Approx(0.09));       // below the base
  CHECK(distance_to(tet, {0, 0, 1 + 0.5 + 0.2}) == doctest::Approx(0.19)); // above the apex
  CHECK(distance_to(tet, {5, 5, 5}) == doctest::Approx(1.0));              // beyond reach: "no contact"
  // 1e18 m and more away, past the search's first bound: no contact (its walk used to find no
  // triangle and read past the list).
  for (double far : {1e18, 1e30}) {
    CAPTURE(far);
    const Collider away = Collider::triangle_mesh(tetrahedron(), {far, 0, 0}, glm::dmat3(1.0), 0.01);
    CHECK(distance_to(away, {0, 0, 1}) == 1.0);
  }
}

TEST_CASE("a mesh collider 1e18 m away or more leaves a falling particle alone, every backend") {
  const ParticleSystem s = particle({0, 0, 1}, {0, 0, 0});
  SimParams p = gravity_only();
  std::vector<std::vector<glm::dvec3>> ends;
  for (Backend b : backends()) {
    CAPTURE(to_string(b));
    ValidationScope validation;
    auto alone = make_sim(b, s, p);
    REQUIRE(alone->run(20).ok());
    for (double far : {1e18, 1e25}) {
      CAPTURE(far);
      SimParams q = p;
      q.colliders = {Collider::triangle_mesh(tetrahedron(), {far, 0, 0}, glm::dmat3(1.0), 0.01)};
      auto sim = make_sim(b, s, q);
      REQUIRE(sim->run(20).ok());
      CHECK(sim->position(0) == alone->position(0));
    }
  }
}

TEST_CASE("kernel: a mesh remembers the side a particle came from (a thin sheet is not crossed)") {
  const Collider s = Collider::triangle_mesh(sheet(4, 2.0), {0, 0, 0}, glm::dmat3(1.0), 0.01);
  kernel::MeshData md{s.mesh->nodes().data(), s.mesh->triangles().data()};
  const auto shape = kernel::kernel_shape<double>(s);
  // From above to 0.3 m below within one step: pushed back above, to thickness + eps.
  glm::dvec3 x{0.1, 0.2, -0.3}, v{0, 0, -15};
  kernel::project_out(md, shape, 1e-3, glm::dvec3{0.1, 0.2, 0.005}, x, v);
  CHECK(x.z == doctest::Approx(0.011));
  CHECK(v.z == 0.0);
  // From below, the same sheet pushes the other way.
  glm::dvec3 y{0.1, 0.2, 0.004}, w{0, 0, 1};
  kernel::project_out(md, shape, 1e-3, glm::dvec3{0.1, 0.2, -0.02}, y, w);
  CHECK(y.z == doctest::Approx(-0.011));
  CHECK(w.z == 0.0);
  // Past the sheet's edge, out of reach of its shell: left alone.
  glm::dvec3 z{1.5, 0.0, -0.2}, u{0, 0, -1};
  kernel::project_out(md, shape, 1e-3, glm::dvec3{1.5, 0.0, 0.1}, z, u);
  CHECK(z.z == -0.2);
}

TEST_CASE("kinetic friction slows a sliding particle by mu_k g h per step and stops it") {
  // A particle resting on the floor (within the 2 eps band) sliding at 1 m/s: the floor removes the
  // weight's impulse g h, so friction takes mu_k g h off the speed each step until the speed left is
  // below mu_s g h, when the particle stops; x = h sum (1 - n mu_k g h) over the sliding steps.
  ValidationScope validation;
  SimParams p = gravity_only();
  const double mu = 0.5, h = p.dt;
  p.colliders = {with_friction(Collider::plane({0, 0, 1}, 0.0), mu)};
  for (Backend b : backends()) {
    CAPTURE(to_string(b));
    const double tol = is_float(b) ? 2e-6 : 1e-12;
    auto s = make_sim(b, particle({0, 0, 0.001}, {1.0, 0, 0}), p);
    REQUIRE(s->run(5).ok());
    CHECK(std::abs(s->velocity(0).x - (1.0 - 5 * mu * g * h)) < tol);
    REQUIRE(s->run(15).ok());
    CHECK(s->velocity(0).x == 0.0);
    double travelled = 0.0;
    for (int n = 1; 1.0 - (n - 1) * mu * g * h > mu * g * h; ++n)
      travelled += h * (1.0 - n * mu * g * h);
    CHECK(std::abs(s->position(0).x - travelled) < 10 * tol);
    CHECK(std::abs(s->position(0).z - 0.001) < tol); // stayed on the floor
  }
}

TEST_CASE("static friction holds on a slope when tan(theta) <= mu_s, kinetic friction sets the slide") {
  // A slope with tan(theta) = 0.5: a particle at rest stays with mu_s = 0.6, and with mu = 0.4
  // accelerates at g (sin theta - mu_k cos theta) along it.
  ValidationScope validation;
  const double theta = std::atan(0.5);
  const glm::dvec3 n{-std::sin(theta), 0.0, std::cos(theta)}; // rising towards +x
  const glm::dvec3 down_slope{-std::cos(theta), 0.0, -std::sin(theta)};
  const glm::dvec3 start = n * 0.001;
  for (Backend b : backends()) {
    CAPTURE(to_string(b));
    SimParams p = gravity_only();
    p.colliders = {with_friction(Collider::plane(n, 0.0), 0.5, 0.6)};
    {
      auto s = make_sim(b, particle(start, {0, 0, 0}), p);
      REQUIRE(s->run(100).ok());
      CHECK(glm::length(s->position(0) - start) < 1e-6);
      CHECK(glm::length(s->velocity(0)) < 1e-6); // rounding of the normal split only
    }
    p.colliders = {with_friction(Collider::plane(n, 0.0), 0.4)};
    {
      auto s = make_sim(b, particle(start, {0, 0, 0}), p);
      REQUIRE(s->run(50).ok());
      const double expected = 50 * p.dt * g * (std::sin(theta) - 0.4 * std::cos(theta));
      CHECK(glm::dot(s->velocity(0), down_slope) == doctest::Approx(expected).epsilon(1e-5));
      CHECK(std::abs(glm::dot(s->velocity(0), n)) < 1e-5); // along the slope, not into it
    }
  }
}

TEST_CASE("vbd: friction in the vertex step holds on a slope when tan(theta) <= mu_s and slides at "
          "g (sin theta - mu_k cos theta)") {
  // The slope above under vertex block descent, whose friction acts in each vertex's step (Coulomb's
  // law on the step's quadratic model, the normal force from the inward move the contact stops; vbd.h
  // vbd_friction). A single particle's step is exact: held still by mu_s = 0.6 (with mu_k = tan theta
  // = 0.5, which alone would only balance gravity), and sliding with mu = 0.4 at exactly backward
  // Euler's v = n h a.
  ValidationScope validation;
  const double theta = std::atan(0.5);
  const glm::dvec3 n{-std::sin(theta), 0.0, std::cos(theta)};
  const glm::dvec3 down_slope{-std::cos(theta), 0.0, -std::sin(theta)};
  const glm::dvec3 start = n * 0.001;
  for (Backend b : backends()) {
    const std::string name = to_string(b);
    CAPTURE(name);
    SimParams p = gravity_only();
    p.integrator = Integrator::vbd;
    p.colliders = {with_friction(Collider::plane(n, 0.0), 0.5, 0.6)};
    {
      auto s = make_sim(b, particle(start, {0, 0, 0}), p);
      REQUIRE(s->run(100).ok());
      MESSAGE(name << ": held " << glm::length(s->position(0) - start) << " m from its start");
      CHECK(glm::length(s->position(0) - start) < 1e-6);
      CHECK(glm::length(s->velocity(0)) < 1e-6);
    }
    p.colliders = {with_friction(Collider::plane(n, 0.0), 0.4)};
    {
      auto s = make_sim(b, particle(start, {0, 0, 0}), p);
      REQUIRE(s->run(50).ok());
      const double expected = 50 * p.dt * g * (std::sin(theta) - 0.4 * std::cos(theta));
      MESSAGE(name << ": slides at " << glm::dot(s->velocity(0), down_slope) << " m/s of " << expected);
      CHECK(glm::dot(s->velocity(0), down_slope) == doctest::Approx(expected).epsilon(1e-5));
      CHECK(std::abs(glm::dot(s->velocity(0), n)) < 1e-5);
    }
  }
}

TEST_CASE("a moving box carries a resting particle, a frictionless one slides under it") {
  // Friction acts on the velocity relative to the surface: with mu = 1 the particle picks up the
  // box's 0.3 m/s within two steps (kinetic, then static) and keeps it; with mu = 0 it stays put.
  ValidationScope validation;
  for (Backend b : backends()) {
    CAPTURE(to_string(b));
    SimParams p = gravity_only();
    Collider box = Collider::box({0, 0, -0.5}, {5, 5, 0.5});
    box.linear_velocity = {0.3, 0, 0};
    p.colliders = {with_friction(box, 1.0)};
    auto s = make_sim(b, particle({0, 0, 0.001}, {0, 0, 0}), p);
    REQUIRE(s->run(20).ok());
    CHECK(s->velocity(0).x == doctest::Approx(0.3).epsilon(1e-6));
    CHECK(s->position(0).x == doctest::Approx(0.3 * 20 * p.dt).epsilon(0.05));
    CHECK(std::abs(s->position(0).z - 0.001) < 1e-6);
    p.colliders = {box};
    auto f = make_sim(b, particle({0, 0, 0.001}, {0, 0, 0}), p);
    REQUIRE(f->run(20).ok());
    CHECK(f->velocity(0).x == 0.0);
  }
}

TEST_CASE(
    "keyframed collider: the pose between keys (linear, slerp), held outside, velocities from the path") {
  // A box turned 90 degrees about z and moved 1 m along x between t = 1 and t = 3.
  const Collider box = Collider::box({0, 0, 1}, {0.5, 0.5, 0.5});
  auto keyed = box.with_keyframes({{1.0, {0, 0, 0}, {0, 0, 0}}, {3.0, {1, 0, 0}, {0, 0, 90}}});
  REQUIRE(keyed.ok());
  CHECK(keyed->center == box.center); // at t = 0: the first key's pose, held
  const Collider mid = keyed->posed_at(2.0);
  CHECK(glm::length(mid.center - glm::dvec3(0.5, 0, 1)) < 1e-12);
  const glm::dmat3 r45 = Collider::rotation_from_degrees({0, 0, 45});
  for (int c = 0; c < 3; ++c)
    CHECK(glm::length(mid.rotation[c] - r45[c]) < 1e-12); // slerp: half the angle at half the time
  // Velocities: the path's motion over the advance (here 1 s at 0.5 m/s, 45 degrees/s within [1, 3]).
  const Collider step = mid.posed_at(0.5);
  CHECK(glm::length(step.linear_velocity - glm::dvec3(0.5, 0, 0)) < 1e-12);
  CHECK(glm::length(step.angular_velocity - glm::dvec3(0, 0, std::atan(1.0))) < 1e-12);
  // Past the last key the pose holds and the collider rests.
  const Collider after = step.posed_at(10.0).posed_at(0.1);
  CHECK(glm::length(after.center - glm::dvec3(1, 0, 1)) < 1e-12);
  CHECK(after.linear_velocity == glm::dvec3(0.0));
  CHECK(after.angular_velocity == glm::dvec3(0.0));
  // A capsule turns about its middle; a plane's normal turns and its offset follows the move.
  auto cap =
      Collider::capsule({-1, 0, 0}, {1, 0, 0}, 0.1).with_keyframes({{0, {}, {}}, {1, {0, 0, 2}, {0, 0, 90}}});
  REQUIRE(cap.ok());
  const Collider turned = cap->posed_at(1.0);
  CHECK(glm::length(turned.a - glm::dvec3(0, -1, 2)) < 1e-12);
  CHECK(glm::length(turned.b - glm::dvec3(0, 1, 2)) < 1e-12);
  auto floor = Collider::plane({0, 0, 1}, 0.0).with_keyframes({{0, {}, {}}, {1, {0, 0, 0.5}, {90, 0, 0}}});
  REQUIRE(floor.ok());
  const Collider wall = floor->posed_at(1.0);
  CHECK(glm::length(wall.normal - glm::dvec3(0, -1, 0)) < 1e-12);
  CHECK(std::abs(wall.offset) < 1e-12);            // the point (0, 0, 0.5) lies on y = 0
  CHECK(wall.angular_velocity == glm::dvec3(0.0)); // a plane takes linear velocity only
  // A plane given a normal of any length moves as its unit normal would (the scene normalises it).
  auto tall = Collider::plane({0, 0, 2}, 1.0).with_keyframes({{0, {}, {}}, {1, {0, 0, 1}, {}}});
  REQUIRE(tall.ok());
  CHECK(std::abs(tall->posed_at(1.0).offset - 2.0) < 1e-12);
  CHECK(glm::length(tall->posed_at(1.0).normal - glm::dvec3(0, 0, 1)) < 1e-12);
  // A slow turn keeps its axis: 1e-4 degrees about x over 10 s, advanced by 1/3000 s.
  auto slow = box.with_keyframes({{0, {}, {}}, {10, {}, {1e-4, 0, 0}}});
  REQUIRE(slow.ok());
  const glm::dvec3 w = slow->posed_at(1.0 / 3000.0).angular_velocity;
  CHECK(w.x == doctest::Approx(1e-4 * std::atan(1.0) / 45.0 / 10.0).epsilon(1e-6));
  CHECK(std::abs(w.y) + std::abs(w.z) < 1e-15);
  CHECK_FALSE(keyed->with_keyframes({{0, {}, {}}}).ok()); // one path per collider
  // A host's pose ends the path.
  ColliderPose still;
  CHECK(step.with_pose(still).path == nullptr);
}

TEST_CASE("keyframed collider: a box moving along its keys carries a resting particle by friction, every "
          "backend") {
  // The moving-box test below with the box's motion given by two keys (0.3 m/s for 10 s) instead of
  // a velocity: the path's velocity enters friction, on the CPU and the GPU.
  ValidationScope validation;
  std::vector<std::vector<glm::dvec3>> ends;
  for (Backend b : backends()) {
    CAPTURE(to_string(b));
    SimParams p = gravity_only();
    auto box = with_friction(Collider::box({0, 0, -0.5}, {5, 5, 0.5}), 1.0)
                   .with_keyframes({{0.0, {0, 0, 0}, {0, 0, 0}}, {10.0, {3, 0, 0}, {0, 0, 0}}});
    REQUIRE(box.ok());
    p.colliders = {*box};
    auto s = make_sim(b, particle({0, 0, 0.001}, {0, 0, 0}), p);
    REQUIRE(s->run(20).ok());
    CHECK(s->velocity(0).x == doctest::Approx(0.3).epsilon(1e-6));
    CHECK(s->position(0).x == doctest::Approx(0.3 * 20 * p.dt).epsilon(0.05));
    CHECK(std::abs(s->position(0).z - 0.001) < 1e-6);
    if (is_float(b))
      ends.push_back({s->position(0)});
  }
  for (std::size_t k = 1; k < ends.size(); ++k)
    CHECK(glm::length(ends[k][0] - ends[0][0]) < 1e-5); // GPU = CPU float
}

TEST_CASE(
    "keyframed collider: a cloth on a turning, rising capsule, GPU = CPU within 1e-5 m after 100 steps") {
  // A capsule under a small cloth turns 90 degrees and rises 0.2 m over 1 s, then holds
  // (both backends take the host's pose of each substep, Collider::posed_at).
  ValidationScope validation;
  ClothDesc d;
  d.nx = d.ny = 12;
  d.size = {0.6, 0.6};
  d.origin = {-0.3, -0.3, 0.15};
  d.orientation = ClothOrientation::horizontal;
  d.pin_default_corners = false;
  auto cloth = make_cloth(d);
  REQUIRE(cloth.ok());
  SimParams p;
  p.dt = 0.01;
  auto rod = with_friction(Collider::capsule({-0.4, 0, 0}, {0.4, 0, 0}, 0.1), 0.5)
                 .with_keyframes({{0.0, {0, 0, 0}, {0, 0, 0}}, {1.0, {0, 0, 0.2}, {0, 0, 90}}});
  REQUIRE(rod.ok());
  p.colliders = {*rod};
  std::vector<std::vector<glm::dvec3>> ends;
  for (Backend b : backends()) {
    CAPTURE(to_string(b));
    auto s = make_sim(b, *cloth, p);
    REQUIRE(s->run(100).ok());
    if (is_float(b)) // CPU float and Vulkan
      ends.push_back(s->positions());
  }
  REQUIRE(ends.size() == (backends().back() == Backend::vulkan ? 2u : 1u));
  double worst = 0.0;
  for (std::size_t k = 1; k < ends.size(); ++k)
    for (std::size_t i = 0; i < ends[0].size(); ++i)
      worst = std::max(worst, glm::length(ends[k][i] - ends[0][i]));
  MESSAGE("largest difference between backends: " << worst << " m");
  CHECK(worst < 1e-5);
}

TEST_CASE("a spinning sphere carries a particle on its top along its surface velocity") {
  // omega = (0, 2, 0) about the centre: the top of a 0.5 m sphere moves at omega x r = (1, 0, 0).
  ValidationScope validation;
  for (Backend b : backends()) {
    CAPTURE(to_string(b));
    SimParams p = gravity_only();
    Collider ball = with_friction(Collider::sphere({0, 0, 0}, 0.5), 1.0);
    ball.angular_velocity = {0, 2, 0};
    p.colliders = {ball};
    auto s = make_sim(b, particle({0, 0, 0.501}, {0, 0, 0}), p);
    REQUIRE(s->run(5).ok());
    CHECK(s->velocity(0).x > 0.8);
    CHECK(s->position(0).x > 0.02);
    CHECK(glm::length(s->position(0)) >= 0.5);
  }
}

TEST_CASE("cloth dropped on a capsule, a turned box and a mesh: no particle ever deeper than eps") {
  ValidationScope validation;
  ClothDesc d;
  d.nx = d.ny = 15;
  d.orientation = ClothOrientation::horizontal;
  d.origin = {-0.5, -0.5, 0.6};
  d.pin_default_corners = false;
  auto sys = make_cloth(d);
  REQUIRE(sys.ok());
  const Collider shapes[] = {
      Collider::capsule({-0.6, 0.1, 0.2}, {0.6, -0.1, 0.3}, 0.15),
      Collider::box({0.05, 0, 0.2}, {0.2, 0.3, 0.2}, Collider::rotation_from_degrees({10, 20, 30})),
      Collider::triangle_mesh(tetrahedron(), {0.05, 0.02, 0.0}, Collider::rotation_from_degrees({0, 0, 15}),
                              0.01)};
  for (const Collider& shape : shapes) {
    CAPTURE(int(shape.type));
    for (Backend b : backends()) {
      CAPTURE(to_string(b));
      SimParams p;
      p.substeps = 2;
      p.colliders = {with_friction(shape, 0.3)};
      auto s = make_sim(b, *sys, p);
      double deepest = std::numeric_limits<double>::infinity();
      int touching = 0;
      for (int block = 0; block < 40; ++block) {
        REQUIRE(s->run(5).ok());
        for (const glm::dvec3& x : s->positions()) {
          const double dist = distance_to(shape, x);
          deepest = std::min(deepest, dist);
          touching += dist < 2 * p.contact_epsilon;
        }
      }
      CHECK(deepest >= -p.contact_epsilon);
      CHECK(touching > 50); // it did land on the shape
    }
  }
}

TEST_CASE("a particle hitting a thin open mesh at 20 m/s does not pass through it") {
  // 0.4 m per step against a 5 mm shell: the step starts 5 cm above the sheet and would end 35 cm
  // below it; the projection searches as far as the particle moved and puts it back on its side.
  ValidationScope validation;
  const Collider s = Collider::triangle_mesh(sheet(8, 2.0), {0, 0, 0}, glm::dmat3(1.0), 0.005);
  for (Backend b : backends()) {
    CAPTURE(to_string(b));
    SimParams p = gravity_only();
    p.colliders = {s};
    auto sim = make_sim(b, particle({0.13, -0.27, 0.05}, {0, 0, -20}), p);
    for (int step = 0; step < 20; ++step) {
      REQUIRE(sim->step().ok());
      CHECK(sim->position(0).z >= 0.005); // above the shell after every step
    }
    CHECK(sim->velocity(0).z == doctest::Approx(0.0).scale(1.0)); // at rest on it
    // From below, the same sheet stops it going up.
    auto up = make_sim(b, particle({0.13, -0.27, -0.05}, {0, 0, 20}), p);
    REQUIRE(up->run(3).ok());
    CHECK(up->position(0).z <= -0.005);
  }
}
