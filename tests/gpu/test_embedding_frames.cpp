// SPDX-License-Identifier: MIT
// Embedding, frame by frame: what a host changes every frame (StepParams, set_collider_pose,
// set_pin_targets) travels in the command buffer, so two frames in flight step as one frame at a
// time would, and as the CPU world does.
#include "embedding_host.hpp"
#include "gpu_test_util.hpp"
#include "host_vulkan.hpp"

#include <cmath>
#include <utility>

#include <glm/gtc/matrix_transform.hpp>

namespace {

using namespace vkcloth;
using namespace vkcloth::gpu;
using vkcloth::gpu::test::diff;
using vkcloth::gpu::test::handles_of;
using vkcloth::gpu::test::host_or_skip;
using vkcloth::gpu::test::HostVulkan;
using vkcloth::gpu::test::make_topology;

} // namespace

namespace {

/// Frame k's per-frame parameters: the host's frame time, its wind and a sphere it animates.
StepParams frame_params(int k) {
  StepParams s;
  s.dt = 0.004 + 0.002 * std::sin(0.7 * k);
  s.gravity = glm::dvec3(0.8 * std::sin(0.3 * k), 0.0, -9.81);
  Wind w;
  w.direction = {1.0, 0.2 * std::cos(0.5 * k), 0.3};
  w.strength = 0.02 * (1.0 + std::cos(0.9 * k));
  s.wind = w;
  s.colliders = std::vector<Collider>{Collider::sphere({0.02 * k - 0.2, 0.0, 0.0}, 0.25)};
  return s;
}

SimParams frame_start_params() {
  SimParams p;
  p.integrator = Integrator::semi_implicit_euler;
  p.colliders = {Collider::sphere({-0.2, 0.0, 0.0}, 0.25)};
  return p;
}

} // namespace

TEST_CASE("Per-frame parameters: two frames in flight changing dt, gravity, wind and a moving sphere "
          "every frame give the bits of one frame at a time") {
  VKCLOTH_GPU_TEST_BEGIN(ctx);
  std::string error;
  auto host = host_or_skip(error);
  if (!host)
    return;
  auto adopted = Context::adopt(handles_of(*host, nullptr));
  REQUIRE(adopted.ok());
  auto topo = make_topology(16, 12, true);
  constexpr int frames = 30;
  constexpr std::uint32_t steps_per_frame = 2;

  // In flight: frame k records into slot k % 2 and is submitted without waiting (a renderer's
  // ring); only slot reuse waits (for frame k - 2). A solver and a world of two instances.
  auto flying = GpuSolver::create(*adopted, topo, frame_start_params());
  auto world = ClothWorld::create(*adopted);
  REQUIRE(flying.ok());
  REQUIRE(world.ok());
  auto a = world->add(topo, frame_start_params());
  auto b = world->add(topo, frame_start_params());
  REQUIRE(a.ok());
  REQUIRE(b.ok());
  double expected_time = 0.0;
  for (int k = 0; k < frames; ++k) {
    const std::uint32_t slot = std::uint32_t(k) % HostVulkan::frames_in_flight;
    REQUIRE(host->begin_frame(slot));
    const StepParams s = frame_params(k);
    REQUIRE(flying->record_steps(host->frame_cmd[slot], steps_per_frame, s).ok());
    REQUIRE(world->set_step_params(*a, s).ok());
    REQUIRE(world->set_step_params(*b, frame_params(k + 7)).ok()); // its own sequence
    world->record_steps(host->frame_cmd[slot], steps_per_frame);
    world->record_barrier_to(host->frame_cmd[slot], VK_PIPELINE_STAGE_TRANSFER_BIT,
                             VK_ACCESS_TRANSFER_READ_BIT);
    REQUIRE(host->submit_frame(slot));
    expected_time += steps_per_frame * *s.dt;
  }
  REQUIRE(host->wait_frames());
  CHECK(flying->time() == doctest::Approx(expected_time).epsilon(1e-12));

  // One frame at a time: set_params, simulate (submitted and waited for), on the shared Context;
  // and the CPU reference.
  auto serial = GpuSolver::create(ctx, topo, frame_start_params());
  auto serial_b = GpuSolver::create(ctx, topo, frame_start_params());
  auto cpu = CpuSolver<float>::create(topo, frame_start_params());
  REQUIRE(serial.ok());
  REQUIRE(serial_b.ok());
  REQUIRE(cpu.ok());
  for (int k = 0; k < frames; ++k) {
    REQUIRE(serial->set_params(frame_params(k).applied_to(serial->params())).ok());
    REQUIRE(serial->simulate(steps_per_frame).ok());
    REQUIRE(serial_b->set_params(frame_params(k + 7).applied_to(serial_b->params())).ok());
    REQUIRE(serial_b->simulate(steps_per_frame).ok());
    REQUIRE(cpu->set_params(frame_params(k).applied_to(cpu->params())).ok());
    for (std::uint32_t s = 0; s < steps_per_frame; ++s)
      REQUIRE(cpu->step().ok());
  }
  const auto want = serial->positions();
  const auto want_b = serial_b->positions();
  const auto got = flying->positions();
  const auto got_a = world->positions(*a);
  const auto got_b = world->positions(*b);
  const auto want_v = serial->velocities();
  const auto got_v = flying->velocities();
  REQUIRE((want && want_b && got && got_a && got_b && want_v && got_v));
  CHECK_MESSAGE(diff(*got, *want).bitwise,
                "in flight vs one at a time: " << diff(*got, *want).max_abs << " m");
  CHECK(diff(*got_v, *want_v).bitwise);
  CHECK(diff(*got_a, *want).bitwise);
  CHECK(diff(*got_b, *want_b).bitwise);
  CHECK_MESSAGE(diff(*got_a, *got_b).max_abs > 1e-4,
                "the two instances' sequences differ, so must their cloths");
  const std::vector<glm::vec3> cpu_pos(cpu->positions().begin(), cpu->positions().end());
  CHECK_MESSAGE(diff(*want, cpu_pos).max_abs < 1e-5, "GPU vs CPU: " << diff(*want, cpu_pos).max_abs << " m");
  // The sphere moved under the cloth: it did touch it (the colliders were not a no-op).
  float lowest = 1e9f;
  for (const auto& x : *got)
    lowest = std::min(lowest, x.z);
  CHECK(lowest < 0.25f);

  // Bad per-frame values: the error names the field, nothing is recorded.
  REQUIRE(host->begin_frame(0));
  StepParams bad;
  bad.dt = -0.01;
  const std::uint64_t before = flying->step_index();
  auto r = flying->record_steps(host->frame_cmd[0], 1, bad);
  REQUIRE_FALSE(r.ok());
  CHECK(r.error().message.find("dt") != std::string::npos);
  CHECK(flying->step_index() == before);
  REQUIRE(host->submit_frame(0));

  // A change that rebuilds (another integrator) while frames are in flight: vkcloth waits for
  // them itself (the Context's queue), then goes on from the same state.
  REQUIRE(host->begin_frame(1));
  flying->record_steps(host->frame_cmd[1], 3);
  REQUIRE(host->submit_frame(1));
  SimParams rk4 = flying->params();
  rk4.integrator = Integrator::rk4;
  REQUIRE(flying->set_params(rk4).ok());
  REQUIRE(serial->simulate(3).ok());
  REQUIRE(serial->set_params(rk4).ok());
  REQUIRE(flying->simulate(2).ok());
  REQUIRE(serial->simulate(2).ok());
  const auto after = flying->positions();
  const auto after_serial = serial->positions();
  REQUIRE((after && after_serial));
  CHECK(diff(*after, *after_serial).bitwise);
  REQUIRE(host->wait_frames());
  CHECK(host->messages.load() == 0);
}

namespace {

/// Colliders set once (shape, friction): a frictionless floor, a sticky sphere ("stick on
/// contact", docs/embedding.md) and a turning box.
SimParams posed_start_params() {
  SimParams p;
  p.dt = 0.005;
  Collider sphere = Collider::sphere({-0.2, 0.0, 0.05}, 0.2);
  sphere.friction = 0.8;
  Collider box = Collider::box({0.3, 0.0, 0.1}, {0.08, 0.3, 0.05});
  box.friction = 0.4;
  p.colliders = {Collider::plane({0, 0, 1}, 0.0), sphere, box};
  return p;
}

/// Frame k's poses of colliders 1 (the sphere slides along x) and 2 (the box turns about z).
std::pair<ColliderPose, ColliderPose> frame_poses(int k) {
  ColliderPose sphere;
  sphere.position = {-0.2 + 0.01 * k, 0.03 * std::sin(0.4 * k), 0.05};
  sphere.linear_velocity = {1.0, 0.0, 0.0};
  ColliderPose box;
  box.position = {0.3, 0.0, 0.1};
  box.rotation = glm::dmat3(glm::rotate(glm::dmat4(1.0), 0.05 * k, glm::dvec3(0, 0, 1)));
  box.angular_velocity = {0.0, 0.0, 5.0};
  return {sphere, box};
}

/// The host's frame loop for either world: each frame poses two colliders (nothing else resent),
/// then `run_frame` steps it.
template <typename World, typename RunFrame>
std::vector<glm::vec3> posed_frames(World& world, InstanceId id, int frames, RunFrame run_frame) {
  for (int k = 0; k < frames; ++k) {
    const auto [sphere, box] = frame_poses(k);
    REQUIRE(world.set_collider_pose(id, 1, sphere).ok());
    REQUIRE(world.set_collider_pose(id, 2, box).ok());
    run_frame(k);
  }
  return world.positions(id).value();
}

} // namespace

TEST_CASE("set_collider_pose: a pose per frame with two frames in flight on the GPU, the CPU world's "
          "positions within 1e-5 m, shape and friction kept, bad poses refused") {
  VKCLOTH_GPU_TEST_BEGIN(ctx);
  std::string error;
  auto host = host_or_skip(error);
  if (!host)
    return;
  auto adopted = Context::adopt(handles_of(*host, nullptr));
  REQUIRE(adopted.ok());
  auto topo = make_topology(16, 12, true);
  constexpr int frames = 40;
  constexpr std::uint32_t steps_per_frame = 2;

  auto gpu_world = ClothWorld::create(*adopted);
  REQUIRE(gpu_world.ok());
  auto g = gpu_world->add(topo, posed_start_params());
  REQUIRE(g.ok());
  std::vector<glm::vec3> gpu = posed_frames(*gpu_world, *g, frames, [&](int k) {
    const std::uint32_t slot = std::uint32_t(k) % HostVulkan::frames_in_flight; // waits for frame k - 2 only
    REQUIRE(host->begin_frame(slot));
    gpu_world->record_steps(host->frame_cmd[slot], steps_per_frame);
    gpu_world->record_barrier_to(host->frame_cmd[slot], VK_PIPELINE_STAGE_TRANSFER_BIT,
                                 VK_ACCESS_TRANSFER_READ_BIT);
    REQUIRE(host->submit_frame(slot));
  });
  REQUIRE(host->wait_frames());
  REQUIRE(gpu_world->check_divergence().ok());

  auto cpu_world = CpuWorld::create();
  REQUIRE(cpu_world.ok());
  auto c = cpu_world->add(topo, posed_start_params());
  REQUIRE(c.ok());
  std::vector<glm::vec3> cpu =
      posed_frames(*cpu_world, *c, frames, [&](int) { REQUIRE(cpu_world->simulate(steps_per_frame).ok()); });
  CHECK_MESSAGE(diff(gpu, cpu).max_abs <= 1e-5, "GPU vs CPU: " << diff(gpu, cpu).max_abs << " m");
  MESSAGE("pose updates, GPU in flight vs CPU: max |dp| = "
          << diff(gpu, cpu).max_abs << " m" << std::string(diff(gpu, cpu).bitwise ? " (bitwise)" : ""));

  // The cloth met the moving sphere and the floor (the poses were not a no-op).
  float lowest = 1e9f;
  for (const auto& x : gpu)
    lowest = std::min(lowest, x.z);
  CHECK(lowest < 0.1f);

  // Only the pose changed: shape and friction are the ones given at add(); the sphere is where
  // the last pose put it, advanced by its velocity over that frame's steps.
  for (const SimParams& p : {gpu_world->params(*g).value(), cpu_world->params(*c).value()}) {
    REQUIRE(p.colliders.size() == 3);
    CHECK(p.colliders[1].radius == 0.2);
    CHECK(p.colliders[1].friction == 0.8);
    CHECK(p.colliders[2].half_extents == glm::dvec3(0.08, 0.3, 0.05));
    CHECK(p.colliders[2].friction == 0.4);
    const double t = steps_per_frame * 0.005;
    CHECK(p.colliders[1].center.x == doctest::Approx(-0.2 + 0.01 * (frames - 1) + t).epsilon(1e-12));
  }

  // Bad poses: named, nothing changed.
  const SimParams before = cpu_world->params(*c).value();
  ColliderPose bad;
  auto r = cpu_world->set_collider_pose(*c, 3, bad);
  REQUIRE_FALSE(r.ok());
  CHECK_MESSAGE(r.error().message.find("colliders[3]") != std::string::npos, r.error().message);
  CHECK_MESSAGE(r.error().message.find("3 colliders") != std::string::npos, r.error().message);
  bad.rotation = glm::dmat3(2.0);
  r = gpu_world->set_collider_pose(*g, 2, bad);
  REQUIRE_FALSE(r.ok());
  CHECK_MESSAGE(r.error().message.find("pose.rotation") != std::string::npos, r.error().message);
  bad.rotation.reset();
  bad.position.x = std::nan("");
  r = cpu_world->set_collider_pose(*c, 1, bad);
  REQUIRE_FALSE(r.ok());
  CHECK_MESSAGE(r.error().message.find("pose.position") != std::string::npos, r.error().message);
  bad.position = {};
  bad.angular_velocity = {0.0, 0.0, 1.0}; // a plane cannot turn
  r = gpu_world->set_collider_pose(*g, 0, bad);
  REQUIRE_FALSE(r.ok());
  CHECK_MESSAGE(r.error().message.find("colliders[0].angular_velocity") != std::string::npos,
                r.error().message);
  r = cpu_world->set_collider_pose(*c + 100, 0, ColliderPose{});
  REQUIRE_FALSE(r.ok());
  CHECK_MESSAGE(r.error().message.find("no cloth instance") != std::string::npos, r.error().message);
  CHECK(cpu_world->params(*c)->colliders[1].center == before.colliders[1].center);
  CHECK(host->messages.load() == 0);
}

TEST_CASE("set_pin_targets: targets every frame with two frames in flight on the GPU, the CPU world's "
          "positions within 1e-5 m, pinned corners on their targets, a free edge held within reach") {
  VKCLOTH_GPU_TEST_BEGIN(ctx);
  std::string error;
  auto host = host_or_skip(error);
  if (!host)
    return;
  auto adopted = Context::adopt(handles_of(*host, nullptr));
  REQUIRE(adopted.ok());
  auto topo = make_topology(12, 10); // vertical, its top corners (0, 9) and (11, 9) pinned
  const std::uint32_t left = 9 * 12, right = 9 * 12 + 11, middle = 9 * 12 + 5;
  constexpr int frames = 30;
  constexpr std::uint32_t steps_per_frame = 2;
  SimParams p;
  p.dt = 0.005;
  p.substeps = 2;
  // Frame k: the corners swing along a circle (a host's skinned shoulders), the free middle of the
  // top edge is held within 2 cm of a point between them.
  const auto frame_targets = [&](int k) {
    const double a = 0.15 * k;
    const glm::dvec3 swing(0.2 * std::sin(a), 0.2 * (1.0 - std::cos(a)), 0.0);
    const auto at = [&](std::uint32_t q) { return topo->system().particles[q].position + swing; };
    return std::vector<PinTarget>{{left, at(left), 0.0}, {right, at(right), 0.0}, {middle, at(middle), 0.02}};
  };
  auto gpu_world = ClothWorld::create(*adopted);
  REQUIRE(gpu_world.ok());
  auto g = gpu_world->add(topo, p);
  REQUIRE(g.ok());
  auto cpu_world = CpuWorld::create();
  REQUIRE(cpu_world.ok());
  auto c = cpu_world->add(topo, p);
  REQUIRE(c.ok());
  for (int k = 0; k < frames; ++k) {
    const auto targets = frame_targets(k);
    REQUIRE(gpu_world->set_pin_targets(*g, targets).ok());
    const std::uint32_t slot = std::uint32_t(k) % HostVulkan::frames_in_flight; // waits for frame k - 2 only
    REQUIRE(host->begin_frame(slot));
    gpu_world->record_steps(host->frame_cmd[slot], steps_per_frame);
    gpu_world->record_barrier_to(host->frame_cmd[slot], VK_PIPELINE_STAGE_TRANSFER_BIT,
                                 VK_ACCESS_TRANSFER_READ_BIT);
    REQUIRE(host->submit_frame(slot));
    REQUIRE(cpu_world->set_pin_targets(*c, targets).ok());
    REQUIRE(cpu_world->simulate(steps_per_frame).ok());
  }
  REQUIRE(host->wait_frames());
  REQUIRE(gpu_world->check_divergence().ok());
  const std::vector<glm::vec3> gpu = gpu_world->positions(*g).value(), cpu = cpu_world->positions(*c).value();
  CHECK_MESSAGE(diff(gpu, cpu).max_abs <= 1e-5, "GPU vs CPU: " << diff(gpu, cpu).max_abs << " m");
  const auto last = frame_targets(frames - 1);
  for (const auto& x : {gpu, cpu}) {
    CHECK(glm::length(glm::dvec3(x[left]) - last[0].position) < 1e-5);
    CHECK(glm::length(glm::dvec3(x[right]) - last[1].position) < 1e-5);
    CHECK(glm::length(glm::dvec3(x[middle]) - last[2].position) < 0.02 + 1e-5);
  }
  // An unknown instance and a bad target are refused, naming them.
  auto r = gpu_world->set_pin_targets(*g + 100, frame_targets(0));
  REQUIRE_FALSE(r.ok());
  CHECK_MESSAGE(r.error().message.find("no cloth instance") != std::string::npos, r.error().message);
  const PinTarget past{10000, {0, 0, 0}, 0.0};
  r = gpu_world->set_pin_targets(*g, {&past, 1});
  REQUIRE_FALSE(r.ok());
  CHECK_MESSAGE(r.error().message.find("past the cloth's 120 particles") != std::string::npos,
                r.error().message);
  CHECK(host->messages.load() == 0);
}
