// SPDX-License-Identifier: MIT
// Context and error paths: device filters, adopting a host's handles, size limits, bad input.
#include "gpu_test_util.hpp"
#include "vkcloth/gpu/testing.hpp"

using namespace vkcloth;
using namespace vkcloth::gpu;
using namespace vkcloth::gpu::test;

TEST_CASE("Context: a device filter that matches nothing is ErrorCode::no_device") {
  ContextOptions o;
  o.device_filter = "no-such-device-1f2e3d";
  o.validation = false;
  auto c = Context::create(o);
  REQUIRE(!c.ok());
  CHECK(c.error().code == ErrorCode::no_device);
  MESSAGE(c.error().message);
  if (shared_context().context)
    CHECK(c.error().message.find("no-such-device-1f2e3d") != std::string::npos);
  o.device_filter = "4096"; // an index past the end
  auto c2 = Context::create(o);
  REQUIRE(!c2.ok());
  CHECK(c2.error().code == ErrorCode::no_device);
}

TEST_CASE("Context: picks a device, lists devices, selects by index and name") {
  VKCLOTH_GPU_TEST_BEGIN(ctx);
  CHECK(ctx.owns_device());
  CHECK(!ctx.device_name().empty());
  auto list = Context::list_devices();
  REQUIRE(list.ok());
  REQUIRE(!list->empty());
  const auto usable = std::find_if(list->begin(), list->end(), [](const DeviceInfo& d) { return d.usable; });
  REQUIRE(usable != list->end());
  ContextOptions by_index;
  by_index.device_filter = std::to_string(usable->index);
  by_index.validation = true;
  auto c = Context::create(by_index);
  REQUIRE(c.ok());
  CHECK(c->device_name() == usable->name);
  ContextOptions by_name;
  by_name.device_filter = usable->name.substr(0, 4);
  by_name.validation = true;
  auto c2 = Context::create(by_name);
  REQUIRE(c2.ok());
  CHECK(c->validation_message_count() == 0);
  CHECK(c2->validation_message_count() == 0);
}

TEST_CASE("Context: adopting a host's handles destroys none of them") {
  VKCLOTH_GPU_TEST_BEGIN(ctx);
  auto cloth = make_cloth(ClothDesc{});
  REQUIRE(cloth.ok());
  {
    auto adopted = Context::adopt(ctx.handles());
    REQUIRE(adopted.ok());
    CHECK(!adopted->owns_device());
    CHECK(adopted->device_name() == ctx.device_name());
    auto gpu = GpuSolver::create(*adopted, *cloth, SimParams{});
    REQUIRE(gpu.ok());
    REQUIRE(gpu->simulate(10).ok());
  } // adopted Context and its solver gone; the host's device must still work
  auto gpu = GpuSolver::create(ctx, *cloth, SimParams{});
  REQUIRE(gpu.ok());
  REQUIRE(gpu->simulate(10).ok());
  CHECK(ctx.wait_idle().ok());
  HostHandles incomplete = ctx.handles();
  incomplete.queue = VK_NULL_HANDLE;
  CHECK(Context::adopt(incomplete).error().code == ErrorCode::invalid_argument);
}

TEST_CASE("GpuSolver: a system too large for the device is refused before allocation") {
  VKCLOTH_GPU_TEST_BEGIN(ctx);
  auto cloth = make_cloth(ClothDesc{});
  REQUIRE(cloth.ok());
  testing::SolverKnobs o;
  o.max_storage_buffer_bytes = 1024; // 100 particles x 16 bytes = 1600 > 1024
  auto gpu = testing::create_solver(ctx, *cloth, SimParams{}, {}, o);
  REQUIRE(!gpu.ok());
  CHECK(gpu.error().code == ErrorCode::unsupported);
  CHECK(gpu.error().message.find("too large") != std::string::npos);
  CHECK(gpu.error().message.find("1600") != std::string::npos);
  CHECK(gpu.error().message.find("1024") != std::string::npos);
  MESSAGE(gpu.error().message);
  // Past the device's real limit (maxStorageBufferRange): a description is enough, no allocation
  // happens; only the particle list is built (~40 B per particle on the host).
  const std::uint64_t limit = ctx.limits().maxStorageBufferRange;
  if (limit / 16 + 1 <= 20'000'000) {
    ParticleSystem big;
    big.particles.resize(limit / 16 + 1);
    big.finalize();
    auto g2 = GpuSolver::create(ctx, big, SimParams{});
    REQUIRE(!g2.ok());
    CHECK(g2.error().code == ErrorCode::unsupported);
    CHECK(g2.error().message.find("maxStorageBufferRange") != std::string::npos);
  }
}

TEST_CASE("GpuSolver: invalid input is ErrorCode::invalid_argument") {
  VKCLOTH_GPU_TEST_BEGIN(ctx);
  ParticleSystem empty;
  empty.finalize();
  CHECK(GpuSolver::create(ctx, empty, SimParams{}).error().code == ErrorCode::invalid_argument);
  auto cloth = make_cloth(ClothDesc{});
  REQUIRE(cloth.ok());
  SimParams p;
  p.dt = 0;
  CHECK(GpuSolver::create(ctx, *cloth, p).error().code == ErrorCode::invalid_argument);
  ParticleSystem unfinalized = *cloth;
  unfinalized.adjacency = {};
  CHECK(GpuSolver::create(ctx, unfinalized, SimParams{}).error().code == ErrorCode::invalid_argument);
}

TEST_CASE("GpuSolver: uvs and buffers of a grid") {
  VKCLOTH_GPU_TEST_BEGIN(ctx);
  ClothDesc d;
  d.nx = 37;
  d.ny = 23;
  auto cloth = make_cloth(d);
  REQUIRE(cloth.ok());
  auto gpu = GpuSolver::create(ctx, *cloth, SimParams{});
  REQUIRE(gpu.ok());
  CHECK(gpu->particle_count() == 37 * 23);
  const auto& uv = gpu->uvs();
  REQUIRE(uv.size() == 37 * 23);
  CHECK(uv[0] == glm::vec2(0, 0));
  CHECK(uv[36] == glm::vec2(1, 0));
  CHECK(uv[22 * 37] == glm::vec2(0, 1));
  CHECK(uv[22 * 37 + 18] == glm::vec2(0.5f, 1));
  CHECK(gpu->normal_buffer() != VK_NULL_HANDLE);
  CHECK(gpu->uv_buffer() != VK_NULL_HANDLE);
  CHECK(gpu->velocity_buffer() != VK_NULL_HANDLE);
  // Before any step the normals are zero (as on the CPU) and the forces too.
  auto n = gpu->normals();
  REQUIRE(n.ok());
  CHECK((*n)[5] == glm::vec3(0));
  // After one step the normals of a flat vertical (x-z) cloth point along -y or +y.
  REQUIRE(gpu->simulate(1).ok());
  n = gpu->normals();
  REQUIRE(n.ok());
  CHECK(std::abs(std::abs((*n)[400].y) - 1.0f) < 1e-6f);
  auto f = gpu->forces();
  REQUIRE(f.ok());
  CHECK((*f)[400].z < 0.0f); // gravity on a free particle at rest
}

TEST_CASE("Context: the validation messenger counts real errors, sync validation included") {
  VKCLOTH_GPU_TEST_BEGIN(shared_ctx);
  // A Context of its own, so the deliberate errors below do not touch the shared count.
  ContextOptions o;
  o.validation = true;
  o.print_validation_messages = false;
  auto c = Context::create(o);
  REQUIRE(c.ok());
  Context& ctx = *c;
  const HostHandles h = ctx.handles();
  const auto gdpa = ctx.device_proc_addr();
#define LOAD(name)                                                                                           \
  const auto name = reinterpret_cast<PFN_##name>(gdpa(h.device, #name));                                     \
  REQUIRE((name != nullptr ? true : false))
  LOAD(vkCreateCommandPool);
  LOAD(vkDestroyCommandPool);
  LOAD(vkAllocateCommandBuffers);
  LOAD(vkBeginCommandBuffer);
  LOAD(vkEndCommandBuffer);
  LOAD(vkCmdCopyBuffer);
  LOAD(vkQueueSubmit);
  LOAD(vkQueueWaitIdle);
#undef LOAD
  auto cloth = make_cloth(ClothDesc{});
  REQUIRE(cloth.ok());
  auto gpu = GpuSolver::create(ctx, *cloth, SimParams{});
  REQUIRE(gpu.ok());
  CHECK(ctx.validation_message_count() == 0);

  VkCommandPoolCreateInfo pi{};
  pi.sType = VK_STRUCTURE_TYPE_COMMAND_POOL_CREATE_INFO;
  pi.queueFamilyIndex = h.queue_family;
  VkCommandPool pool = VK_NULL_HANDLE;
  REQUIRE(vkCreateCommandPool(h.device, &pi, nullptr, &pool) == VK_SUCCESS);
  VkCommandBufferAllocateInfo ai{};
  ai.sType = VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO;
  ai.commandPool = pool;
  ai.level = VK_COMMAND_BUFFER_LEVEL_PRIMARY;
  ai.commandBufferCount = 1;
  VkCommandBuffer cb = VK_NULL_HANDLE;
  REQUIRE(vkAllocateCommandBuffers(h.device, &ai, &cb) == VK_SUCCESS);
  VkCommandBufferBeginInfo bi{};
  bi.sType = VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO;
  REQUIRE(vkBeginCommandBuffer(cb, &bi) == VK_SUCCESS);
  gpu->record_steps(cb, 1);
  // Deliberate hazard: copy the positions just written by the last dispatch WITHOUT the barrier
  // record_barrier_to() would add (read-after-write for synchronization validation).
  const VkBufferCopy region{0, 0, 16};
  vkCmdCopyBuffer(cb, gpu->current_position_buffer(),
                  gpu->position_buffer(gpu->current_position_index() ^ 1u), 1, &region);
  REQUIRE(vkEndCommandBuffer(cb) == VK_SUCCESS);
  const std::uint64_t before_submit = ctx.validation_message_count();
  CHECK(before_submit >= 1); // the hazard is reported at record time
  VkSubmitInfo si{};
  si.sType = VK_STRUCTURE_TYPE_SUBMIT_INFO;
  si.commandBufferCount = 1;
  si.pCommandBuffers = &cb;
  REQUIRE(vkQueueSubmit(h.queue, 1, &si, VK_NULL_HANDLE) == VK_SUCCESS);
  REQUIRE(vkQueueWaitIdle(h.queue) == VK_SUCCESS);
  vkDestroyCommandPool(h.device, pool, nullptr);
  MESSAGE("deliberate hazard: " << ctx.validation_message_count() << " validation message(s)");
}

TEST_CASE("Context: pipelines are made once per Context and shared by every solver and world batch") {
  VKCLOTH_GPU_TEST_BEGIN(ctx);
  ClothDesc d;
  d.nx = 11;
  d.ny = 9;
  auto cloth = make_cloth(d);
  REQUIRE(cloth.ok());
  SimParams params;
  auto first = GpuSolver::create(ctx, *cloth, params);
  REQUIRE(first.ok());
  const std::size_t made = testing::pipeline_count(ctx);
  CHECK(made > 0);
  // A second solver of the same cloth (same stencil) and a world with two of them make none.
  auto second = GpuSolver::create(ctx, *cloth, params);
  REQUIRE(second.ok());
  CHECK(testing::pipeline_count(ctx) == made);
  auto world = ClothWorld::create(ctx);
  REQUIRE(world.ok());
  auto topology = ClothTopology::create(*cloth);
  REQUIRE(topology.ok());
  auto a = world->add(*topology, params);
  auto b = world->add(*topology, params);
  REQUIRE(a.ok());
  REQUIRE(b.ok());
  REQUIRE(world->remove(*a).ok());
  CHECK(testing::pipeline_count(ctx) == made);
  // Colliders need the fused variants with contacts: made once, then shared.
  SimParams with_sphere = params;
  with_sphere.colliders.push_back(Collider::sphere({0.5, 0.5, -1.0}, 0.3));
  REQUIRE(first->set_params(with_sphere).ok());
  const std::size_t with_contacts = testing::pipeline_count(ctx);
  REQUIRE(second->set_params(with_sphere).ok());
  REQUIRE(world->set_params(*b, with_sphere).ok());
  CHECK(testing::pipeline_count(ctx) == with_contacts);
  REQUIRE(first->simulate(3).ok());
  REQUIRE(world->simulate(3).ok());
}
