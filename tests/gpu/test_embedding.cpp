// SPDX-License-Identifier: MIT
// Embedding (issue #7): a host-created device and command buffer, record_step / record_steps in
// the host's own submission, the host's VkAllocationCallbacks, many cloths in a ClothWorld.
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

TEST_CASE("ClothWorld batches: instances with and without the fast projection, each bitwise == alone") {
  // One batch of a topology: the fast projection (two Newton budgets), the sweeps, nothing. The
  // projection's dispatches serve every instance of the batch (one workgroup each) and end when
  // the last projecting instance is done; the others skip them.
  VKCLOTH_GPU_TEST_BEGIN(ctx);
  auto topo = make_topology(12, 9);
  std::vector<SimParams> params(4);
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
  if (!host) { // lavapipe has one family: this runs on a GPU with a dedicated compute family
    MESSAGE("skipped: " << error);
    return;
  }
  REQUIRE(host->graphics_family != host->family);
  hand_over(*host, ctx);
}

TEST_CASE("interleaved_vertices: one 32-byte vertex per particle holds the current position, the "
          "stored normal and the uv, in every integrator; the state is unchanged") {
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
