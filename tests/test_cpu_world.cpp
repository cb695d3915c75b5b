// SPDX-License-Identifier: MIT
// CpuWorld (cpu_world.hpp): many cloths on the CPU with ClothWorld's shape. Each instance is a
// CpuSolver<float>, so every check here is bitwise against standalone solvers given the same
// inputs: two instances of one topology, remove, set_params / set_step_params, an initial
// state, and a divergence that freezes and names one instance while the others go on.
#include <doctest/doctest.h>

#include <glm/geometric.hpp>

#include <cstring>
#include <limits>
#include <string>
#include <vector>

#include "vkcloth/vkcloth.hpp"

using namespace vkcloth;

namespace {

std::shared_ptr<const ClothTopology> topology_of(std::uint32_t nx, std::uint32_t ny) {
  ClothDesc d;
  d.nx = nx;
  d.ny = ny;
  auto s = make_cloth(d);
  REQUIRE(s.ok());
  auto t = ClothTopology::create(*s);
  REQUIRE(t.ok());
  return *t;
}

CpuSolver<float> solver_of(std::shared_ptr<const ClothTopology> topology, const SimParams& params) {
  auto s = CpuSolver<float>::create(std::move(topology), params);
  REQUIRE(s.ok());
  return std::move(*s);
}

bool same_bits(std::span<const glm::vec3> a, std::span<const glm::vec3> b) {
  return a.size() == b.size() && std::memcmp(a.data(), b.data(), a.size_bytes()) == 0;
}

/// The world's instance `id` has the bits of `alone`: positions, velocities, normals, step.
void check_same_as(CpuWorld& world, InstanceId id, const CpuSolver<float>& alone) {
  CAPTURE(id);
  const auto p = world.positions(id);
  const auto v = world.velocities(id);
  const auto n = world.normals(id);
  REQUIRE(p.ok());
  REQUIRE(v.ok());
  REQUIRE(n.ok());
  CHECK(same_bits(*p, alone.positions()));
  CHECK(same_bits(*v, alone.velocities()));
  CHECK(same_bits(*n, alone.normals()));
  CHECK(world.step_index(id) == alone.step_index());
}

SimParams windy() {
  SimParams p;
  p.integrator = Integrator::rk4;
  p.damping = 0.2;
  p.wind.strength = 0.05;
  p.wind.direction = {1.0, 0.2, 0.0};
  p.colliders = {Collider::sphere({0.05, 0.0, -0.3}, 0.2)};
  return p;
}

bool contains(const std::string& text, const std::string& part) {
  return text.find(part) != std::string::npos;
}

} // namespace

TEST_CASE("CpuWorld: two instances of one topology, different params == two CpuSolver<float>, bitwise") {
  auto topo = topology_of(13, 9);
  const SimParams p0;
  const SimParams p1 = windy();
  auto world = CpuWorld::create();
  REQUIRE(world.ok());
  auto a = world->add(topo, p0);
  auto b = world->add(topo, p1);
  REQUIRE(a.ok());
  REQUIRE(b.ok());
  CHECK(*a != *b);
  CHECK(world->size() == 2);
  CHECK(world->instances() == std::vector<InstanceId>{*a, *b});
  CHECK(world->topology(*a) == topo); // shared, not copied
  CHECK(world->topology(*b) == topo);
  CHECK(world->params(*b)->integrator == Integrator::rk4);

  CpuSolver<float> alone_a = solver_of(topo, p0);
  CpuSolver<float> alone_b = solver_of(topo, p1);
  check_same_as(*world, *a, alone_a); // the start: the topology's state
  REQUIRE(world->simulate(40).ok());
  REQUIRE(alone_a.run(40).ok());
  REQUIRE(alone_b.run(40).ok());
  check_same_as(*world, *a, alone_a);
  check_same_as(*world, *b, alone_b);
  // steps_per_submit is ignored: 3 steps in "submissions" of 1 are 3 steps.
  REQUIRE(world->simulate(3, 1).ok());
  REQUIRE(alone_a.run(3).ok());
  REQUIRE(alone_b.run(3).ok());
  check_same_as(*world, *a, alone_a);
  check_same_as(*world, *b, alone_b);
  // The two differ from each other (the params mattered).
  CHECK(!same_bits(*world->positions(*a), *world->positions(*b)));
  // The solver accessor reads the same state without a copy.
  REQUIRE(world->solver(*b) != nullptr);
  CHECK(same_bits(world->solver(*b)->positions(), alone_b.positions()));
  CHECK(world->solver(*b)->time() == alone_b.time());
}

TEST_CASE("CpuWorld: remove keeps the others' state, unknown ids are errors naming the id") {
  auto topo = topology_of(9, 7);
  const SimParams p0;
  auto world = CpuWorld::create();
  REQUIRE(world.ok());
  auto a = world->add(topo, p0);
  auto b = world->add(topo, windy());
  auto c = world->add(topo, p0);
  REQUIRE(a.ok());
  REQUIRE(b.ok());
  REQUIRE(c.ok());
  CpuSolver<float> alone = solver_of(topo, p0);
  REQUIRE(world->simulate(10).ok());
  REQUIRE(alone.run(10).ok());

  REQUIRE(world->remove(*b).ok());
  CHECK(world->size() == 2);
  CHECK(world->instances() == std::vector<InstanceId>{*a, *c});
  check_same_as(*world, *a, alone);
  check_same_as(*world, *c, alone);
  REQUIRE(world->simulate(10).ok());
  REQUIRE(alone.run(10).ok());
  check_same_as(*world, *a, alone);
  check_same_as(*world, *c, alone);
  // Ids are never reused.
  auto d = world->add(topo, p0);
  REQUIRE(d.ok());
  CHECK(*d != *b);

  const std::string named = "no cloth instance with id " + std::to_string(*b);
  const auto removed = world->remove(*b);
  REQUIRE(!removed.ok());
  CHECK(removed.error().code == ErrorCode::invalid_argument);
  CHECK_MESSAGE(contains(removed.error().message, named), removed.error().message);
  const auto pos = world->positions(*b);
  REQUIRE(!pos.ok());
  CHECK(pos.error().code == ErrorCode::invalid_argument);
  CHECK(contains(pos.error().message, named));
  CHECK(world->velocities(*b).error().code == ErrorCode::invalid_argument);
  CHECK(world->normals(*b).error().code == ErrorCode::invalid_argument);
  CHECK(world->params(*b).error().code == ErrorCode::invalid_argument);
  CHECK(world->set_params(*b, p0).error().code == ErrorCode::invalid_argument);
  CHECK(world->set_step_params(*b, StepParams{}).error().code == ErrorCode::invalid_argument);
  CHECK(world->set_particle(*b, 0, glm::vec3(0.0f), glm::vec3(0.0f)).error().code ==
        ErrorCode::invalid_argument);
  CHECK(world->step_index(*b) == 0);
  CHECK(world->topology(*b) == nullptr);
  CHECK(world->solver(*b) == nullptr);
  // The others were not touched by the failed calls.
  check_same_as(*world, *a, alone);

  // Other argument errors.
  CHECK(world->add(nullptr, p0).error().code == ErrorCode::invalid_argument);
  SimParams bad;
  bad.dt = -1.0;
  CHECK(world->add(topo, bad).error().code == ErrorCode::invalid_argument);
  CHECK(world->set_params(*a, bad).error().code == ErrorCode::invalid_argument);
  CHECK(world->params(*a)->dt == p0.dt); // the old parameters stay
  CHECK(world->set_particle(*a, 9999, glm::vec3(0.0f), glm::vec3(0.0f)).error().code ==
        ErrorCode::invalid_argument);
  CpuWorldOptions too_many;
  too_many.solver.threads = 1000;
  CHECK(CpuWorld::create(too_many).error().code == ErrorCode::invalid_argument);
}

TEST_CASE("CpuWorld: set_params and set_step_params apply as CpuSolver::set_params would, bitwise") {
  auto topo = topology_of(11, 8);
  const SimParams p0;
  auto world = CpuWorld::create();
  REQUIRE(world.ok());
  auto a = world->add(topo, p0);
  auto b = world->add(topo, p0);
  REQUIRE(a.ok());
  REQUIRE(b.ok());
  CpuSolver<float> alone = solver_of(topo, p0);
  CpuSolver<float> unchanged = solver_of(topo, p0);
  REQUIRE(world->simulate(8).ok());
  REQUIRE(alone.run(8).ok());
  REQUIRE(unchanged.run(8).ok());

  // A frame's per-frame parameters on instance a only.
  StepParams step;
  step.gravity = glm::dvec3(2.0, 0.0, -4.0);
  step.dt = 0.008;
  step.colliders = std::vector<Collider>{Collider::sphere({0.0, 0.1, -0.4}, 0.25)};
  REQUIRE(world->set_step_params(*a, step).ok());
  REQUIRE(alone.set_params(step.applied_to(alone.params())).ok());
  CHECK(world->params(*a)->gravity == glm::dvec3(2.0, 0.0, -4.0));
  CHECK(world->params(*a)->dt == 0.008);
  CHECK(world->params(*b)->gravity == p0.gravity); // b keeps its own
  REQUIRE(world->simulate(20).ok());
  REQUIRE(alone.run(20).ok());
  REQUIRE(unchanged.run(20).ok());
  check_same_as(*world, *a, alone);
  check_same_as(*world, *b, unchanged);
  CHECK(!same_bits(*world->positions(*a), unchanged.positions())); // the change mattered

  // A whole SimParams, integrator included: the state carries over.
  SimParams implicit = p0;
  implicit.integrator = Integrator::implicit_euler;
  implicit.dt = 0.02;
  REQUIRE(world->set_params(*b, implicit).ok());
  REQUIRE(unchanged.set_params(implicit).ok());
  REQUIRE(world->simulate(5).ok());
  REQUIRE(alone.run(5).ok());
  REQUIRE(unchanged.run(5).ok());
  check_same_as(*world, *a, alone);
  check_same_as(*world, *b, unchanged);
  // An invalid step leaves the parameters as they were.
  StepParams bad;
  bad.dt = 0.0;
  CHECK(world->set_step_params(*a, bad).error().code == ErrorCode::invalid_argument);
  CHECK(world->params(*a)->dt == 0.008);
}

TEST_CASE("CpuWorld: an initial state starts there, wrong sizes are errors naming both counts") {
  auto topo = topology_of(7, 5); // 35 particles
  const SimParams p0;
  auto world = CpuWorld::create();
  REQUIRE(world.ok());

  InitialState wrong;
  wrong.positions.resize(3);
  const auto r = world->add(topo, p0, wrong);
  REQUIRE(!r.ok());
  CHECK(r.error().code == ErrorCode::invalid_argument);
  CHECK_MESSAGE(contains(r.error().message, "initial positions has 3 entries, the topology 35 particles"),
                r.error().message);
  InitialState wrong_v;
  wrong_v.velocities.resize(36);
  const auto rv = world->add(topo, p0, wrong_v);
  REQUIRE(!rv.ok());
  CHECK_MESSAGE(contains(rv.error().message, "initial velocities has 36 entries, the topology 35 particles"),
                rv.error().message);
  InitialState not_finite;
  not_finite.positions.assign(35, glm::dvec3(0.0));
  not_finite.positions[4].y = std::numeric_limits<double>::infinity();
  const auto rn = world->add(topo, p0, not_finite);
  REQUIRE(!rn.ok());
  CHECK(rn.error().code == ErrorCode::invalid_argument);
  CHECK_MESSAGE(contains(rn.error().message, "initial state"), rn.error().message);
  CHECK_MESSAGE(contains(rn.error().message, "particle 4"), rn.error().message);
  CHECK(world->size() == 0); // nothing added by the failed calls

  // Positions 0.25 higher and a velocity: the same as a solver of the moved system.
  InitialState init;
  ParticleSystem moved = topo->system();
  for (Particle& q : moved.particles) {
    q.position += glm::dvec3(0.0, 0.0, 0.25);
    q.velocity = glm::dvec3(0.1, -0.2, 0.3);
    init.positions.push_back(q.position);
    init.velocities.push_back(q.velocity);
  }
  auto id = world->add(topo, p0, init);
  REQUIRE(id.ok());
  const auto start = world->positions(*id);
  REQUIRE(start.ok());
  for (std::size_t p = 0; p < start->size(); ++p)
    CHECK((*start)[p] == glm::vec3(init.positions[p]));
  const auto v0 = world->velocities(*id);
  REQUIRE(v0.ok());
  for (std::size_t p = 0; p < v0->size(); ++p) // pinned particles start at rest
    CHECK((*v0)[p] == (moved.particles[p].pinned ? glm::vec3(0.0f) : glm::vec3(0.1f, -0.2f, 0.3f)));
  auto alone = CpuSolver<float>::create(moved, p0);
  REQUIRE(alone.ok());
  check_same_as(*world, *id, *alone);
  REQUIRE(world->simulate(30).ok());
  REQUIRE(alone->run(30).ok());
  check_same_as(*world, *id, *alone);

  // Positions only: the topology's velocities (zero).
  InitialState only_positions;
  only_positions.positions = init.positions;
  auto id2 = world->add(topo, p0, only_positions);
  REQUIRE(id2.ok());
  const auto v2 = world->velocities(*id2);
  REQUIRE(v2.ok());
  for (const glm::vec3& v : *v2)
    CHECK(v == glm::vec3(0.0f));
}

TEST_CASE("CpuWorld: a diverging instance is frozen and named, the others go on") {
  auto topo = topology_of(9, 7);
  SimParams calm;
  SimParams wild; // explicit Euler far past its stability limit (as the ClothWorld test)
  wild.integrator = Integrator::explicit_euler;
  wild.dt = 0.5;
  auto world = CpuWorld::create();
  REQUIRE(world.ok());
  auto a = world->add(topo, calm);
  auto b = world->add(topo, wild);
  auto c = world->add(topo, calm);
  REQUIRE(a.ok());
  REQUIRE(b.ok());
  REQUIRE(c.ok());
  CpuSolver<float> wild_alone = solver_of(topo, wild);
  const auto alone_result = wild_alone.run(40);
  REQUIRE(!alone_result.ok());
  CpuSolver<float> calm_alone = solver_of(topo, calm);
  REQUIRE(calm_alone.run(40).ok());

  const auto r = world->simulate(40);
  REQUIRE(!r.ok());
  CHECK(r.error().code == ErrorCode::diverged);
  // "cloth instance 2: <the solver's message, with the step and time>"
  CHECK_MESSAGE(r.error().message ==
                    "cloth instance " + std::to_string(*b) + ": " + alone_result.error().message,
                r.error().message);
  CHECK(contains(r.error().message, "at step"));
  CHECK(world->step_index(*b) == wild_alone.step_index()); // the first bad step
  CHECK(world->step_index(*b) < 40);
  check_same_as(*world, *b, wild_alone); // frozen as after that step
  check_same_as(*world, *a, calm_alone); // the others did their 40 steps
  check_same_as(*world, *c, calm_alone);
  CHECK(world->check_divergence().error().code == ErrorCode::diverged);

  // Later steps: still reported, b stays where it stopped, a and c go on.
  const auto again = world->simulate(5);
  REQUIRE(!again.ok());
  CHECK(again.error().message == r.error().message);
  REQUIRE(calm_alone.run(5).ok());
  check_same_as(*world, *b, wild_alone);
  check_same_as(*world, *a, calm_alone);
  check_same_as(*world, *c, calm_alone);
  // Removing the diverged instance clears the report.
  REQUIRE(world->remove(*b).ok());
  CHECK(world->check_divergence().ok());
  CHECK(world->simulate(1).ok());
}

TEST_CASE("Collider::with_pose: each shape moved and turned as ColliderPose says, the rest kept") {
  const glm::dmat3 quarter_x(glm::dvec3(1, 0, 0), glm::dvec3(0, 0, 1), glm::dvec3(0, -1, 0)); // z -> -y
  ColliderPose pose;
  pose.position = {1.0, 2.0, 3.0};
  pose.linear_velocity = {0.5, 0.0, 0.0};
  pose.angular_velocity = {0.0, 0.0, 2.0};

  Collider sphere = Collider::sphere({0, 0, 0}, 0.3);
  sphere.friction = 0.8;
  const Collider s = sphere.with_pose(pose);
  CHECK(s.center == pose.position);
  CHECK(s.radius == 0.3);
  CHECK(s.friction == 0.8);
  CHECK(s.linear_velocity == pose.linear_velocity);
  CHECK(s.angular_velocity == pose.angular_velocity);

  const Collider capsule = Collider::capsule({0, 0, -0.5}, {0, 0, 0.5}, 0.1);
  const Collider moved = capsule.with_pose(pose); // no rotation: only moved
  CHECK(moved.a == glm::dvec3(1.0, 2.0, 2.5));
  CHECK(moved.b == glm::dvec3(1.0, 2.0, 3.5));
  pose.rotation = quarter_x; // the axis becomes the rotation's third column, its length kept
  const Collider turned = capsule.with_pose(pose);
  CHECK(glm::length(turned.a - glm::dvec3(1.0, 2.5, 3.0)) < 1e-15);
  CHECK(glm::length(turned.b - glm::dvec3(1.0, 1.5, 3.0)) < 1e-15);

  const Collider box = Collider::box({0, 0, 0}, {0.1, 0.2, 0.3}).with_pose(pose);
  CHECK(box.center == pose.position);
  CHECK(box.rotation == quarter_x);
  CHECK(box.half_extents == glm::dvec3(0.1, 0.2, 0.3));

  pose.angular_velocity = {};
  const Collider plane = Collider::plane({0, 0, 2}, 1.0).with_pose(pose); // normal -> -y, through (1, 2, 3)
  CHECK(glm::length(plane.normal - glm::dvec3(0, -1, 0)) < 1e-15);
  CHECK(plane.offset == doctest::Approx(-2.0));
  pose.rotation.reset();
  const Collider level = Collider::plane({0, 0, 2}, 1.0).with_pose(pose); // an unnormalised normal
  CHECK(level.offset == doctest::Approx(3.0)); // along the unit normal, as validate() reads it

  // with_collider_pose: the index and the pose are checked, the errors name them.
  SimParams p;
  p.colliders = {sphere};
  auto r = with_collider_pose(p, 1, pose);
  REQUIRE_FALSE(r.ok());
  CHECK_MESSAGE(r.error().message.find("colliders[1]: no such collider to pose, the cloth has 1 collider") !=
                    std::string::npos,
                r.error().message);
  pose.linear_velocity.y = std::numeric_limits<double>::infinity();
  r = with_collider_pose(p, 0, pose);
  REQUIRE_FALSE(r.ok());
  CHECK_MESSAGE(r.error().message.find("pose.linear_velocity") != std::string::npos, r.error().message);
  pose.linear_velocity.y = 0.0;
  r = with_collider_pose(p, 0, pose);
  REQUIRE(r.ok());
  CHECK(r->colliders[0].center == pose.position);
  CHECK(r->colliders[0].friction == 0.8);
}

TEST_CASE("a solver's positions keep their address across steps (a host's or numpy's view stays valid)") {
  // The explicit sweep, the SIMD row sweep (a grid) and vbd each swap their position buffers inside
  // a step; after any number of steps positions() is where it was, and its values are the steps'.
  for (const Integrator integrator : {Integrator::semi_implicit_euler, Integrator::rk4, Integrator::vbd}) {
    CAPTURE(to_string(integrator));
    SimParams p;
    p.integrator = integrator;
    p.dt = 0.01;
    auto topology = topology_of(17, 13);
    CpuSolver<float> solver = solver_of(topology, p);
    CpuSolver<float> reference = solver_of(topology, p);
    const glm::vec3* home = solver.positions().data();
    for (const std::uint64_t steps : {1, 2, 3}) {
      REQUIRE(solver.run(steps).ok());
      for (std::uint64_t s = 0; s < steps; ++s)
        REQUIRE(reference.step().ok());
      CHECK(solver.positions().data() == home);
      CHECK(same_bits(solver.positions(), reference.positions()));
    }
  }
}
