// SPDX-License-Identifier: MIT
// The Vulkan solver against CpuSolver<float>: every integrator on chains and cloth grids (odd,
// non-square, strips, wind, collisions), determinism, ping-pong buffers, caller-recorded command
// buffers, staging, divergence detection.
//
// Tolerance: max |p_gpu - p_cpu| <= 1e-5 scene units after 100 steps. The shaders evaluate every
// float expression in the CPU's order with `precise` (no FMA contraction), so on lavapipe the
// results are bit-identical (reported per scene); 1e-5 leaves room for real GPUs whose sqrt and
// division are not correctly rounded (a few ulp per step, ~1e-7 relative, amplified by 100
// steps of a stiff system) while still catching any formula or ordering mistake (those show up
// at 1e-3 or more).
#include "gpu_test_util.hpp"
#include "vkcloth/gpu/testing.hpp"

#include <fmt/format.h>
#include <glm/geometric.hpp>

using namespace vkcloth;
using namespace vkcloth::gpu;
using namespace vkcloth::gpu::test;

namespace {

constexpr Integrator integrators[] = {Integrator::explicit_euler, Integrator::semi_implicit_euler,
                                      Integrator::rk4};

struct TestScene {
  ParticleSystem system;
  SimParams params;
};

TestScene chain(std::vector<double> masses, std::vector<glm::dvec3> positions) {
  ChainDesc d;
  d.masses = std::move(masses);
  d.positions = std::move(positions);
  auto s = make_chain(d);
  REQUIRE(s.ok());
  return {std::move(s.value()), SimParams{}};
}

TestScene cloth(std::uint32_t nx, std::uint32_t ny) {
  ClothDesc d;
  d.nx = nx;
  d.ny = ny;
  auto s = make_cloth(d);
  REQUIRE(s.ok());
  return {std::move(s.value()), SimParams{}};
}

TestScene falling_cloth() {
  ClothDesc d;
  d.nx = 15;
  d.ny = 13;
  d.orientation = ClothOrientation::horizontal;
  d.origin = {-0.5, -0.5, 0.3};
  d.pin_default_corners = false;
  auto s = make_cloth(d);
  REQUIRE(s.ok());
  SimParams p;
  p.colliders = {Collider::plane({0, 0, 1}, 0.0), Collider::sphere({0.05, 0.0, 0.15}, 0.15)};
  return {std::move(s.value()), p};
}

/// Runs `steps` steps on both solvers with `integrator`; checks positions, velocities, normals.
void check_against_cpu(Context& ctx, const std::string& name, TestScene scene, std::uint64_t steps = 100,
                       GpuSolverOptions options = {}, testing::SolverKnobs knobs = {}) {
  const double base_dt = scene.params.dt;
  for (Integrator integrator : integrators) {
    const std::string method = to_string(integrator);
    CAPTURE(name);
    CAPTURE(method);
    scene.params.integrator = integrator;
    // Explicit Euler gains energy every step: at the default dt = 0.02 the cloths blow up within
    // 40 steps (on both solvers, identically); a quarter of the step keeps 100 steps bounded.
    if (integrator == Integrator::explicit_euler && scene.system.grid)
      scene.params.dt = base_dt / 4;
    else
      scene.params.dt = base_dt;
    auto cpu = CpuSolver<float>::create(scene.system, scene.params);
    REQUIRE(cpu.ok());
    auto gpu = testing::create_solver(ctx, scene.system, scene.params, options, knobs);
    REQUIRE_MESSAGE(gpu.ok(), (gpu.ok() ? "" : gpu.error().message));
    const auto cr = cpu->run(steps);
    REQUIRE_MESSAGE(cr.ok(), (cr.ok() ? "" : cr.error().message));
    const auto gr = gpu->simulate(steps, 64); // 64 + 36: two submissions
    REQUIRE_MESSAGE(gr.ok(), (gr.ok() ? "" : gr.error().message));
    CHECK(gpu->step_index() == steps);
    CHECK(gpu->current_position_index() == steps % 2);

    auto gp = gpu->positions();
    auto gv = gpu->velocities();
    auto gn = gpu->normals();
    REQUIRE(gp.ok());
    REQUIRE(gv.ok());
    REQUIRE(gn.ok());
    const Diff dp = diff(*gp, cpu->positions());
    const Diff dv = diff(*gv, cpu->velocities());
    const Diff dn = diff(*gn, cpu->normals());
    // The scene must actually move: compare with the initial positions.
    double moved = 0.0;
    for (std::size_t i = 0; i < scene.system.size(); ++i)
      moved = std::max(moved, double(glm::length(glm::dvec3((*gp)[i]) - scene.system.particles[i].position)));
    MESSAGE(fmt::format("{:<28} {:<20} dt {:<6} max|dp| = {:.3g}{} max|dv| = {:.3g} max|dn| = {:.3g} (moved "
                        "{:.3g} m, gpu {:.2f} ms)",
                        name, method, scene.params.dt, dp.max_abs, dp.bitwise ? " (bitwise)" : "", dv.max_abs,
                        dn.max_abs, moved, gpu->last_gpu_ms()));
    CHECK(moved > 1e-3);
    CHECK(dp.max_abs <= gpu_cpu_tolerance);
    CHECK(dv.max_abs <= 100 * gpu_cpu_tolerance); // velocities ~ positions / dt
    CHECK(dn.max_abs <= 100 * gpu_cpu_tolerance); // unit normals of nearly flat fans are sensitive
  }
}

} // namespace

TEST_CASE("GPU matches CPU: single spring (chain of 1)") {
  VKCLOTH_GPU_TEST_BEGIN(ctx);
  check_against_cpu(ctx, "spring", chain({1.0}, {}));
}

TEST_CASE("GPU matches CPU: double spring, off-axis start (chain of 2)") {
  VKCLOTH_GPU_TEST_BEGIN(ctx);
  check_against_cpu(ctx, "double spring", chain({1.0, 1.0}, {{0.1, 0.0, -0.4}, {0.3, 0.1, -0.9}}));
}

TEST_CASE("GPU matches CPU: hanging cloth 10x10") {
  VKCLOTH_GPU_TEST_BEGIN(ctx);
  check_against_cpu(ctx, "cloth 10x10", cloth(10, 10));
}

TEST_CASE("GPU matches CPU: odd non-square cloth 37x23, without and with wind") {
  VKCLOTH_GPU_TEST_BEGIN(ctx);
  check_against_cpu(ctx, "cloth 37x23", cloth(37, 23));
  TestScene windy = cloth(37, 23);
  windy.params.wind.strength = 0.8;
  windy.params.wind.direction = {0.3, 1.0, 0.1};
  check_against_cpu(ctx, "cloth 37x23 + wind", std::move(windy));
}

TEST_CASE("GPU matches CPU: strips 1x9 and 9x1, tiny 2x2") {
  VKCLOTH_GPU_TEST_BEGIN(ctx);
  check_against_cpu(ctx, "strip 1x9", cloth(1, 9));
  check_against_cpu(ctx, "strip 9x1", cloth(9, 1));
  check_against_cpu(ctx, "cloth 2x2", cloth(2, 2));
}

TEST_CASE("GPU matches CPU: horizontal cloth falling on a plane and a sphere") {
  VKCLOTH_GPU_TEST_BEGIN(ctx);
  check_against_cpu(ctx, "falling cloth + colliders", falling_cloth());
  // The contacts happened: the cloth reached the floor and nothing went through it (the sphere
  // sits on the floor, so its projection cannot push a particle below it either).
  auto cpu = CpuSolver<float>::create(falling_cloth().system, falling_cloth().params);
  REQUIRE(cpu.ok());
  REQUIRE(cpu->run(100).ok());
  float lowest = 1e9f;
  for (const auto& p : cpu->positions())
    lowest = std::min(lowest, p.z);
  CHECK(lowest >= 0.0f);
  CHECK(lowest < 0.01f);
}

TEST_CASE("GPU staging path (forced) matches CPU") {
  VKCLOTH_GPU_TEST_BEGIN(ctx);
  testing::SolverKnobs staging;
  staging.force_staging = true;
  TestScene s = cloth(13, 7);
  auto gpu = testing::create_solver(ctx, s.system, s.params, {}, staging);
  REQUIRE(gpu.ok());
  CHECK(gpu->uses_staging());
  check_against_cpu(ctx, "cloth 13x7 (staging)", cloth(13, 7), 100, {}, staging);
  // Wind so that the normals are used, with staging too.
  TestScene w = cloth(13, 7);
  w.params.wind.strength = 0.5;
  check_against_cpu(ctx, "cloth 13x7 + wind (staging)", std::move(w), 40, {}, staging);
}

TEST_CASE("GPU two-dimensional dispatch (rows of workgroups) matches CPU") {
  VKCLOTH_GPU_TEST_BEGIN(ctx);
  testing::SolverKnobs k;
  k.max_workgroups_x = 3; // 851 particles = 14 groups of 64 -> 3 x 5 groups, the last row partly idle
  TestScene w = cloth(37, 23);
  w.params.wind.strength = 0.8;
  check_against_cpu(ctx, "cloth 37x23 + wind (3x5 groups)", std::move(w), 50, {}, k);
}

TEST_CASE("GPU runs are deterministic (bit-identical)") {
  VKCLOTH_GPU_TEST_BEGIN(ctx);
  TestScene s = cloth(37, 23);
  s.params.wind.strength = 0.8;
  s.params.integrator = Integrator::rk4;
  std::vector<glm::vec3> runs[2];
  for (auto& r : runs) {
    auto gpu = GpuSolver::create(ctx, s.system, s.params);
    REQUIRE(gpu.ok());
    REQUIRE(gpu->simulate(100, 17).ok());
    auto p = gpu->positions();
    REQUIRE(p.ok());
    r = std::move(*p);
  }
  REQUIRE(runs[0].size() == runs[1].size());
  CHECK(std::memcmp(runs[0].data(), runs[1].data(), runs[0].size() * sizeof(glm::vec3)) == 0);
}

TEST_CASE("GPU double buffering: the current index follows the step parity") {
  VKCLOTH_GPU_TEST_BEGIN(ctx);
  TestScene s = cloth(5, 4);
  auto gpu = GpuSolver::create(ctx, s.system, s.params);
  auto cpu = CpuSolver<float>::create(s.system, s.params);
  REQUIRE(gpu.ok());
  REQUIRE(cpu.ok());
  CHECK(gpu->position_buffer(0) != gpu->position_buffer(1));
  CHECK(gpu->current_position_index() == 0);
  for (std::uint64_t n : {1u, 1u, 2u, 3u}) {
    REQUIRE(gpu->simulate(n).ok());
    REQUIRE(cpu->run(n).ok());
    CHECK(gpu->current_position_index() == gpu->step_index() % 2);
    CHECK(gpu->current_position_buffer() == gpu->position_buffer(gpu->current_position_index()));
    auto p = gpu->positions();
    REQUIRE(p.ok());
    CHECK(diff(*p, cpu->positions()).max_abs <= gpu_cpu_tolerance);
  }
  CHECK(gpu->step_index() == 7);
  CHECK(gpu->time() == doctest::Approx(7 * 0.02));
}

TEST_CASE("GPU record_steps into a caller's command buffer") {
  VKCLOTH_GPU_TEST_BEGIN(ctx);
  const HostHandles h = ctx.handles();
  const auto gdpa = ctx.device_proc_addr();
  REQUIRE((gdpa != nullptr ? true : false));
#define LOAD(name)                                                                                           \
  const auto name = reinterpret_cast<PFN_##name>(gdpa(h.device, #name));                                     \
  REQUIRE((name != nullptr ? true : false))
  LOAD(vkCreateCommandPool);
  LOAD(vkDestroyCommandPool);
  LOAD(vkAllocateCommandBuffers);
  LOAD(vkBeginCommandBuffer);
  LOAD(vkEndCommandBuffer);
  LOAD(vkQueueSubmit);
  LOAD(vkQueueWaitIdle);
#undef LOAD

  TestScene s = cloth(11, 6);
  s.params.integrator = Integrator::rk4;
  auto gpu = GpuSolver::create(ctx, s.system, s.params);
  auto cpu = CpuSolver<float>::create(s.system, s.params);
  REQUIRE(gpu.ok());
  REQUIRE(cpu.ok());

  VkCommandPoolCreateInfo pi{};

  pi.sType = VK_STRUCTURE_TYPE_COMMAND_POOL_CREATE_INFO;
  pi.queueFamilyIndex = h.queue_family;
  VkCommandPool pool = VK_NULL_HANDLE;
  REQUIRE(vkCreateCommandPool(h.device, &pi, nullptr, &pool) == VK_SUCCESS);
  VkCommandBufferAllocateInfo ai{};
  ai.sType = VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO;
  ai.commandPool = pool;
  ai.level = VK_COMMAND_BUFFER_LEVEL_PRIMARY;
  ai.commandBufferCount = 2;
  VkCommandBuffer cbs[2] = {};
  REQUIRE(vkAllocateCommandBuffers(h.device, &ai, cbs) == VK_SUCCESS);
  const std::uint32_t steps[2] = {5, 4};
  VkCommandBufferBeginInfo bi{};
  bi.sType = VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO;
  for (int k = 0; k < 2; ++k) {
    REQUIRE(vkBeginCommandBuffer(cbs[k], &bi) == VK_SUCCESS);
    gpu->record_steps(cbs[k], steps[k]);
    // What a renderer would do before drawing; here the host reads next.
    gpu->record_barrier_to(cbs[k], VK_PIPELINE_STAGE_HOST_BIT, VK_ACCESS_HOST_READ_BIT);
    REQUIRE(vkEndCommandBuffer(cbs[k]) == VK_SUCCESS);
  }
  CHECK(gpu->step_index() == 9); // counters advance at record time
  CHECK(gpu->current_position_index() == 1);
  VkSubmitInfo si{};
  si.sType = VK_STRUCTURE_TYPE_SUBMIT_INFO;
  si.commandBufferCount = 2;
  si.pCommandBuffers = cbs;
  REQUIRE(vkQueueSubmit(h.queue, 1, &si, VK_NULL_HANDLE) == VK_SUCCESS);
  REQUIRE(vkQueueWaitIdle(h.queue) == VK_SUCCESS);
  vkDestroyCommandPool(h.device, pool, nullptr);

  CHECK(gpu->check_divergence().ok());
  REQUIRE(cpu->run(9).ok());
  auto p = gpu->positions();
  REQUIRE(p.ok());
  const Diff d = diff(*p, cpu->positions());
  MESSAGE(fmt::format("record_steps 5 + 4 rk4 steps: max|dp| = {:.3g}{}", d.max_abs,
                      d.bitwise ? " (bitwise)" : ""));
  CHECK(d.max_abs <= gpu_cpu_tolerance);
  // simulate() continues from there.
  REQUIRE(gpu->simulate(3).ok());
  REQUIRE(cpu->run(3).ok());
  auto p2 = gpu->positions();
  REQUIRE(p2.ok());
  CHECK(diff(*p2, cpu->positions()).max_abs <= gpu_cpu_tolerance);
}

TEST_CASE("GPU set_params between steps matches the CPU") {
  VKCLOTH_GPU_TEST_BEGIN(ctx);
  TestScene s = cloth(9, 8);
  auto gpu = GpuSolver::create(ctx, s.system, s.params);
  auto cpu = CpuSolver<float>::create(s.system, s.params);
  REQUIRE(gpu.ok());
  REQUIRE(cpu.ok());
  REQUIRE(gpu->simulate(20).ok());
  REQUIRE(cpu->run(20).ok());
  SimParams p = s.params;
  p.integrator = Integrator::rk4;
  p.wind.strength = 1.0;
  p.wind.direction = {0, 1, 0};
  p.colliders = {Collider::sphere({0.5, 0.4, 0.3}, 0.2), Collider::plane({0, 0, 1}, -0.3),
                 Collider::plane({0, 1, 0}, -0.2), Collider::plane({1, 0, 0}, -1.0),
                 Collider::plane({-1, 0, 0}, -2.0)}; // more than the initial capacity
  REQUIRE(gpu->set_params(p).ok());
  REQUIRE(cpu->set_params(p).ok());
  REQUIRE(gpu->simulate(30).ok());
  REQUIRE(cpu->run(30).ok());
  auto gp = gpu->positions();
  REQUIRE(gp.ok());
  CHECK(diff(*gp, cpu->positions()).max_abs <= gpu_cpu_tolerance);
  SimParams bad = p;
  bad.dt = -1;
  CHECK(gpu->set_params(bad).error().code == ErrorCode::invalid_argument);
}

TEST_CASE("GPU blow-up detection names the exact step") {
  VKCLOTH_GPU_TEST_BEGIN(ctx);
  TestScene s = chain({1.0}, {{0.0, 0.0, -0.5}});
  for (Integrator integrator : integrators) {
    const std::string method = to_string(integrator);
    CAPTURE(method);
    s.params.integrator = integrator;
    // omega dt = sqrt(20) dt: Euler blows up at dt = 0.45; RK4 is stable up to omega dt ~ 2.8.
    s.params.dt = integrator == Integrator::rk4 ? 0.7 : 0.45;
    auto cpu = CpuSolver<float>::create(s.system, s.params);
    REQUIRE(cpu.ok());
    const auto cr = cpu->run(2000);
    REQUIRE(!cr.ok());
    REQUIRE(cr.error().code == ErrorCode::diverged);
    auto gpu = GpuSolver::create(ctx, s.system, s.params);
    REQUIRE(gpu.ok());
    const auto gr = gpu->simulate(2000, 64);
    REQUIRE(!gr.ok());
    CHECK(gr.error().code == ErrorCode::diverged);
    MESSAGE("cpu: " << cr.error().message << "\ngpu: " << gr.error().message);
    CHECK(gpu->step_index() == cpu->step_index());
    CHECK(gr.error().message.find(fmt::format("step {}", cpu->step_index())) != std::string::npos);
    // The state is left as after the bad step, as on the CPU.
    auto gp = gpu->positions();
    REQUIRE(gp.ok());
    CHECK(diff(*gp, cpu->positions()).max_abs <=
          gpu_cpu_tolerance * std::max(1.0f, std::abs(cpu->positions()[1].z)));
    // Further simulation is refused with the same error.
    const auto again = gpu->simulate(1);
    CHECK(again.error().code == ErrorCode::diverged);
  }
}

// The two-pass layout's force and integrate passes (and RK4's, and implicit Euler's FORCE and
// FINISH) are specialised with the collider types of the batch, as the fused pass
// (each pass's prepare(), passes/): colliders that set_params adds between steps must
// reach them. The falling cloth without its colliders for 30 steps, then with its plane and
// sphere (two new types) for 60.
TEST_CASE("GPU two-pass, RK4 and implicit passes follow colliders added by set_params, as the CPU") {
  VKCLOTH_GPU_TEST_BEGIN(ctx);
  const TestScene with = falling_cloth();
  for (Integrator integrator :
       {Integrator::semi_implicit_euler, Integrator::rk4, Integrator::implicit_euler}) {
    CAPTURE(to_string(integrator));
    SimParams bare = with.params;
    bare.integrator = integrator;
    bare.colliders.clear();
    SimParams later = with.params;
    later.integrator = integrator;
    auto cpu = CpuSolver<float>::create(with.system, bare);
    REQUIRE(cpu.ok());
    REQUIRE(cpu->run(30).ok());
    REQUIRE(cpu->set_params(later).ok());
    REQUIRE(cpu->run(60).ok());
    GpuSolverOptions two_pass;
    two_pass.fused = false;
    auto gpu = GpuSolver::create(ctx, with.system, bare, two_pass);
    REQUIRE(gpu.ok());
    REQUIRE(gpu->simulate(30).ok());
    REQUIRE(gpu->set_params(later).ok());
    REQUIRE(gpu->simulate(60).ok());
    auto gp = gpu->positions();
    REQUIRE(gp.ok());
    const Diff d = diff(*gp, cpu->positions());
    MESSAGE(std::string(to_string(integrator))
            << " (fused = false), colliders from step 30: max |p_gpu - p_cpu| = " << d.max_abs);
    CHECK(d.max_abs <= gpu_cpu_tolerance);
    // The colliders acted: the cloth ends higher than it would without them.
    auto free_fall = CpuSolver<float>::create(with.system, bare);
    REQUIRE(free_fall.ok());
    REQUIRE(free_fall->run(90).ok());
    CHECK(diff(free_fall->positions(), cpu->positions()).max_abs > 1e-3);
  }
}

TEST_CASE("GPU fused step and two-pass layout agree with each other and with the CPU") {
  VKCLOTH_GPU_TEST_BEGIN(ctx);
  GpuSolverOptions two_pass;
  two_pass.fused = false;
  TestScene w = cloth(37, 23);
  w.params.wind.strength = 0.8;
  w.params.wind.direction = {0.3, 1.0, 0.1};
  check_against_cpu(ctx, "cloth 37x23 + wind (two-pass)", std::move(w), 100, two_pass);
  check_against_cpu(ctx, "falling cloth (two-pass)", falling_cloth(), 100, two_pass);
  check_against_cpu(ctx, "double spring (two-pass)", chain({1.0, 1.0}, {{0.1, 0.0, -0.4}, {0.3, 0.1, -0.9}}),
                    100, two_pass);
  GpuSolverOptions fused;
  fused.fused = true;
  testing::SolverKnobs rows;
  rows.max_workgroups_x = 3;
  check_against_cpu(ctx, "falling cloth (fused, 2-D dispatch)", falling_cloth(), 100, fused, rows);

  // Fused vs two-pass directly: every state buffer bit for bit, for both Euler integrators.
  for (Integrator integrator : {Integrator::explicit_euler, Integrator::semi_implicit_euler}) {
    CAPTURE(to_string(integrator));
    TestScene s = falling_cloth();
    s.params.wind.strength = 0.5;
    s.params.integrator = integrator;
    if (integrator == Integrator::explicit_euler)
      s.params.dt /= 4;
    std::vector<glm::vec3> out[2][4];
    for (int k = 0; k < 2; ++k) {
      GpuSolverOptions o;
      o.fused = k == 0;
      auto gpu = GpuSolver::create(ctx, s.system, s.params, o);
      REQUIRE(gpu.ok());
      REQUIRE(gpu->simulate(77, 10).ok());
      CHECK(gpu->current_position_index() == 1);
      out[k][0] = gpu->positions().value();
      out[k][1] = gpu->velocities().value();
      out[k][2] = gpu->forces().value();
      out[k][3] = gpu->normals().value();
    }
    for (int b = 0; b < 4; ++b) {
      CAPTURE(b);
      CHECK(diff(out[0][b], out[1][b]).bitwise);
    }
  }
}

TEST_CASE(
    "GPU grid stencil (specialisation constants) gives the CSR gather's bits, and the CPU's on lavapipe") {
  VKCLOTH_GPU_TEST_BEGIN(ctx);
  const bool cpu_device = ctx.device_name().find("llvmpipe") != std::string::npos;
  TestScene scenes[2] = {cloth(37, 23), falling_cloth()};
  scenes[0].params.wind.strength = 0.8;
  scenes[0].params.wind.direction = {0.3, 1.0, 0.1};
  scenes[1].params.wind.strength = 0.5;
  for (TestScene& s : scenes)
    for (Integrator integrator : integrators)
      for (bool fused : {true, false}) {
        CAPTURE(to_string(integrator));
        CAPTURE(fused);
        s.params.integrator = integrator;
        const double dt = s.params.dt;
        if (integrator == Integrator::explicit_euler)
          s.params.dt /= 4;
        std::vector<glm::vec3> out[2][4];
        for (int k = 0; k < 2; ++k) {
          GpuSolverOptions o;
          o.fused = fused;
          testing::SolverKnobs knobs;
          knobs.csr_only = k == 1;
          auto gpu = testing::create_solver(ctx, s.system, s.params, o, knobs);
          REQUIRE(gpu.ok());
          REQUIRE(gpu->simulate(60, 25).ok());
          out[k][0] = gpu->positions().value();
          out[k][1] = gpu->velocities().value();
          out[k][2] = gpu->forces().value();
          out[k][3] = gpu->normals().value();
        }
        for (int b = 0; b < 4; ++b) {
          CAPTURE(b);
          CHECK(diff(out[0][b], out[1][b]).bitwise);
        }
        if (cpu_device) { // lavapipe reproduces the CPU solver bit for bit
          auto cpu = CpuSolver<float>::create(s.system, s.params, {2});
          REQUIRE(cpu.ok());
          REQUIRE(cpu->run(60).ok());
          CHECK(diff(out[0][0], cpu->positions()).bitwise);
          CHECK(diff(out[0][1], cpu->velocities()).bitwise);
          CHECK(diff(out[0][2], cpu->forces()).bitwise);
          // Normals: equal values (a zero component's sign may differ; nothing downstream sees it).
          std::size_t differ = 0;
          for (std::size_t k = 0; k < out[0][3].size(); ++k)
            differ += out[0][3][k] != cpu->normals()[k];
          CHECK(differ == 0);
        }
        s.params.dt = dt;
      }
}
