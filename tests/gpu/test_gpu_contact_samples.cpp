// SPDX-License-Identifier: MIT
// The contact sample scenes (friction, a spinning sphere, a box, a capsule, a mesh) on
// the Vulkan solver against the CPU reference (float), with the validation layer on: the same
// positions after 100 steps, and after every one of those steps no particle deeper inside a
// collider than contact_epsilon on either backend.
#include <doctest/doctest.h>

#include <algorithm>
#include <filesystem>
#include <string>

#include "gpu_test_util.hpp"

using namespace vkcloth;

namespace {

std::vector<glm::dvec3> widen(std::span<const glm::vec3> v) {
  return {v.begin(), v.end()};
}

} // namespace

TEST_CASE("GPU matches CPU on the contact samples: 100 steps within 1e-5 m, never deeper than eps") {
  VKCLOTH_GPU_TEST_BEGIN(ctx);
  for (const char* name : {"tablecloth_on_table", "cloth_on_sphere_friction", "cloth_on_rotating_sphere",
                           "flag_on_pole", "cloth_on_mesh"}) {
    CAPTURE(name);
    auto scene =
        load_scene_file(std::filesystem::path(VKCLOTH_SAMPLES_SCENES_DIR) / (std::string(name) + ".json"));
    REQUIRE_MESSAGE(scene.ok(), (scene.ok() ? "" : scene.error().message));
    auto cpu = CpuSolver<float>::create(scene->system, scene->params);
    REQUIRE(cpu.ok());
    auto gpu = gpu::GpuSolver::create(ctx, scene->system, scene->params);
    REQUIRE(gpu.ok());
    const double eps = scene->params.contact_epsilon;
    double deepest_cpu = -1.0, deepest_gpu = -1.0;
    int touching = 0; // particle-steps within 2 eps of a collider, on the CPU: contact did happen
    for (int step = 0; step < 100; ++step) {
      REQUIRE(cpu->step().ok());
      REQUIRE(gpu->simulate(1).ok());
      auto gp = gpu->positions();
      REQUIRE(gp.ok());
      const auto c = penetration(scene->system, cpu->params().colliders, widen(cpu->positions()));
      const auto g = penetration(scene->system, gpu->params().colliders, widen(*gp));
      REQUIRE(c.ok());
      REQUIRE(g.ok());
      deepest_cpu = std::max(deepest_cpu, c->depth);
      deepest_gpu = std::max(deepest_gpu, g->depth);
      touching += c->depth > -2.0 * eps;
    }
    auto gp = gpu->positions();
    REQUIRE(gp.ok());
    const auto d = gpu::test::diff(cpu->positions(), *gp);
    MESSAGE(std::string(name) << ": max |p_cpu - p_gpu| after 100 steps = " << d.max_abs
                              << " m (bitwise: " << d.bitwise << "); deepest penetration cpu " << deepest_cpu
                              << " m, gpu " << deepest_gpu << " m (eps " << eps << ")");
    CHECK(d.max_abs <= 1e-5);
    CHECK(deepest_cpu <= eps);
    CHECK(deepest_gpu <= eps);
    CHECK(touching > 0); // the cloth reached a collider within the 100 steps
  }
}
