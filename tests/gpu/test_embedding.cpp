// Embedding (issue #7): a host-created device and command buffer, record_step / record_steps in
// the host's own submission, the host's VkAllocationCallbacks, many cloths in a ClothWorld.
#include "gpu_test_util.hpp"
#include "host_vulkan.hpp"

#include <cstddef>
#include <cstdlib>
#include <cstring>
#include <map>
#include <mutex>

namespace {

using namespace vkcloth;
using namespace vkcloth::gpu;
using vkcloth::gpu::test::diff;
using vkcloth::gpu::test::HostVulkan;

/// VkAllocationCallbacks that count calls and live allocations.
struct CountingAllocator {
  std::mutex m;
  std::map<void*, std::size_t> live; // pointer -> size
  std::uint64_t calls = 0;
  VkAllocationCallbacks callbacks{};

  CountingAllocator() {
    callbacks.pUserData = this;
    callbacks.pfnAllocation = [](void* user, std::size_t size, std::size_t align, VkSystemAllocationScope) -> void* {
      return static_cast<CountingAllocator*>(user)->allocate(size, align);
    };
    callbacks.pfnReallocation = [](void* user, void* old, std::size_t size, std::size_t align, VkSystemAllocationScope) -> void* {
      auto& a = *static_cast<CountingAllocator*>(user);
      if (!old) return a.allocate(size, align);
      if (size == 0) return a.release(old), nullptr;
      std::size_t old_size;
      {
        const std::lock_guard lock(a.m);
        old_size = a.live.at(old);
      }
      void* p = a.allocate(size, align);
      if (p) std::memcpy(p, old, std::min(size, old_size));
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
    if (p) live[p] = size;
    return p;
  }
  void release(void* p) {
    if (!p) return;
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

std::shared_ptr<const ParticleSystem> make_topology(std::uint32_t nx, std::uint32_t ny, bool horizontal = false) {
  ClothDesc d;
  d.nx = nx;
  d.ny = ny;
  if (horizontal) {
    d.orientation = ClothOrientation::horizontal;
    d.origin = {-0.5, -0.5, 0.3};
    d.pin_default_corners = false;
  }
  auto s = make_cloth(d);
  REQUIRE(s.ok());
  return std::make_shared<const ParticleSystem>(std::move(s.value()));
}

std::unique_ptr<HostVulkan> host_or_skip(std::string& error) {
  auto h = HostVulkan::create(error);
  if (!h && vkcloth::gpu::test::on_ci()) FAIL("CI=true but the test host could not create its device: " << error);
  if (!h) MESSAGE("skipped: " << error);
  return h;
}

HostHandles handles_of(const HostVulkan& h, const VkAllocationCallbacks* allocator) {
  HostHandles hh;
  hh.instance = h.instance;
  hh.physical_device = h.physical_device;
  hh.device = h.device;
  hh.queue_family = h.family;
  hh.queue = h.queue;
  hh.get_instance_proc_addr = h.get_instance_proc_addr;
  hh.allocator = allocator;
  return hh;
}

} // namespace

TEST_CASE("Embedding: host device and command buffer, record_step/record_steps, allocation callbacks") {
  VKCLOTH_GPU_TEST_BEGIN(ctx); // the standalone reference runs on the shared validated Context
  std::string error;
  auto host = host_or_skip(error);
  if (!host) return;
  CountingAllocator counter;
  auto topo = make_topology(11, 7);
  SimParams params;
  params.wind.strength = 0.02;
  params.wind.direction = {0.3, 1.0, 0.1};

  auto reference = GpuSolver::create(ctx, *topo, params);
  REQUIRE(reference.ok());
  REQUIRE(reference->simulate(10).ok());
  const auto ref_pos = reference->positions();
  REQUIRE(ref_pos.ok());
  std::uint64_t calls_before_set_params = 0, calls_after_set_params = 0;
  {
    auto adopted = Context::adopt(handles_of(*host, &counter.callbacks));
    REQUIRE(adopted.ok());
    CHECK(adopted->handles().allocator == &counter.callbacks);
    auto gpu = GpuSolver::create(*adopted, *topo, params);
    REQUIRE(gpu.ok());
    CHECK(counter.live_count() > 0); // vkcloth's objects went through the host's callbacks
    REQUIRE(host->begin());
    for (int k = 0; k < 3; ++k) gpu->record_step(host->cmd);
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
    std::shared_ptr<const ParticleSystem> topo;
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
    auto g = GpuSolver::create(ctx, *c.topo, c.params);
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
    CHECK_MESSAGE(d.bitwise, when << ": instance " << k << " differs from its own GpuSolver by " << d.max_abs);
    const auto wv = world->velocities(ids[k]);
    const auto av = alone[k].velocities();
    REQUIRE(wv.ok());
    REQUIRE(av.ok());
    CHECK(diff(*wv, *av).bitwise);
  };
  REQUIRE(world->simulate(15).ok());
  for (auto& g : alone) REQUIRE(g.simulate(15).ok());
  for (std::size_t k = 0; k < 4; ++k) compare(k, "after 15 steps");

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
  for (const Particle& q : small->particles) init.positions.push_back(q.position + glm::dvec3(0.0, 0.0, 0.25));
  auto late = world->add(small, p0, init);
  REQUIRE(late.ok());
  ParticleSystem moved = *small;
  for (std::size_t p = 0; p < moved.particles.size(); ++p) moved.particles[p].position = init.positions[p];
  auto late_alone = GpuSolver::create(ctx, moved, p0);
  REQUIRE(late_alone.ok());

  REQUIRE(world->simulate(12, 5).ok());
  for (std::size_t k : {0u, 2u, 3u}) REQUIRE(alone[k].simulate(12).ok());
  REQUIRE(late_alone->simulate(12).ok());
  for (std::size_t k : {0u, 2u, 3u}) compare(k, "after remove + set_params + 12 steps");
  const auto wl = world->positions(*late);
  const auto al = late_alone->positions();
  REQUIRE(wl.ok());
  REQUIRE(al.ok());
  CHECK(diff(*wl, *al).bitwise);
  // The parameter change mattered: the instance no longer matches the unchanged parameters.
  auto unchanged = GpuSolver::create(ctx, *small, p0);
  REQUIRE(unchanged.ok());
  REQUIRE(unchanged->simulate(27).ok());
  CHECK(!diff(*world->positions(ids[0]), *unchanged->positions()).bitwise);

  // Buffers for drawing.
  const auto bufs = world->buffers(ids[3]);
  REQUIRE(bufs.ok());
  CHECK(bufs->positions == world->solver(ids[3])->current_position_buffer());
  CHECK(bufs->count == 15u * 13u);
  CHECK(bufs->nx == 15u);
  CHECK(grid_triangle_indices(bufs->nx, bufs->ny).size() == 14u * 12u * 6u);
  CHECK(!world->add(nullptr, p0).ok());
  InitialState wrong;
  wrong.positions.resize(3);
  CHECK(world->add(small, p0, wrong).error().code == ErrorCode::invalid_argument);
}
