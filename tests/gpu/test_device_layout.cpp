// SPDX-License-Identifier: MIT
// The per-device layout (vkcloth/gpu/layout.hpp): choose_layout() per device type,
// subgroup size and limits (no device needed), and, on the test device, the two builds of the
// shaders (texel views, storage buffers) and other workgroup sizes forced through
// GpuSolverOptions on the same scenes: a grid with its stencil, colliders and wind (fused and
// two-pass, RK4), a mesh cloth (CSR gather, fan normals), stretch control (tethers and Provot
// sweeps). A 32-bit texel fetch is a copy and each particle is computed by one invocation, so every
// variant gives the same bits; each is also held to the CPU reference with test_gpu_solver.cpp's
// tolerance (1e-5 m after the run).
#include "gpu_test_util.hpp"
#include "vkcloth/gpu/layout.hpp"
#include "vkcloth/gpu/testing.hpp"
#include "vkcloth/mesh.hpp"

#include <fmt/format.h>

using namespace vkcloth;
using namespace vkcloth::gpu;
using namespace vkcloth::gpu::test;

namespace {

VkPhysicalDeviceProperties device_of(VkPhysicalDeviceType type, std::uint32_t max_size = 1024,
                                     std::uint32_t max_invocations = 1024) {
  VkPhysicalDeviceProperties p{};
  p.deviceType = type;
  p.limits.maxComputeWorkGroupSize[0] = max_size;
  p.limits.maxComputeWorkGroupSize[1] = p.limits.maxComputeWorkGroupSize[2] = 64;
  p.limits.maxComputeWorkGroupInvocations = max_invocations;
  return p;
}

struct LayoutScene {
  std::string name;
  ParticleSystem system;
  SimParams params;
  std::uint64_t steps = 60;
};

/// A 23 x 17 horizontal grid (odd, non-square: the stencil's border and interior) falling on a
/// plane and a sphere, in the wind.
LayoutScene grid_scene() {
  ClothDesc d;
  d.nx = 23;
  d.ny = 17;
  d.orientation = ClothOrientation::horizontal;
  d.origin = {-0.5, -0.5, 0.25};
  d.pin_default_corners = false;
  auto s = make_cloth(d);
  REQUIRE(s.ok());
  SimParams p;
  p.colliders = {Collider::plane({0, 0, 1}, 0.0), Collider::sphere({0.05, 0.0, 0.12}, 0.12)};
  p.wind.strength = 0.6;
  p.wind.direction = {0.3, 1.0, 0.1};
  p.integrator = Integrator::semi_implicit_euler;
  return {"grid 23x17 + colliders + wind", std::move(*s), p};
}

/// A jittered 11 x 9 triangle mesh (diagonals alternating by cell), horizontal, falling on the
/// same colliders in the wind: the mesh path (CSR gather, fan-list normals).
LayoutScene mesh_scene() {
  Mesh m;
  constexpr std::uint32_t mx = 11, my = 9;
  for (std::uint32_t j = 0; j < my; ++j)
    for (std::uint32_t i = 0; i < mx; ++i) {
      const double jx = ((i * 7 + j * 13) % 5) * 0.004, jy = ((i * 11 + j * 3) % 7) * 0.003;
      m.positions.push_back({-0.5 + i * 0.1 + jx, -0.4 + j * 0.1 + jy, 0.25});
    }
  for (std::uint32_t j = 0; j + 1 < my; ++j)
    for (std::uint32_t i = 0; i + 1 < mx; ++i) {
      const std::uint32_t a = j * mx + i, b = a + 1, c = a + mx, e = c + 1;
      if ((i + j) % 2)
        m.indices.insert(m.indices.end(), {a, b, e, a, e, c});
      else
        m.indices.insert(m.indices.end(), {a, b, c, b, e, c});
      m.face_offsets.push_back(static_cast<std::uint32_t>(m.indices.size() - 3));
      m.face_offsets.push_back(static_cast<std::uint32_t>(m.indices.size()));
    }
  auto made = make_mesh_cloth(m, {});
  REQUIRE_MESSAGE(made.ok(), (made.ok() ? "" : made.error().message));
  LayoutScene s = grid_scene();
  s.name = "mesh 11x9 + colliders + wind";
  s.system = std::move(made->system);
  return s;
}

/// The vertical hanging grid with stretch control (tethers and 3 Provot sweeps) and a sphere.
LayoutScene stretch_scene() {
  ClothDesc d;
  d.nx = 19;
  d.ny = 15;
  auto s = make_cloth(d);
  REQUIRE(s.ok());
  SimParams p;
  p.integrator = Integrator::semi_implicit_euler;
  p.stretch_limit.method = StretchLimit::Method::both;
  p.stretch_limit.iterations = 3;
  p.stretch_limit.max_strain = 0.05;
  p.colliders = {Collider::sphere({0.5, 0.25, -0.6}, 0.2)};
  p.wind.strength = 0.4;
  return {"grid 19x15 + stretch limit (both)", std::move(*s), p};
}

/// Runs `scene` with `options` on the GPU; checks it against the CPU reference and returns the
/// final positions.
std::vector<glm::vec3> run_gpu(Context& ctx, const LayoutScene& scene, const GpuSolverOptions& options,
                               const std::vector<glm::vec3>& cpu, const std::string& what) {
  CAPTURE(scene.name);
  CAPTURE(what);
  auto gpu = GpuSolver::create(ctx, scene.system, scene.params, options);
  REQUIRE_MESSAGE(gpu.ok(), (gpu.ok() ? "" : gpu.error().message));
  const auto r = gpu->simulate(scene.steps, 25); // several submissions
  REQUIRE_MESSAGE(r.ok(), (r.ok() ? "" : r.error().message));
  auto p = gpu->positions();
  REQUIRE(p.ok());
  const Diff d = diff(*p, cpu);
  MESSAGE(fmt::format("{:<34} {:<34} max|dp| vs CPU = {:.3g}{}", scene.name, what, d.max_abs,
                      d.bitwise ? " (bitwise)" : ""));
  CHECK(d.max_abs <= 1e-5);
  return std::move(*p);
}

/// Every buffer access x {fused, two-pass} (and the given integrators) with the device's workgroup
/// size, then storage buffers with workgroups of 32 and 128: all the same bits as texel views.
void check_variants(Context& ctx, LayoutScene scene, std::initializer_list<Integrator> integrators) {
  const double base_dt = scene.params.dt;
  for (Integrator integrator : integrators) {
    scene.params.integrator = integrator;
    // Explicit Euler gains energy every step: a quarter of the step keeps the run bounded (as
    // test_gpu_solver.cpp).
    scene.params.dt = integrator == Integrator::explicit_euler ? base_dt / 4 : base_dt;
    auto cpu = CpuSolver<float>::create(scene.system, scene.params);
    REQUIRE(cpu.ok());
    REQUIRE(cpu->run(scene.steps).ok());
    const std::vector<glm::vec3> reference(cpu->positions().begin(), cpu->positions().end());
    for (bool fused : {true, false}) {
      if (fused && integrator == Integrator::rk4)
        continue; // RK4 is always two-pass: `fused` changes nothing
      GpuSolverOptions o;
      o.fused = fused;
      const std::string mode = fmt::format("{} {}", to_string(integrator),
                                           fused && integrator != Integrator::rk4 ? "fused" : "two-pass");
      o.buffer_access = BufferAccess::texel_views;
      const auto texel = run_gpu(ctx, scene, o, reference, mode + ", texel views");
      o.buffer_access = BufferAccess::storage_buffers;
      const auto storage = run_gpu(ctx, scene, o, reference, mode + ", storage buffers");
      CHECK_MESSAGE(diff(texel, storage).bitwise, "texel views and storage buffers differ: " << mode);
      for (std::uint32_t size : {32u, 128u}) {
        o.workgroup_size = size;
        const auto sized =
            run_gpu(ctx, scene, o, reference, fmt::format("{}, storage, workgroup {}", mode, size));
        CHECK_MESSAGE(diff(texel, sized).bitwise, "workgroup " << size << " differs: " << mode);
      }
      o.workgroup_size = 0;
    }
  }
}

} // namespace

TEST_CASE("choose_layout: a CPU device reads through texel views with the compiled workgroup") {
  const DeviceLayout l = choose_layout(device_of(VK_PHYSICAL_DEVICE_TYPE_CPU), 8);
  CHECK(l.access == BufferAccess::texel_views);
  CHECK(l.workgroup_size == 64);
  CHECK(l.subgroup_size == 8);
  CHECK(l.reason.find("CPU") != std::string::npos);
  // Never above the device's limits.
  CHECK(choose_layout(device_of(VK_PHYSICAL_DEVICE_TYPE_CPU, 32, 1024), 8).workgroup_size == 32);
}

TEST_CASE("choose_layout: a GPU reads storage buffers in workgroups of whole subgroups") {
  for (VkPhysicalDeviceType type :
       {VK_PHYSICAL_DEVICE_TYPE_DISCRETE_GPU, VK_PHYSICAL_DEVICE_TYPE_INTEGRATED_GPU,
        VK_PHYSICAL_DEVICE_TYPE_VIRTUAL_GPU, VK_PHYSICAL_DEVICE_TYPE_OTHER})
    for (std::uint32_t sub : {8u, 16u, 32u, 64u, 128u}) {
      CAPTURE(type);
      CAPTURE(sub);
      const DeviceLayout l = choose_layout(device_of(type), sub);
      CHECK(l.access == BufferAccess::storage_buffers);
      CHECK(l.workgroup_size % sub == 0);
      CHECK(l.workgroup_size >= 64);
      CHECK(l.workgroup_size <= 1024);
      CHECK(l.subgroup_size == sub);
      CHECK_FALSE(l.reason.empty());
    }
  const DeviceLayout nv = choose_layout(device_of(VK_PHYSICAL_DEVICE_TYPE_DISCRETE_GPU), 32);
  CHECK(nv.workgroup_size == 64);
  CHECK(nv.reason.find("discrete") != std::string::npos);
  CHECK(choose_layout(device_of(VK_PHYSICAL_DEVICE_TYPE_DISCRETE_GPU), 128).workgroup_size == 128);
  // Unknown subgroup size: taken as 32.
  CHECK(choose_layout(device_of(VK_PHYSICAL_DEVICE_TYPE_DISCRETE_GPU), 0).workgroup_size == 64);
  // Limits: maxComputeWorkGroupInvocations and maxComputeWorkGroupSize[0] both bound it (Vulkan
  // guarantees 128 of each), and it stays a whole number of subgroups when one fits.
  CHECK(choose_layout(device_of(VK_PHYSICAL_DEVICE_TYPE_DISCRETE_GPU, 1024, 48), 16).workgroup_size == 48);
  CHECK(choose_layout(device_of(VK_PHYSICAL_DEVICE_TYPE_DISCRETE_GPU, 40, 1024), 32).workgroup_size == 32);
  CHECK(choose_layout(device_of(VK_PHYSICAL_DEVICE_TYPE_DISCRETE_GPU, 128, 128), 256).workgroup_size == 128);
}

TEST_CASE("BufferAccess spellings round-trip") {
  for (BufferAccess a : {BufferAccess::automatic, BufferAccess::texel_views, BufferAccess::storage_buffers})
    CHECK(parse_buffer_access(to_string(a)) == a);
  CHECK_FALSE(parse_buffer_access("ssbo").has_value());
}

TEST_CASE("device_layout of the test device (lavapipe: a CPU device, texel views)") {
  VKCLOTH_GPU_TEST_BEGIN(ctx);
  const DeviceLayout l = device_layout(ctx);
  MESSAGE(ctx.device_name() << ": " << std::string(to_string(l.access)) << ", workgroups of "
                            << l.workgroup_size << ", subgroups of " << l.subgroup_size << " (" << l.reason
                            << ")");
  CHECK(l.access != BufferAccess::automatic);
  CHECK(l.subgroup_size > 0);
  CHECK(l.workgroup_size <= ctx.limits().maxComputeWorkGroupInvocations);
  if (ctx.device_type() == VK_PHYSICAL_DEVICE_TYPE_CPU)
    CHECK(l.access == BufferAccess::texel_views);
  else
    CHECK(l.access == BufferAccess::storage_buffers);
}

TEST_CASE("Texel views and storage buffers give the same bits: grid with stencil, colliders, wind") {
  VKCLOTH_GPU_TEST_BEGIN(ctx);
  check_variants(ctx, grid_scene(),
                 {Integrator::semi_implicit_euler, Integrator::explicit_euler, Integrator::rk4});
}

TEST_CASE("Texel views and storage buffers give the same bits: mesh cloth") {
  VKCLOTH_GPU_TEST_BEGIN(ctx);
  check_variants(ctx, mesh_scene(), {Integrator::semi_implicit_euler, Integrator::rk4});
}

TEST_CASE("Texel views and storage buffers give the same bits: stretch control") {
  VKCLOTH_GPU_TEST_BEGIN(ctx);
  check_variants(ctx, stretch_scene(), {Integrator::semi_implicit_euler});
  // The tethers first asked for by set_params (their buffer made then; with storage buffers no
  // texel view of it is made).
  LayoutScene s = stretch_scene();
  SimParams plain = s.params;
  plain.stretch_limit.method = StretchLimit::Method::off;
  std::vector<glm::vec3> results[2];
  for (int k = 0; k < 2; ++k) {
    GpuSolverOptions o;
    o.buffer_access = k == 0 ? BufferAccess::texel_views : BufferAccess::storage_buffers;
    auto gpu = GpuSolver::create(ctx, s.system, plain, o);
    REQUIRE(gpu.ok());
    REQUIRE(gpu->simulate(10).ok());
    REQUIRE(gpu->set_params(s.params).ok());
    REQUIRE(gpu->simulate(30).ok());
    auto p = gpu->positions();
    REQUIRE(p.ok());
    results[k] = std::move(*p);
  }
  CHECK(diff(results[0], results[1]).bitwise);
}

TEST_CASE("Texel views and storage buffers give the same bits: a ClothWorld batch of three") {
  VKCLOTH_GPU_TEST_BEGIN(ctx);
  LayoutScene s = grid_scene();
  auto topology = ClothTopology::create(s.system);
  REQUIRE(topology.ok());
  std::vector<glm::vec3> results[2];
  for (int k = 0; k < 2; ++k) {
    WorldOptions wo;
    wo.solver.buffer_access = k == 0 ? BufferAccess::texel_views : BufferAccess::storage_buffers;
    auto world = ClothWorld::create(ctx, wo);
    REQUIRE(world.ok());
    std::vector<InstanceId> ids;
    for (int i = 0; i < 3; ++i) {
      SimParams p = s.params;
      p.wind.strength = 0.2 * i;
      auto id = world->add(*topology, p);
      REQUIRE(id.ok());
      ids.push_back(*id);
    }
    REQUIRE(world->simulate(40).ok());
    for (InstanceId id : ids) {
      auto p = world->positions(id);
      REQUIRE(p.ok());
      results[k].insert(results[k].end(), p->begin(), p->end());
    }
  }
  CHECK(diff(results[0], results[1]).bitwise);
}

TEST_CASE("A workgroup size beyond the device's limits is refused, naming the limit") {
  VKCLOTH_GPU_TEST_BEGIN(ctx);
  LayoutScene s = grid_scene();
  GpuSolverOptions o;
  o.workgroup_size = ctx.limits().maxComputeWorkGroupInvocations + 1;
  auto gpu = GpuSolver::create(ctx, s.system, s.params, o);
  REQUIRE_FALSE(gpu.ok());
  CHECK(gpu.error().code == ErrorCode::unsupported);
  CHECK(gpu.error().message.find("maxComputeWorkGroupInvocations") != std::string::npos);
  CHECK(ctx.live_allocation_count() == 0);
}
