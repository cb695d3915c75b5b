// SPDX-License-Identifier: MIT
// `--backend auto` (render, view, the samples): the choice (gpu::choose_backend), and the CPU
// path it takes on lavapipe: CpuSolver<float> drawn from render::HostClothBuffers must give the
// frame the GPU solver gives drawn from its own buffers (bit for bit on a CPU device, where the
// two solvers agree bit for bit; else within the golden-image metric).
#include "render_test_util.hpp"

#include "vkcloth/cpu_solver.hpp"
#include "vkcloth/gpu/backend_choice.hpp"
#include "vkcloth/render/host_buffers.hpp"

using namespace vkcloth;
using namespace vkcloth::render;
using namespace vkcloth::render::test;

TEST_CASE(
    "backend auto: the CPU solver on a CPU device and the GPU solver on every other type (with the reason)") {
  const gpu::BackendChoice cpu = gpu::choose_backend(VK_PHYSICAL_DEVICE_TYPE_CPU, "llvmpipe (LLVM 15)");
  CHECK(cpu.backend == gpu::Backend::cpu);
  CHECK(std::string(gpu::to_string(cpu.backend)) == "cpu");
  CHECK(cpu.reason.find("llvmpipe (LLVM 15)") != std::string::npos);
  CHECK(cpu.reason.find("CPU implementation of Vulkan") != std::string::npos);
  CHECK(cpu.reason.find("faster") != std::string::npos);
  const std::pair<VkPhysicalDeviceType, const char*> gpus[] = {
      {VK_PHYSICAL_DEVICE_TYPE_DISCRETE_GPU, "a discrete GPU"},
      {VK_PHYSICAL_DEVICE_TYPE_INTEGRATED_GPU, "an integrated GPU"},
      {VK_PHYSICAL_DEVICE_TYPE_VIRTUAL_GPU, "a virtual GPU"},
      {VK_PHYSICAL_DEVICE_TYPE_OTHER, "not a CPU device"}};
  for (const auto& [type, words] : gpus) {
    CAPTURE(words);
    const gpu::BackendChoice c = gpu::choose_backend(type, "Some GPU");
    CHECK(c.backend == gpu::Backend::vulkan);
    CHECK(std::string(gpu::to_string(c.backend)) == "vulkan");
    CHECK(c.reason.find("Some GPU") != std::string::npos);
    CHECK(c.reason.find(words) != std::string::npos);
    CHECK(c.reason.find("nothing crosses the bus") != std::string::npos);
  }
}

namespace {

/// The scene's frame after `steps` steps, drawn by the GPU solver from its buffers and by the CPU
/// solver from HostClothBuffers (slot `slot`), on the same target and renderer.
void same_frame_on_both(gpu::Context& ctx, const std::string& file, std::uint32_t steps,
                        const std::string& golden) {
  auto rig = make_rig(ctx, load(file), 160, 120);
  auto gpu_img = rig->target.render(rig->solver, rig->renderer, rig->camera, steps);
  REQUIRE_MESSAGE(gpu_img, (gpu_img ? "" : gpu_img.error().message));

  auto cpu = CpuSolver<float>::create(rig->solver.topology(), rig->scene.params);
  REQUIRE_MESSAGE(cpu, (cpu ? "" : cpu.error().message));
  REQUIRE(cpu->run(steps));
  auto host = HostClothBuffers::create(ctx, *cpu->topology(), 2);
  REQUIRE_MESSAGE(host, (host ? "" : host.error().message));
  for (std::uint32_t slot : {0u, 1u}) {
    CAPTURE(slot);
    auto buffers = host->upload(slot, cpu->positions(), cpu->normals());
    REQUIRE_MESSAGE(buffers, (buffers ? "" : buffers.error().message));
    auto cpu_img = rig->target.render(*buffers, rig->renderer, rig->camera);
    REQUIRE_MESSAGE(cpu_img, (cpu_img ? "" : cpu_img.error().message));
    if (ctx.device_type() == VK_PHYSICAL_DEVICE_TYPE_CPU) // lavapipe: the same bits in, the same pixels out
      CHECK(cpu_img->rgba == gpu_img->rgba);
    CHECK(compare(*cpu_img, *gpu_img).fraction < golden_max_fraction);
    check_golden(golden, *cpu_img); // the GPU path's golden image
  }
}

} // namespace

TEST_CASE("backend auto: the CPU solver drawn from HostClothBuffers gives the GPU solver's frame") {
  VKCLOTH_RENDER_TEST_BEGIN(ctx);
  SUBCASE("a cloth on the sphere") {
    same_frame_on_both(ctx, "cloth_on_sphere.json", 16, "cloth_on_sphere");
  }
  SUBCASE("a chain (masses instanced at the uploaded positions)") {
    same_frame_on_both(ctx, "spring.json", 20, "spring");
  }
}

TEST_CASE(
    "backend auto: HostClothBuffers slots are separate buffers and wrong sizes or slot counts are errors") {
  VKCLOTH_RENDER_TEST_BEGIN(ctx);
  auto cloth = load("cloth_hanging.json");
  auto topology = ClothTopology::create(cloth.system);
  REQUIRE(topology);
  auto host = HostClothBuffers::create(ctx, **topology, 3);
  REQUIRE(host);
  CHECK(host->slots() == 3);
  CHECK(host->particle_count() == (*topology)->size());
  const std::vector<glm::vec3> x((*topology)->size(), glm::vec3(0.0f));
  auto a = host->upload(0, x, x), b = host->upload(1, x, x), c = host->upload(3, x, x);
  REQUIRE(a);
  REQUIRE(b);
  REQUIRE(c);
  CHECK(a->positions != b->positions);
  CHECK(a->normals != b->normals);
  CHECK(c->positions == a->positions); // slot 3 of 3 is slot 0
  CHECK(a->uvs == b->uvs);
  CHECK(a->index_count == (*topology)->triangles().size());
  auto short_normals = host->upload(0, x, std::span<const glm::vec3>(x).first(3));
  REQUIRE_FALSE(short_normals);
  CHECK(short_normals.error().code == ErrorCode::invalid_argument);
  CHECK(short_normals.error().message.find("3 normals") != std::string::npos);
  auto none = HostClothBuffers::create(ctx, **topology, 0);
  REQUIRE_FALSE(none);
  CHECK(none.error().code == ErrorCode::invalid_argument);
  CHECK(none.error().message.find("frame in flight") != std::string::npos);
}

TEST_CASE("backend auto: a held particle moves the CPU solver as record_hold_particle moves the GPU's") {
  // `vkcloth view`'s drag on the CPU path is CpuSolver::set_particle(index, position, 0) before the
  // frame's steps (host::DrawnCloth); on the GPU, record_hold_particle. Same state after.
  VKCLOTH_RENDER_TEST_BEGIN(ctx);
  auto rig = make_rig(ctx, load("cloth_on_sphere.json"), 64, 48);
  auto cpu = CpuSolver<float>::create(rig->solver.topology(), rig->scene.params);
  REQUIRE(cpu);
  REQUIRE(rig->solver.simulate(5));
  REQUIRE(cpu->run(5));
  const std::uint32_t held = 37;
  const glm::vec3 where(0.2f, -0.1f, 1.5f);
  auto img = rig->target.render(rig->solver, rig->renderer, rig->camera, 3, [&](VkCommandBuffer cmd) {
    record_hold_particle(ctx, cmd, rig->solver, held, where);
  });
  REQUIRE(img);
  REQUIRE(cpu->set_particle(held, where, glm::vec3(0.0f)));
  REQUIRE(cpu->run(3));
  auto p = rig->solver.positions();
  REQUIRE(p);
  const gpu::test::Diff d = gpu::test::diff(*p, cpu->positions());
  CHECK(d.max_abs < 1e-5);
  if (ctx.device_type() == VK_PHYSICAL_DEVICE_TYPE_CPU)
    CHECK(d.bitwise);
}
