// SPDX-License-Identifier: MIT
// One host, two backends: the host code below is written once, as a template over the world type,
// and run with vkcloth::CpuWorld and vkcloth::gpu::ClothWorld (only their create() differs). The
// two agree within gpu_cpu_tolerance (gpu_test_util.hpp) for the same scenes (1e-5 on positions after
// 100 steps; bit-identical on lavapipe, reported), and a divergence is reported the same way.
#include "gpu_test_util.hpp"

#include <string>

#include <fmt/format.h>

using namespace vkcloth;
using vkcloth::gpu::test::diff;
using vkcloth::gpu::test::Diff;
using vkcloth::gpu::test::gpu_cpu_tolerance;

namespace {

std::shared_ptr<const ClothTopology> topology_of(ClothDesc d) {
  auto s = make_cloth(d);
  REQUIRE(s.ok());
  auto t = ClothTopology::create(*s);
  REQUIRE(t.ok());
  return *t;
}

/// What the host read back at the end, per instance it kept.
struct Readback {
  std::vector<std::vector<glm::vec3>> positions, velocities, normals;
  std::vector<std::uint64_t> steps;
};

/// A host's frame loop, written once for any world: three cloths (a hanging one in a wind that
/// changes every frame, a horizontal one falling from its own initial height on a plane and a
/// sphere, one removed halfway), 30 frames of 2 steps, then 40 more steps.
template <typename World> Readback host_frames(World& world) {
  ClothDesc hanging_desc;
  hanging_desc.nx = 13;
  hanging_desc.ny = 11;
  auto hanging_topo = topology_of(hanging_desc);
  ClothDesc falling_desc;
  falling_desc.nx = 15;
  falling_desc.ny = 13;
  falling_desc.orientation = ClothOrientation::horizontal;
  falling_desc.origin = {-0.5, -0.5, 0.25};
  falling_desc.pin_default_corners = false;
  auto falling_topo = topology_of(falling_desc);

  SimParams windy;
  windy.integrator = Integrator::rk4;
  windy.wind.strength = 0.03;
  windy.wind.direction = {1.0, 0.3, 0.0};
  SimParams falling;
  falling.colliders = {Collider::plane({0, 0, 1}, 0.0), Collider::sphere({0.05, 0.0, 0.15}, 0.15)};
  InitialState higher; // the backend-neutral vkcloth::InitialState
  for (const Particle& q : falling_topo->system().particles)
    higher.positions.push_back(q.position + glm::dvec3(0.0, 0.0, 0.05));

  auto a = world.add(hanging_topo, windy);
  auto b = world.add(falling_topo, falling, higher);
  auto c = world.add(hanging_topo, SimParams{});
  REQUIRE(a.ok());
  REQUIRE(b.ok());
  REQUIRE(c.ok());
  for (int frame = 0; frame < 30; ++frame) {
    StepParams step; // the host's per-frame wind and gravity
    Wind w = windy.wind;
    w.strength = 0.03 * (1.0 + std::cos(0.4 * frame));
    step.wind = w;
    step.gravity = glm::dvec3(0.5 * std::sin(0.3 * frame), 0.0, -9.81);
    REQUIRE(world.set_step_params(*a, step).ok());
    const auto r = world.simulate(2);
    REQUIRE_MESSAGE(r.ok(), (r.ok() ? "" : r.error().message));
    if (frame == 14)
      REQUIRE(world.remove(*c).ok());
  }
  REQUIRE(world.size() == 2);
  REQUIRE(world.simulate(40, 16).ok());
  REQUIRE(world.check_divergence().ok());

  Readback out;
  for (InstanceId id : world.instances()) {
    auto p = world.positions(id);
    auto v = world.velocities(id);
    auto n = world.normals(id);
    REQUIRE(p.ok());
    REQUIRE(v.ok());
    REQUIRE(n.ok());
    out.positions.push_back(std::move(*p));
    out.velocities.push_back(std::move(*v));
    out.normals.push_back(std::move(*n));
    out.steps.push_back(world.step_index(id));
  }
  return out;
}

/// The same host with a cloth that blows up between two calm ones: the error names it, it stops
/// at its first bad step, the others do all their steps. Returns the bad step.
template <typename World> std::uint64_t host_divergence(World& world) {
  ClothDesc d;
  d.nx = 9;
  d.ny = 7;
  auto topo = topology_of(d);
  SimParams wild; // explicit Euler far past its stability limit
  wild.integrator = Integrator::explicit_euler;
  wild.dt = 0.5;
  auto a = world.add(topo, SimParams{});
  auto b = world.add(topo, wild);
  auto c = world.add(topo, SimParams{});
  REQUIRE(a.ok());
  REQUIRE(b.ok());
  REQUIRE(c.ok());
  const auto r = world.simulate(40, 40);
  REQUIRE(!r.ok());
  CHECK(r.error().code == ErrorCode::diverged);
  CHECK_MESSAGE(r.error().message.find("cloth instance " + std::to_string(*b)) != std::string::npos,
                r.error().message);
  CHECK(world.step_index(*a) == 40);
  CHECK(world.step_index(*c) == 40);
  CHECK(world.step_index(*b) < 40);
  CHECK(!world.check_divergence().ok());
  return world.step_index(*b);
}

} // namespace

TEST_CASE("One host template, two worlds: CpuWorld and gpu::ClothWorld agree (GPU tolerance)") {
  VKCLOTH_GPU_TEST_BEGIN(ctx);
  auto cpu_world = CpuWorld::create();
  auto gpu_world = gpu::ClothWorld::create(ctx);
  REQUIRE(cpu_world.ok());
  REQUIRE(gpu_world.ok());
  const Readback cpu = host_frames(*cpu_world);
  const Readback gpu = host_frames(*gpu_world);

  REQUIRE(cpu.positions.size() == 2);
  REQUIRE(gpu.positions.size() == 2);
  CHECK(cpu.steps == std::vector<std::uint64_t>{100, 100});
  CHECK(gpu.steps == cpu.steps);
  for (std::size_t k = 0; k < 2; ++k) {
    CAPTURE(k);
    const Diff dp = diff(gpu.positions[k], cpu.positions[k]);
    const Diff dv = diff(gpu.velocities[k], cpu.velocities[k]);
    const Diff dn = diff(gpu.normals[k], cpu.normals[k]);
    MESSAGE(fmt::format("instance {}: max|dp| = {:.3g}{} max|dv| = {:.3g} max|dn| = {:.3g}", k, dp.max_abs,
                        dp.bitwise ? " (bitwise)" : "", dv.max_abs, dn.max_abs));
    CHECK(dp.max_abs <= gpu_cpu_tolerance);
    CHECK(dv.max_abs <= 100 * gpu_cpu_tolerance); // velocities ~ positions / dt
    CHECK(dn.max_abs <= 100 * gpu_cpu_tolerance); // unit normals of nearly flat fans are sensitive
  }

  auto cpu_wild = CpuWorld::create();
  auto gpu_wild = gpu::ClothWorld::create(ctx);
  REQUIRE(cpu_wild.ok());
  REQUIRE(gpu_wild.ok());
  CHECK(host_divergence(*cpu_wild) == host_divergence(*gpu_wild)); // the same first bad step
}
