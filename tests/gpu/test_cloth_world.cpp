// SPDX-License-Identifier: MIT
// Many cloths in a ClothWorld: shared topology, add / remove, per-instance parameters, one
// dispatch per pass for every instance of a topology, the fast projection and a diverging instance in
// a batch; each instance bitwise what it gives alone.
#include "gpu_test_util.hpp"
#include "vkcloth/gpu/testing.hpp"
#include "vkcloth/measure.hpp"

#include <cmath>
#include <cstddef>
#include <string>
#include <utility>
#include <vector>

namespace {

using namespace vkcloth;
using namespace vkcloth::gpu;
using vkcloth::gpu::test::diff;
using vkcloth::gpu::test::make_topology;

} // namespace

TEST_CASE("ClothWorld: many cloths, shared topology, add/remove, set_params == each alone, bitwise") {
  VKCLOTH_GPU_TEST_BEGIN(ctx);
  auto small = make_topology(7, 5);
  auto big = make_topology(13, 11);
  auto falling = make_topology(15, 13, true);
  SimParams p0;
  SimParams p1;
  p1.integrator = Integrator::rk4;
  p1.wind.strength = 0.05;
  p1.wind.direction = {1.0, 0.2, 0.0};
  p1.damping = 0.2;
  SimParams p2;
  p2.integrator = Integrator::explicit_euler;
  p2.dt = 0.005;
  SimParams p3;
  p3.colliders = {Collider::plane({0, 0, 1}, 0.0), Collider::sphere({0.05, 0.0, 0.15}, 0.15)};

  struct Case {
    std::shared_ptr<const ClothTopology> topo;
    SimParams params;
  };
  const Case cases[] = {{small, p0}, {small, p1}, {big, p2}, {falling, p3}}; // 0 and 1 share a topology
  auto world = ClothWorld::create(ctx);
  REQUIRE(world.ok());
  std::vector<InstanceId> ids;
  std::vector<GpuSolver> alone;
  for (const Case& c : cases) {
    auto id = world->add(c.topo, c.params);
    REQUIRE(id.ok());
    ids.push_back(*id);
    auto g = GpuSolver::create(ctx, c.topo, c.params);
    REQUIRE(g.ok());
    alone.push_back(std::move(g.value()));
  }
  CHECK(world->size() == 4);
  CHECK(world->topology(ids[0]) == world->topology(ids[1]));
  auto compare = [&](std::size_t k, const char* when) {
    const auto w = world->positions(ids[k]);
    const auto a = alone[k].positions();
    REQUIRE(w.ok());
    REQUIRE(a.ok());
    const auto d = diff(*w, *a);
    CHECK_MESSAGE(d.bitwise,
                  when << ": instance " << k << " differs from its own GpuSolver by " << d.max_abs);
    const auto wv = world->velocities(ids[k]);
    const auto av = alone[k].velocities();
    REQUIRE(wv.ok());
    REQUIRE(av.ok());
    CHECK(diff(*wv, *av).bitwise);
  };
  REQUIRE(world->simulate(15).ok());
  for (auto& g : alone)
    REQUIRE(g.simulate(15).ok());
  for (std::size_t k = 0; k < 4; ++k)
    compare(k, "after 15 steps");

  // Remove one at run time; the others keep their state and go on identically.
  REQUIRE(world->remove(ids[1]).ok());
  CHECK(world->remove(ids[1]).error().code == ErrorCode::invalid_argument);
  CHECK(!world->positions(ids[1]).ok());
  CHECK(world->size() == 3);
  // Parameters changed between steps take effect (same change on the standalone solver).
  SimParams windy = p0;
  windy.wind.strength = 0.1;
  windy.wind.direction = {0.0, 1.0, 0.0};
  windy.gravity = {0.0, 0.0, -5.0};
  REQUIRE(world->set_params(ids[0], windy).ok());
  REQUIRE(alone[0].set_params(windy).ok());
  CHECK(world->params(ids[0])->wind.strength == 0.1);
  // Add one at run time (with its own initial state).
  InitialState init;
  for (const Particle& q : small->system().particles)
    init.positions.push_back(q.position + glm::dvec3(0.0, 0.0, 0.25));
  auto late = world->add(small, p0, init);
  REQUIRE(late.ok());
  ParticleSystem moved = small->system();
  for (std::size_t p = 0; p < moved.particles.size(); ++p)
    moved.particles[p].position = init.positions[p];
  auto late_alone = GpuSolver::create(ctx, moved, p0);
  REQUIRE(late_alone.ok());

  REQUIRE(world->simulate(12, 5).ok());
  for (std::size_t k : {0u, 2u, 3u})
    REQUIRE(alone[k].simulate(12).ok());
  REQUIRE(late_alone->simulate(12).ok());
  for (std::size_t k : {0u, 2u, 3u})
    compare(k, "after remove + set_params + 12 steps");
  const auto wl = world->positions(*late);
  const auto al = late_alone->positions();
  REQUIRE(wl.ok());
  REQUIRE(al.ok());
  CHECK(diff(*wl, *al).bitwise);
  // The parameter change mattered: the instance no longer matches the unchanged parameters.
  auto unchanged = GpuSolver::create(ctx, small, p0);
  REQUIRE(unchanged.ok());
  REQUIRE(unchanged->simulate(27).ok());
  CHECK(!diff(*world->positions(ids[0]), *unchanged->positions()).bitwise);

  // Buffers for drawing.
  const auto bufs = world->buffers(ids[3]);
  REQUIRE(bufs.ok());
  CHECK(bufs->count == 15u * 13u);
  CHECK(bufs->offset == 0); // alone in its batch
  CHECK(bufs->nx == 15u);
  CHECK(grid_triangle_indices(bufs->nx, bufs->ny).size() == 14u * 12u * 6u);
  CHECK(!world->add(nullptr, p0).ok());
  InitialState wrong;
  wrong.positions.resize(3);
  CHECK(world->add(small, p0, wrong).error().code == ErrorCode::invalid_argument);
}

namespace {

/// Euler parameters that differ in every per-instance field the shaders read.
std::vector<SimParams> varied_euler_params() {
  std::vector<SimParams> out(6);
  out[1].integrator = Integrator::explicit_euler;
  out[1].dt = 0.004;
  out[2].damping = 0.5;
  out[2].wind.strength = 0.08;
  out[2].wind.direction = {0.2, 1.0, 0.3};
  out[3].gravity = {0.5, 0.0, -4.0};
  out[3].colliders = {Collider::sphere({0.1, 0.05, -0.3}, 0.2)};
  out[4].colliders = {Collider::plane({0, 0, 1}, -0.35), Collider::sphere({-0.1, 0.0, -0.2}, 0.12)};
  out[4].contact_inward_only = false;
  out[5].dt = 0.02;
  out[5].wind.strength = 0.03;
  return out;
}

} // namespace

TEST_CASE(
    "ClothWorld batches: one dispatch per pass for every instance of a topology, each bitwise == alone") {
  VKCLOTH_GPU_TEST_BEGIN(ctx);
  auto topo = make_topology(12, 9);
  const std::vector<SimParams> params = varied_euler_params();
  auto world = ClothWorld::create(ctx);
  REQUIRE(world.ok());
  std::vector<InstanceId> ids;
  std::vector<GpuSolver> alone;
  for (std::size_t k = 0; k < params.size(); ++k) {
    InitialState init; // instance k starts k cm higher: distinct states in one batch
    for (const Particle& q : topo->system().particles)
      init.positions.push_back(q.position + glm::dvec3(0.0, 0.0, 0.01 * double(k)));
    auto id = world->add(topo, params[k], init);
    REQUIRE(id.ok());
    ids.push_back(*id);
    ParticleSystem moved = topo->system();
    for (std::size_t p = 0; p < moved.particles.size(); ++p)
      moved.particles[p].position = init.positions[p];
    auto g = GpuSolver::create(ctx, moved, params[k]);
    REQUIRE(g.ok());
    alone.push_back(std::move(g.value()));
  }
  CHECK(world->batch_count() == 1); // explicit and semi-implicit Euler share the batch
  auto compare = [&](std::size_t k, const char* when) {
    const auto w = world->positions(ids[k]);
    const auto a = alone[k].positions();
    REQUIRE(w.ok());
    REQUIRE(a.ok());
    const auto d = diff(*w, *a);
    CHECK_MESSAGE(d.bitwise,
                  when << ": instance " << k << " differs from its own GpuSolver by " << d.max_abs);
    CHECK(diff(*world->velocities(ids[k]), *alone[k].velocities()).bitwise);
    CHECK(diff(*world->normals(ids[k]), *alone[k].normals()).bitwise);
  };

  const std::uint64_t before = world->dispatches_recorded();
  REQUIRE(world->simulate(25, 10).ok());
  CHECK(world->dispatches_recorded() - before == 25); // one fused dispatch per step for 6 cloths
  for (auto& g : alone)
    REQUIRE(g.simulate(25).ok());
  for (std::size_t k = 0; k < ids.size(); ++k)
    compare(k, "after 25 batched steps");
  CHECK(world->step_index(ids[0]) == 25);

  // Drawing: one set of buffers, each instance at its own offset.
  const auto b0 = world->buffers(ids[0]);
  const auto b3 = world->buffers(ids[3]);
  REQUIRE(b0.ok());
  REQUIRE(b3.ok());
  CHECK(b0->positions == b3->positions);
  CHECK(b3->offset == 3 * VkDeviceSize(topo->size()) * GpuSolver::stride);
  CHECK(b3->indices != VK_NULL_HANDLE);
  CHECK(b3->index_count == grid_triangle_indices(12, 9).size());

  // Remove one from the middle, add one: the batch is rebuilt, the others go on bit for bit.
  REQUIRE(world->remove(ids[2]).ok());
  auto late = world->add(topo, params[2]);
  REQUIRE(late.ok());
  auto late_alone = GpuSolver::create(ctx, topo, params[2]);
  REQUIRE(late_alone.ok());
  CHECK(world->batch_count() == 1);
  // set_params within the batch (new wind, new colliders) and across batches (to RK4).
  SimParams changed = params[0];
  changed.wind.strength = 0.06;
  changed.colliders = {Collider::plane({0, 0, 1}, -0.3)};
  REQUIRE(world->set_params(ids[0], changed).ok());
  REQUIRE(alone[0].set_params(changed).ok());
  SimParams rk = params[5];
  rk.integrator = Integrator::rk4;
  REQUIRE(world->set_params(ids[5], rk).ok());
  REQUIRE(alone[5].set_params(rk).ok());
  CHECK(world->batch_count() == 2);

  const std::uint64_t before2 = world->dispatches_recorded();
  REQUIRE(world->simulate(10).ok());
  CHECK(world->dispatches_recorded() - before2 ==
        10 * (1 + 8)); // Euler batch + RK4 batch (2 passes x 4 stages)
  for (std::size_t k : {0u, 1u, 3u, 4u, 5u})
    REQUIRE(alone[k].simulate(10).ok());
  REQUIRE(late_alone->simulate(10).ok());
  for (std::size_t k : {0u, 1u, 3u, 4u, 5u})
    compare(k, "after rebuilds + 10 steps");
  CHECK(diff(*world->positions(*late), *late_alone->positions()).bitwise);
  CHECK(world->step_index(ids[0]) == 35);
  CHECK(world->step_index(*late) == 10);
}

TEST_CASE("ClothWorld batches: instances with and without the fast projection, Provot's sweeps in colours or "
          "in chains, each bitwise == alone") {
  // One batch of a topology: the fast projection (two Newton budgets), the sweeps, nothing, the
  // sweeps in chain order (two budgets). The projection's dispatches serve every instance of the
  // batch (one workgroup each) and end when the last projecting instance is done; the others skip
  // them. The colours' and the chains' dispatches each skip the instances of the other order.
  VKCLOTH_GPU_TEST_BEGIN(ctx);
  auto topo = make_topology(12, 9);
  std::vector<SimParams> params(6);
  params[4].stretch_limit.method = StretchLimit::Method::provot;
  params[4].stretch_limit.order = StretchLimit::SweepOrder::chains;
  params[4].stretch_limit.max_strain = 0.002;
  params[5] = params[4];
  params[5].stretch_limit.iterations = 9;
  params[0].stretch_limit.method = StretchLimit::Method::projection;
  params[0].stretch_limit.max_strain = 0.002;
  params[1] = params[0];
  params[1].stretch_limit.iterations = 10;
  params[1].colliders = {Collider::sphere({0.1, 0.05, -0.3}, 0.2)};
  params[2].stretch_limit.method = StretchLimit::Method::both;
  params[2].stretch_limit.max_strain = 0.002;
  auto world = ClothWorld::create(ctx);
  REQUIRE(world.ok());
  std::vector<InstanceId> ids;
  std::vector<GpuSolver> alone;
  for (const SimParams& p : params) {
    auto id = world->add(topo, p);
    REQUIRE(id.ok());
    ids.push_back(*id);
    auto g = GpuSolver::create(ctx, topo, p);
    REQUIRE(g.ok());
    alone.push_back(std::move(g.value()));
  }
  CHECK(world->batch_count() == 1);
  REQUIRE(world->simulate(30).ok());
  for (auto& g : alone)
    REQUIRE(g.simulate(30).ok());
  for (std::size_t k = 0; k < ids.size(); ++k) {
    const auto d = diff(*world->positions(ids[k]), *alone[k].positions());
    CHECK_MESSAGE(d.bitwise, "instance " << k << " differs from its own GpuSolver by " << d.max_abs);
  }
  // The projection acted: instance 0 holds its links within 0.2 % (+1e-4), instance 3 (no limit) does not.
  const auto strain = [&](std::size_t k) {
    const auto x = world->positions(ids[k]);
    REQUIRE(x.ok());
    std::vector<glm::dvec3> wide(x->size());
    for (std::size_t q = 0; q < x->size(); ++q)
      wide[q] = glm::dvec3((*x)[q]);
    const auto s = structural_strain(topo->system(), wide);
    REQUIRE(s.ok());
    return s->max;
  };
  CHECK(strain(0) < 0.002 + 2e-4);
  CHECK(strain(3) > 0.004);
  MESSAGE("largest strain: colours " << strain(2) << ", none " << strain(3) << ", chains x 4 " << strain(4)
                                     << ", chains x 9 " << strain(5));
  CHECK(strain(4) < strain(3)); // the chains acted
  CHECK(strain(5) < strain(4)); // and 9 sweeps more than 4
}

TEST_CASE("ClothWorld batches: a diverging instance is frozen and named, the others go on") {
  VKCLOTH_GPU_TEST_BEGIN(ctx);
  auto topo = make_topology(9, 7);
  SimParams calm;
  SimParams wild; // explicit Euler far past its stability limit
  wild.integrator = Integrator::explicit_euler;
  wild.dt = 0.5;
  auto world = ClothWorld::create(ctx);
  REQUIRE(world.ok());
  auto a = world->add(topo, calm);
  auto b = world->add(topo, wild);
  auto c = world->add(topo, calm);
  REQUIRE(a.ok());
  REQUIRE(b.ok());
  REQUIRE(c.ok());
  CHECK(world->batch_count() == 1);
  auto wild_alone = GpuSolver::create(ctx, topo, wild);
  REQUIRE(wild_alone.ok());
  const auto alone_result = wild_alone->simulate(40, 40);
  REQUIRE(!alone_result.ok());
  auto calm_alone = GpuSolver::create(ctx, topo, calm);
  REQUIRE(calm_alone.ok());
  REQUIRE(calm_alone->simulate(40).ok());

  const auto r = world->simulate(40, 40); // one submission: the others finish their 40 steps
  REQUIRE(!r.ok());
  CHECK(r.error().code == ErrorCode::diverged);
  CHECK_MESSAGE(r.error().message.find("cloth instance " + std::to_string(*b)) != std::string::npos,
                r.error().message);
  CHECK(world->step_index(*b) == wild_alone->step_index());             // the same first bad step
  CHECK(diff(*world->positions(*b), *wild_alone->positions()).bitwise); // frozen as after that step
  CHECK(diff(*world->positions(*a), *calm_alone->positions()).bitwise);
  CHECK(diff(*world->positions(*c), *calm_alone->positions()).bitwise);
  // Removing the healthy neighbour rebuilds the batch: the diverged one stays frozen and reported.
  REQUIRE(world->remove(*a).ok());
  const auto frozen_at = *world->positions(*b);
  const auto again = world->check_divergence();
  REQUIRE(!again.ok());
  CHECK(world->step_index(*b) == wild_alone->step_index());
  CHECK(diff(*world->positions(*b), frozen_at).bitwise);
}
