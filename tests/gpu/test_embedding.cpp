// SPDX-License-Identifier: MIT
// Embedding: a host-created device and command buffer, record_step / record_steps in
// the host's own submission, the host's VkAllocationCallbacks, the queue-family hand-over; many
// cloths in a ClothWorld: test_cloth_world.cpp.
#include "embedding_host.hpp"
#include "gpu_test_util.hpp"
#include "host_vulkan.hpp"
#include "vkcloth/gpu/testing.hpp"

#include <cmath>
#include <cstddef>
#include <cstdlib>
#include <cstring>
#include <map>
#include <mutex>
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

/// VkAllocationCallbacks that count calls and live allocations.
struct CountingAllocator {
  std::mutex m;
  std::map<void*, std::size_t> live; // pointer -> size
  std::uint64_t calls = 0;
  VkAllocationCallbacks callbacks{};

  CountingAllocator() {
    callbacks.pUserData = this;
    callbacks.pfnAllocation = [](void* user, std::size_t size, std::size_t align,
                                 VkSystemAllocationScope) -> void* {
      return static_cast<CountingAllocator*>(user)->allocate(size, align);
    };
    callbacks.pfnReallocation = [](void* user, void* old, std::size_t size, std::size_t align,
                                   VkSystemAllocationScope) -> void* {
      auto& a = *static_cast<CountingAllocator*>(user);
      if (!old)
        return a.allocate(size, align);
      if (size == 0)
        return a.release(old), nullptr;
      std::size_t old_size;
      {
        const std::lock_guard lock(a.m);
        old_size = a.live.at(old);
      }
      void* p = a.allocate(size, align);
      if (p)
        std::memcpy(p, old, std::min(size, old_size));
      a.release(old);
      return p;
    };
    callbacks.pfnFree = [](void* user, void* p) { static_cast<CountingAllocator*>(user)->release(p); };
  }
  void* allocate(std::size_t size, std::size_t align) {
    align = std::max<std::size_t>(align, alignof(std::max_align_t));
    void* p = std::aligned_alloc(align, (size + align - 1) / align * align);
    const std::lock_guard lock(m);
    ++calls;
    if (p)
      live[p] = size;
    return p;
  }
  void release(void* p) {
    if (!p)
      return;
    {
      const std::lock_guard lock(m);
      live.erase(p);
    }
    std::free(p);
  }
  std::size_t live_count() {
    const std::lock_guard lock(m);
    return live.size();
  }
  std::uint64_t call_count() {
    const std::lock_guard lock(m);
    return calls;
  }
};

} // namespace

TEST_CASE("Embedding: host device and command buffer, record_step/record_steps, allocation callbacks") {
  VKCLOTH_GPU_TEST_BEGIN(ctx); // the standalone reference runs on the shared validated Context
  std::string error;
  auto host = host_or_skip(error);
  if (!host)
    return;
  CountingAllocator counter;
  auto topo = make_topology(11, 7);
  SimParams params;
  params.wind.strength = 0.02;
  params.wind.direction = {0.3, 1.0, 0.1};

  auto reference = GpuSolver::create(ctx, topo, params);
  REQUIRE(reference.ok());
  REQUIRE(reference->simulate(10).ok());
  const auto ref_pos = reference->positions();
  REQUIRE(ref_pos.ok());
  std::uint64_t calls_before_set_params = 0, calls_after_set_params = 0;
  {
    auto adopted = Context::adopt(handles_of(*host, &counter.callbacks));
    REQUIRE(adopted.ok());
    CHECK(adopted->handles().allocator == &counter.callbacks);
    auto gpu = GpuSolver::create(*adopted, topo, params);
    REQUIRE(gpu.ok());
    CHECK(counter.live_count() > 0); // vkcloth's objects went through the host's callbacks
    REQUIRE(host->begin());
    for (int k = 0; k < 3; ++k)
      gpu->record_step(host->cmd);
    gpu->record_steps(host->cmd, 7);
    gpu->record_barrier_to(host->cmd, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_ACCESS_TRANSFER_READ_BIT);
    REQUIRE(host->submit_and_wait());
    CHECK(gpu->step_index() == 10);
    REQUIRE(gpu->check_divergence().ok());
    const auto pos = gpu->positions();
    REQUIRE(pos.ok());
    const auto d = diff(*pos, *ref_pos);
    CHECK_MESSAGE(d.bitwise, "host-recorded steps differ from the standalone solver by " << d.max_abs);

    // Parameters changed between steps: no Vulkan object is created (no callback at all).
    calls_before_set_params = counter.call_count();
    SimParams calm = params;
    calm.gravity = {0.0, 0.0, -3.0};
    REQUIRE(gpu->set_params(calm).ok());
    calls_after_set_params = counter.call_count();

    // A world on the host's device, recorded into the host's command buffer.
    auto world = ClothWorld::create(*adopted);
    REQUIRE(world.ok());
    auto a = world->add(topo, params);
    auto b = world->add(make_topology(6, 9), params);
    REQUIRE(a.ok());
    REQUIRE(b.ok());
    REQUIRE(host->begin());
    world->record_steps(host->cmd, 10);
    world->record_barrier_to(host->cmd, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_ACCESS_TRANSFER_READ_BIT);
    REQUIRE(host->submit_and_wait());
    const auto wa = world->positions(*a);
    REQUIRE(wa.ok());
    CHECK(diff(*wa, *ref_pos).bitwise);
  } // every vkcloth object on the host's device is gone
  CHECK(calls_after_set_params == calls_before_set_params);
  CHECK(counter.call_count() > 0);
  CHECK_MESSAGE(counter.live_count() == 0, counter.live_count() << " host allocations not freed by vkcloth");
  CHECK(host->still_usable());
  CHECK(host->messages.load() == 0);
}

TEST_CASE("flip_normals: the normals buffer points the other way, the physics is unchanged (bitwise)") {
  VKCLOTH_GPU_TEST_BEGIN(ctx);
  auto topo = make_topology(12, 9, true); // horizontal: normals +z by default (the header's rule)
  SimParams p;
  p.wind.strength = 0.05; // wind reads the normal: F = Kw <n, u> n is even in n
  p.wind.direction = {0.2, 0.1, 1.0};
  GpuSolverOptions flipped;
  flipped.flip_normals = true;
  for (bool fused : {true, false}) {
    GpuSolverOptions plain;
    plain.fused = flipped.fused = fused;
    auto a = GpuSolver::create(ctx, topo, p, plain);
    auto b = GpuSolver::create(ctx, topo, p, flipped);
    REQUIRE((a.ok() && b.ok()));
    REQUIRE((a->simulate(15).ok() && b->simulate(15).ok()));
    const auto xa = a->positions(), xb = b->positions(), na = a->normals(), nb = b->normals();
    REQUIRE((xa && xb && na && nb));
    CHECK(diff(*xa, *xb).bitwise);
    double mean_z = 0.0;
    bool opposite = true;
    for (std::size_t k = 0; k < na->size(); ++k) {
      mean_z += (*na)[k].z / double(na->size());
      opposite = opposite && (*nb)[k] == -(*na)[k];
    }
    CHECK(opposite);
    CHECK(mean_z > 0.9);
  }
}

namespace {

/// docs/embedding.md section 6, frame by frame: the compute side in frame_cmd[0] on `queue`
/// (family), the graphics side in graphics_cmd on graphics_queue (graphics_family), a semaphore
/// each way, a copy standing in for the draw; then the positions against a plain run.
/// `ownership` false: section 4's "Two submissions on one queue family", the semaphores alone (no
/// release / acquire, no record_barrier_to); `drawn_semaphore` false: on ONE queue, no semaphore
/// from the graphics submission to the next compute one (the recording's first barrier orders it).
void hand_over(HostVulkan& host, Context& reference_ctx, bool ownership = true, bool drawn_semaphore = true) {
  auto adopted = Context::adopt(handles_of(host, nullptr));
  REQUIRE(adopted.ok());
  auto topo = make_topology(10, 8);
  SimParams p;
  p.wind.strength = 0.03;
  auto world = ClothWorld::create(*adopted);
  REQUIRE(world.ok());
  auto id = world->add(topo, p);
  REQUIRE(id.ok());
  const std::uint32_t compute = host.family, graphics = host.graphics_family;
  VkSemaphore simulated = host.semaphores[0], drawn = drawn_semaphore ? host.semaphores[1] : VK_NULL_HANDLE;
  constexpr int frames = 6;
  for (int f = 0; f < frames; ++f) {
    REQUIRE(host.begin_frame(0)); // the compute queue's command buffer
    VkCommandBuffer c = host.frame_cmd[0];
    if (ownership && f > 0) // the buffers come back from the graphics family
      world->record_acquire(c, {graphics, compute, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT,
                                VK_ACCESS_SHADER_READ_BIT | VK_ACCESS_SHADER_WRITE_BIT});
    world->record_steps(c, 3);
    if (ownership)
      world->record_release(
          c, {compute, graphics, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, VK_ACCESS_SHADER_WRITE_BIT});
    REQUIRE(host.submit_frame(0, f > 0 ? drawn : VK_NULL_HANDLE,
                              drawn ? VkPipelineStageFlags(VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT)
                                    : VkPipelineStageFlags(0),
                              simulated));

    REQUIRE(host.begin_graphics());
    VkCommandBuffer g = host.graphics_cmd;
    // A renderer acquires for VERTEX_INPUT and draws; this host reads the buffers with a copy
    // (TRANSFER), so synchronization validation sees a real read after the compute writes.
    // Without ownership transfers the wait on `simulated` at TRANSFER alone orders the reads.
    if (ownership)
      world->record_acquire(g,
                            {compute, graphics, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_ACCESS_TRANSFER_READ_BIT});
    const InstanceBuffers b = world->buffers(*id).value();
    const VkDeviceSize bytes = b.count * b.stride, at = 2 * bytes * VkDeviceSize(f);
    REQUIRE(host.record_read(g, b.positions, bytes, at)); // each frame its own regions
    REQUIRE(host.record_read(g, b.normals, bytes, at + bytes));
    if (ownership)
      world->record_release(g, {graphics, compute, VK_PIPELINE_STAGE_TRANSFER_BIT, 0});
    REQUIRE(host.submit_graphics(simulated, VK_PIPELINE_STAGE_TRANSFER_BIT, drawn));
  }
  REQUIRE(host.wait_frames());
  if (compute != graphics) { // the last frame's buffers are the graphics family's: take them back
    REQUIRE(host.begin_frame(0));
    world->record_acquire(host.frame_cmd[0], {graphics, compute, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT,
                                              VK_ACCESS_SHADER_READ_BIT | VK_ACCESS_SHADER_WRITE_BIT});
    REQUIRE(host.submit_frame(0, drawn, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, VK_NULL_HANDLE));
    REQUIRE(host.wait_frames());
  }
  auto plain = GpuSolver::create(reference_ctx, topo, p);
  REQUIRE(plain.ok());
  REQUIRE(plain->simulate(3 * frames).ok());
  const auto want = plain->positions();
  const auto got = world->positions(*id);
  REQUIRE((want && got));
  CHECK(diff(*got, *want).bitwise);
  CHECK(host.messages.load() == 0);
}

} // namespace

TEST_CASE("Queue-family hand-over in the documented order, one queue: release/acquire and "
          "semaphores, validation-clean, the bits of a plain run") {
  VKCLOTH_GPU_TEST_BEGIN(ctx);
  std::string error;
  auto host = host_or_skip(error);
  if (!host)
    return;
  REQUIRE(host->graphics_family == host->family);
  hand_over(*host, ctx);
}

TEST_CASE("Two submissions on one queue family (computecloth's pattern): the semaphores replace "
          "record_barrier_to, validation-clean, the bits of a plain run") {
  VKCLOTH_GPU_TEST_BEGIN(ctx);
  std::string error;
  auto host = host_or_skip(error);
  if (!host)
    return;
  REQUIRE(host->graphics_family == host->family);
  REQUIRE(host->graphics_queue == host->queue);
  SUBCASE("a semaphore each way (also what two queues of the family need)") {
    hand_over(*host, ctx, false);
  }
  SUBCASE("one queue: the compute submission's semaphore only") {
    hand_over(*host, ctx, false, false);
  }
}

TEST_CASE("Queue-family hand-over between a compute-only family and a graphics family (where a "
          "device has both: not lavapipe)") {
  VKCLOTH_GPU_TEST_BEGIN(ctx);
  std::string error;
  auto host = HostVulkan::create(error, true);
  if (!host) {
    // Lavapipe has one family: this runs on a GPU with a dedicated compute family. Any other
    // failure (no loader, instance or device) fails on CI, as host_or_skip's.
    if (vkcloth::gpu::test::on_ci() && error.find("compute-only") == std::string::npos)
      FAIL("CI=true but the test host could not create its device: " << error);
    MESSAGE("skipped: " << error);
    return;
  }
  REQUIRE(host->graphics_family != host->family);
  hand_over(*host, ctx);
}

TEST_CASE("interleaved_vertices: one 32-byte vertex per particle holds the current position, the "
          "stored normal and the uv, in every integrator, the state is unchanged") {
  VKCLOTH_GPU_TEST_BEGIN(ctx);
  ClothDesc d;
  d.nx = 9;
  d.ny = 6;
  d.uv_transform = UvTransform{{0.0f, 1.0f}, {2.0f, 0.0f}, {0.0f, -1.0f}}; // not the default uvs
  auto topo = ClothTopology::create(make_cloth(d).value()).value();
  for (Integrator integrator :
       {Integrator::semi_implicit_euler, Integrator::rk4, Integrator::implicit_euler}) {
    CAPTURE(to_string(integrator));
    SimParams p;
    p.integrator = integrator;
    p.dt = 0.005;
    p.wind.strength = 0.03;
    GpuSolverOptions options;
    options.interleaved_vertices = true;
    options.flip_normals = true; // the vertices carry the normals as stored
    auto gpu = GpuSolver::create(ctx, topo, p, options);
    auto plain = GpuSolver::create(ctx, topo, p);
    REQUIRE((gpu.ok() && plain.ok()));
    REQUIRE((gpu->simulate(7, 3).ok() && plain->simulate(7, 3).ok())); // 3 recordings: 3 + 3 + 1 steps
    const auto v = testing::read_vertices(*gpu);
    const auto x = gpu->positions(), n = gpu->normals(), x_plain = plain->positions();
    REQUIRE((v && x && n && x_plain));
    CHECK(diff(*x, *x_plain).bitwise);
    CHECK(gpu->buffers().vertices != VK_NULL_HANDLE);
    CHECK(plain->buffers().vertices == VK_NULL_HANDLE);
    REQUIRE(v->size() == 8 * x->size());
    bool same = true;
    for (std::size_t i = 0; i < x->size(); ++i) {
      const float* w = v->data() + 8 * i;
      const glm::vec2 uv = topo->uvs()[i];
      same = same && glm::vec3(w[0], w[1], w[2]) == (*x)[i] && glm::vec3(w[3], w[4], w[5]) == (*n)[i] &&
             glm::vec2(w[6], w[7]) == uv;
    }
    CHECK(same);
  }
  auto without = GpuSolver::create(ctx, topo, SimParams{});
  REQUIRE(without.ok());
  CHECK_FALSE(testing::read_vertices(*without).ok());
}
