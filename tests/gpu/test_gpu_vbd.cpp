// SPDX-License-Identifier: MIT
// The Vulkan vbd step against the CPU reference (float) on every sample scene: the same kernel
// functions (engine/kernel/vbd.h) in the same order, colour by colour, so on lavapipe the same bits;
// the stated tolerance is the 1e-5 m after 100 steps. Validation with synchronization
// validation is on (gpu_test_util.hpp), and any message fails the test.
#include <doctest/doctest.h>

#include <filesystem>
#include <string>
#include <vector>

#include "gpu_test_util.hpp"

using namespace vkcloth;

TEST_CASE("GPU vbd matches the CPU vbd on every sample scene: 100 steps") {
  VKCLOTH_GPU_TEST_BEGIN(ctx);
  for (const auto& file : gpu::test::scene_files(VKCLOTH_SAMPLES_SCENES_DIR)) {
    // Two substeps: the second starts from the state the first left in the batch's buffers.
    const std::vector<std::string> overrides = {"integrator.method=vbd", "integrator.substeps=2"};
    const std::uint64_t steps = 100;
    auto run = gpu::test::run_cpu_and_gpu(ctx, file, overrides, steps);
    auto& cpu = run.cpu;
    auto& gpu = run.gpu;
    auto gp = gpu->positions();
    REQUIRE(gp.ok());
    auto gv = gpu->velocities();
    REQUIRE(gv.ok());
    const auto d = gpu::test::diff(cpu->positions(), *gp);
    const auto dv = gpu::test::diff(cpu->velocities(), *gv);
    MESSAGE(file.filename().string() << ": max |p_cpu - p_gpu| after " << steps << " vbd steps = "
                                     << d.max_abs << " m, velocities " << dv.max_abs << " m/s");
    CHECK(d.max_abs <= 1e-5);
    CHECK(dv.max_abs <= 1e-3);
  }
}

TEST_CASE("GPU vbd: instances with different sweeps step in their own batches, each as its CPU solver") {
  VKCLOTH_GPU_TEST_BEGIN(ctx);
  auto scene = load_scene_file(std::filesystem::path(VKCLOTH_SAMPLES_SCENES_DIR) / "cloth_on_sphere.json",
                               std::vector<std::string>{"integrator.method=vbd"});
  REQUIRE(scene.ok());
  auto topology = ClothTopology::create(scene->system);
  REQUIRE(topology.ok());
  auto world = gpu::ClothWorld::create(ctx);
  REQUIRE(world.ok());
  std::vector<gpu::InstanceId> ids;
  std::vector<CpuSolver<float>> cpus;
  for (std::uint32_t iterations : {1u, 3u, 3u}) {
    SimParams p = scene->params;
    p.vbd_iterations = iterations;
    auto id = world->add(*topology, p);
    REQUIRE(id.ok());
    ids.push_back(*id);
    auto cpu = CpuSolver<float>::create(scene->system, p);
    REQUIRE(cpu.ok());
    cpus.push_back(std::move(*cpu));
  }
  REQUIRE(world->simulate(50).ok());
  for (std::size_t k = 0; k < ids.size(); ++k) {
    REQUIRE(cpus[k].run(50).ok());
    auto gp = world->positions(ids[k]);
    REQUIRE(gp.ok());
    CHECK(gpu::test::diff(cpus[k].positions(), *gp).max_abs <= 1e-5);
  }
  CHECK(gpu::test::diff(cpus[0].positions(), cpus[1].positions()).max_abs > 1e-4); // 1 vs 3 sweeps differ
}
