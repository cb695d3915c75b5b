// SPDX-License-Identifier: MIT
// Vulkan failure paths: an allocation failing at any point of a solver's life is a clear
// error, everything allocated before it is released, and the Context stays usable.
#include <string>

#include "gpu_test_util.hpp"
#include "vkcloth/gpu/testing.hpp"

using namespace vkcloth;
using namespace vkcloth::gpu;

namespace {

/// Makes the nth device memory allocation on `ctx` fail for the scope (testing.hpp).
struct FailAllocation {
  FailAllocation(Context& ctx, unsigned n) : ctx_(ctx) {
    testing::set_allocation_failure_hook(ctx, [n, count = 0u]() mutable { return ++count == n; });
  }
  ~FailAllocation() { testing::set_allocation_failure_hook(ctx_, {}); }
  FailAllocation(const FailAllocation&) = delete;
  FailAllocation& operator=(const FailAllocation&) = delete;

private:
  Context& ctx_;
};

bool is_injected_oom(const Error& e) {
  return e.code == ErrorCode::out_of_memory &&
         e.message.find("VK_ERROR_OUT_OF_DEVICE_MEMORY") != std::string::npos;
}

} // namespace

TEST_CASE("GpuSolver: out of device memory at every allocation is reported, leaks nothing, keeps the Context "
          "usable") {
  VKCLOTH_GPU_TEST_BEGIN(ctx);
  ClothDesc d;
  d.nx = 12;
  d.ny = 9;
  auto cloth = make_cloth(d);
  REQUIRE(cloth.ok());
  SimParams params;
  params.colliders.push_back(Collider::sphere({0.5, 0.5, -1.0}, 0.3));
  for (bool staging : {false, true}) {
    CAPTURE(staging);
    testing::SolverKnobs o;
    o.force_staging = staging;
    REQUIRE(ctx.live_allocation_count() == 0);
    unsigned failures = 0;
    for (unsigned n = 1; n < 200; ++n) {
      CAPTURE(n);
      bool failed = false;
      {
        FailAllocation hook(ctx, n);
        auto gpu = testing::create_solver(ctx, *cloth, params, {}, o);
        if (!gpu.ok()) {
          CHECK_MESSAGE(is_injected_oom(gpu.error()), gpu.error().message);
          CHECK(gpu.error().message.find("vkAllocateMemory") != std::string::npos);
          failed = true;
        } else {
          // Allocations after creation (readbacks, staging) fail cleanly too.
          auto sim = gpu->simulate(3);
          if (!sim.ok()) {
            CHECK_MESSAGE(is_injected_oom(sim.error()), sim.error().message);
            failed = true;
          }
          auto pos = gpu->positions();
          if (!pos.ok()) {
            CHECK_MESSAGE(is_injected_oom(pos.error()), pos.error().message);
            failed = true;
          }
        }
      }
      CHECK(ctx.live_allocation_count() == 0); // everything released, solver or not
      if (!failed)
        break;
      ++failures;
    }
    CHECK(failures >= 5); // the walk really went through the solver's buffers
    MESSAGE("staging=" << staging << ": " << failures << " allocation points failed cleanly");
    // The Context works as before.
    auto gpu = testing::create_solver(ctx, *cloth, params, {}, o);
    REQUIRE(gpu.ok());
    REQUIRE(gpu->simulate(20).ok());
    CHECK(gpu->positions().ok());
    CHECK(ctx.wait_idle().ok());
  }
  CHECK(ctx.live_allocation_count() == 0);
}

TEST_CASE("GpuSolver: the max_storage_buffer_bytes limit refuses before allocating anything") {
  VKCLOTH_GPU_TEST_BEGIN(ctx);
  auto cloth = make_cloth(ClothDesc{});
  REQUIRE(cloth.ok());
  testing::SolverKnobs o;
  o.max_storage_buffer_bytes = 16;
  auto gpu = testing::create_solver(ctx, *cloth, SimParams{}, {}, o);
  REQUIRE(!gpu.ok());
  CHECK(gpu.error().code == ErrorCode::unsupported);
  CHECK(ctx.live_allocation_count() == 0);
}

TEST_CASE("GpuSolver: simulate with steps_per_submit = 0 is an error, not a hang") {
  VKCLOTH_GPU_TEST_BEGIN(ctx);
  auto cloth = make_cloth(ClothDesc{});
  REQUIRE(cloth.ok());
  auto gpu = GpuSolver::create(ctx, *cloth, SimParams{});
  REQUIRE(gpu.ok());
  auto r = gpu->simulate(10, 0);
  REQUIRE(!r.ok());
  CHECK(r.error().code == ErrorCode::invalid_argument);
  CHECK(r.error().message.find("steps_per_submit") != std::string::npos);
  CHECK(gpu->simulate(0).ok());
  CHECK(gpu->step_index() == 0);
}

TEST_CASE("Context: a device filter that selects nothing leaves nothing behind and a later Context works") {
  ContextOptions o;
  o.device_filter = "no-such-device-xyz";
  o.validation = false;
  for (int k = 0; k < 3; ++k) {
    auto c = Context::create(o);
    REQUIRE(!c.ok());
    CHECK(c.error().code == ErrorCode::no_device);
    CHECK(c.error().message.find("no-such-device-xyz") != std::string::npos);
  }
  VKCLOTH_GPU_TEST_BEGIN(ctx);
  auto cloth = make_cloth(ClothDesc{});
  REQUIRE(cloth.ok());
  auto gpu = GpuSolver::create(ctx, *cloth, SimParams{});
  REQUIRE(gpu.ok());
  CHECK(gpu->simulate(5).ok());
}

TEST_CASE("GpuSolver: the interleaved vertices and the tethers are held to the storage limit too, "
          "the error naming the buffer") {
  VKCLOTH_GPU_TEST_BEGIN(ctx);
  ChainDesc chain; // 20 masses below an anchor: 21 particles, 40 gather entries
  chain.masses.assign(20, 0.1);
  chain.stiffness.assign(20, 50.0);
  chain.rest_lengths.assign(20, 0.05);
  chain.positions.clear();
  for (int k = 1; k <= 20; ++k)
    chain.positions.push_back({0.0, 0.0, -0.05 * k});
  auto system = make_chain(chain);
  REQUIRE(system.ok());
  auto topo = ClothTopology::create(*system);
  REQUIRE(topo.ok());
  const std::uint64_t n = (*topo)->size();
  // Every other buffer fits in 660 bytes (the largest: 40 gather entries of 16 bytes); the vertices
  // need 32 n = 672, the tethers 64 n = 1344.
  REQUIRE(std::max<std::uint64_t>(
              {16 * n, (*topo)->edges().size() * 16, (*topo)->strain_links().size() * 12}) <= 660);
  testing::SolverKnobs knobs;
  knobs.max_storage_buffer_bytes = 660;
  CHECK(testing::create_solver(ctx, *topo, SimParams{}, {}, knobs).ok());
  GpuSolverOptions interleaved;
  interleaved.interleaved_vertices = true;
  auto refused = testing::create_solver(ctx, *topo, SimParams{}, interleaved, knobs);
  REQUIRE_FALSE(refused.ok());
  CHECK(refused.error().code == ErrorCode::unsupported);
  CHECK(refused.error().message.find("interleaved vertices buffer needs 672 bytes") != std::string::npos);

  knobs.max_storage_buffer_bytes = 700;
  SimParams tethered;
  tethered.stretch_limit.method = StretchLimit::Method::tethers;
  auto no_room = testing::create_solver(ctx, *topo, tethered, {}, knobs);
  REQUIRE_FALSE(no_room.ok());
  CHECK(no_room.error().message.find("tethers buffer needs 1344 bytes") != std::string::npos);
  // Asked for later (set_params): the same refusal, and the solver keeps working without them.
  auto plain = testing::create_solver(ctx, *topo, SimParams{}, {}, knobs);
  REQUIRE(plain.ok());
  auto later = plain->set_params(tethered);
  REQUIRE_FALSE(later.ok());
  CHECK(later.error().message.find("tethers") != std::string::npos);
  CHECK_FALSE(plain->params().stretch_limit.enabled()); // the old parameters stay
  REQUIRE(plain->simulate(5).ok());
  auto reference = GpuSolver::create(ctx, *topo, SimParams{});
  REQUIRE(reference.ok());
  REQUIRE(reference->simulate(5).ok());
  CHECK(test::diff(*plain->positions(), *reference->positions()).bitwise);
}
