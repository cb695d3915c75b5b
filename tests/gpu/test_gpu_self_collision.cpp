// SPDX-License-Identifier: MIT
// Self-collision on the Vulkan solver against the CPU reference (float), with the validation
// layer on: the same positions after 100 steps of the self-collision samples (the spatial hash of
// self_collision.comp gives the CPU's pairs in the CPU's order), no intersecting triangle pairs
// once the drop has settled, and per-instance settings in one ClothWorld batch.
#include <doctest/doctest.h>

#include <filesystem>
#include <string>
#include <vector>

#include "gpu_test_util.hpp"
#include "vkcloth/gpu/testing.hpp"

using namespace vkcloth;

namespace {

Result<Scene> sample(const char* name, std::span<const std::string> overrides = {}) {
  return load_scene_file(std::filesystem::path(VKCLOTH_SAMPLES_SCENES_DIR) / (std::string(name) + ".json"),
                         overrides);
}

/// The scene's whole run on the GPU: its positions at the end (the test fails on an error).
std::vector<glm::vec3> gpu_end(gpu::Context& ctx, const Scene& scene) {
  auto gpu = gpu::GpuSolver::create(ctx, scene.system, scene.params);
  REQUIRE(gpu.ok());
  REQUIRE(gpu->simulate(scene.steps).ok());
  auto gp = gpu->positions();
  REQUIRE(gp.ok());
  return *gp;
}

} // namespace

// Both builds of self_collision.comp (its COLLIDE pass reading through texel views, or storage
// buffers): the same bits, and the CPU's within 1e-5 m.
// The samples keep neighbour lists (a skin); with skin 0 every pass walks the cells; with vbd and a
// self-contact stiffness the lists feed an energy in the vertex steps (its CONTACT pass per sweep).
TEST_CASE("GPU matches CPU on the self-collision samples: 100 steps within 1e-5 m") {
  VKCLOTH_GPU_TEST_BEGIN(ctx);
  struct Variant {
    const char* what;
    std::vector<std::string> overrides;
  };
  const Variant variants[] = {{"lists", {}},
                              {"walk", {"self_collision.skin=0"}},
                              {"vbd energy", {"integrator.method=vbd", "self_collision.stiffness=100"}}};
  for (const char* name : {"cloth_drop_self_collision", "cloth_slide_self_collision"})
    for (const Variant& variant : variants) {
      const std::string what = std::string(name) + " (" + variant.what + ")";
      INFO(what);
      auto scene = sample(name, variant.overrides);
      REQUIRE_MESSAGE(scene.ok(), (scene.ok() ? "" : scene.error().message));
      REQUIRE(scene->params.self_collision.enabled);
      auto cpu = CpuSolver<float>::create(scene->system, scene->params);
      REQUIRE(cpu.ok());
      REQUIRE(cpu->run(100).ok());
      std::vector<glm::vec3> builds[2];
      for (int k = 0; k < 2; ++k) {
        gpu::GpuSolverOptions o;
        o.buffer_access = k == 0 ? gpu::BufferAccess::texel_views : gpu::BufferAccess::storage_buffers;
        auto gpu = gpu::GpuSolver::create(ctx, scene->system, scene->params, o);
        REQUIRE(gpu.ok());
        REQUIRE(gpu->simulate(100).ok());
        auto gp = gpu->positions();
        REQUIRE(gp.ok());
        builds[k] = std::move(*gp);
      }
      CHECK_MESSAGE(gpu::test::diff(builds[0], builds[1]).bitwise, "texel views and storage buffers differ");
      const std::vector<glm::vec3>* gp = &builds[0];
      const auto d = gpu::test::diff(cpu->positions(), *gp);
      // Self-collision acted within those 100 steps: the same run without it ends elsewhere.
      SimParams off = scene->params;
      off.self_collision.enabled = false;
      auto bare = CpuSolver<float>::create(scene->system, off);
      REQUIRE(bare.ok());
      REQUIRE(bare->run(100).ok());
      const auto moved = gpu::test::diff(bare->positions(), cpu->positions());
      MESSAGE(what << ": max |p_cpu - p_gpu| after 100 steps = " << d.max_abs << " m (bitwise: " << d.bitwise
                   << "); self-collision moved the cloth by up to " << moved.max_abs << " m");
      CHECK(d.max_abs <= 1e-5);
      CHECK(moved.max_abs > 1e-3);
      if (scene->params.self_collision.stiffness > 0.0) { // the energy's friction acted too
        SimParams frictionless = scene->params;
        frictionless.self_collision.friction = 0.0;
        auto slid = CpuSolver<float>::create(scene->system, frictionless);
        REQUIRE(slid.ok());
        REQUIRE(slid->run(100).ok());
        CHECK(gpu::test::diff(slid->positions(), cpu->positions()).max_abs > 1e-3);
      }
    }
}

TEST_CASE("GPU self-collision: no intersecting triangle pairs after the drop settles (3 s)") {
  VKCLOTH_GPU_TEST_BEGIN(ctx);
  // The report-soft drop (semi-implicit Euler, the passes) and the self-colliding cotton drop (vbd's contact
  // energy with the layers' friction, Provot's sweeps).
  for (const char* name : {"cloth_drop_self_collision", "cotton_drop_self_collision"}) {
    INFO(name);
    auto scene = sample(name);
    REQUIRE_MESSAGE(scene.ok(), (scene.ok() ? "" : scene.error().message));
    auto hits = intersecting_triangle_pairs(scene->system, gpu_end(ctx, *scene));
    REQUIRE(hits.ok());
    MESSAGE(name << " on the GPU after 3 s: " << hits->pairs << " intersecting triangle pairs of "
                 << hits->triangles);
    CHECK(hits->pairs == 0);
  }
}

TEST_CASE("GPU self-collision: the cotton drop at 128 x 128 ends with no intersecting pair (3 s)") {
  VKCLOTH_GPU_TEST_BEGIN(ctx);
  // The self-colliding cotton drop at 128 x 128 (samples/bench/: Provot's sweeps in chain order); the CPU run
  // and its strain at every step: tests/test_self_collision.cpp.
  auto scene = load_scene_file(std::filesystem::path(VKCLOTH_SAMPLES_SCENES_DIR) / ".." / "bench" /
                               "cotton_drop_self_collision_128.json");
  REQUIRE_MESSAGE(scene.ok(), (scene.ok() ? "" : scene.error().message));
  REQUIRE(scene->params.stretch_limit.chains());
  const std::vector<glm::vec3> end = gpu_end(ctx, *scene);
  auto hits = intersecting_triangle_pairs(scene->system, end);
  REQUIRE(hits.ok());
  const auto strain = structural_strain(scene->system, end);
  REQUIRE(strain.ok());
  MESSAGE("on the GPU after 3 s: " << hits->pairs << " intersecting triangle pairs of " << hits->triangles
                                   << ", structural strain " << strain->max);
  CHECK(hits->pairs == 0);
  CHECK(strain->max < 0.10);
}

TEST_CASE("ClothWorld: self-collision per instance in one batch, each as its own CPU solver") {
  VKCLOTH_GPU_TEST_BEGIN(ctx);
  // Instances of one topology: self-collision on (thickness 1 cm, friction 0.2, neighbour lists with
  // a 5 mm skin), on with other settings (1.2 cm, frictionless, no lists: the walk), off, and on with
  // lists of another skin and three passes (the batch runs three; the others stop after theirs);
  // and a vbd batch of two: one taking self-contact as an energy in its sweeps, one with the passes
  // after its steps.
  auto scene = sample("cloth_drop_self_collision");
  REQUIRE_MESSAGE(scene.ok(), (scene.ok() ? "" : scene.error().message));
  std::vector<SimParams> params(6, scene->params);
  params[1].self_collision.thickness = 0.012;
  params[1].self_collision.friction = 0.0;
  params[1].self_collision.iterations = 1;
  params[1].self_collision.skin = 0.0;
  params[2].self_collision.enabled = false;
  params[3].self_collision.skin = 0.008;
  params[3].self_collision.iterations = 3;
  params[4].integrator = params[5].integrator = Integrator::vbd;
  params[4].self_collision.stiffness = 100.0;
  auto topology = ClothTopology::create(scene->system);
  REQUIRE(topology.ok());
  auto world = gpu::ClothWorld::create(ctx);
  REQUIRE(world.ok());
  std::vector<gpu::InstanceId> ids;
  for (const SimParams& p : params) {
    auto id = world->add(*topology, p);
    REQUIRE_MESSAGE(id.ok(), (id.ok() ? "" : id.error().message));
    ids.push_back(*id);
  }
  REQUIRE(world->simulate(120).ok());
  for (std::size_t k = 0; k < params.size(); ++k) {
    INFO("instance " << k);
    auto cpu = CpuSolver<float>::create(*topology, params[k]);
    REQUIRE(cpu.ok());
    REQUIRE(cpu->run(120).ok());
    auto gp = world->positions(ids[k]);
    REQUIRE(gp.ok());
    const auto d = gpu::test::diff(cpu->positions(), *gp);
    MESSAGE("instance " << k << ": max |p_cpu - p_gpu| = " << d.max_abs << " m (bitwise: " << d.bitwise
                        << ")");
    CHECK(d.max_abs <= 1e-5);
  }
}

TEST_CASE("GpuSolver: self-collision turned on between steps, as the CPU solver") {
  VKCLOTH_GPU_TEST_BEGIN(ctx);
  auto scene = sample("cloth_slide_self_collision", std::vector<std::string>{"self_collision.enabled=false"});
  REQUIRE_MESSAGE(scene.ok(), (scene.ok() ? "" : scene.error().message));
  auto cpu = CpuSolver<float>::create(scene->system, scene->params);
  REQUIRE(cpu.ok());
  auto gpu = gpu::GpuSolver::create(ctx, scene->system, scene->params);
  REQUIRE(gpu.ok());
  REQUIRE(cpu->run(40).ok());
  REQUIRE(gpu->simulate(40).ok());
  SimParams on = scene->params;
  on.self_collision.enabled = true; // the first instance to ask: its buffers and sets made now
  REQUIRE(cpu->set_params(on).ok());
  REQUIRE(gpu->set_params(on).ok());
  REQUIRE(cpu->run(60).ok());
  REQUIRE(gpu->simulate(60).ok());
  auto gp = gpu->positions();
  REQUIRE(gp.ok());
  const auto d = gpu::test::diff(cpu->positions(), *gp);
  MESSAGE("max |p_cpu - p_gpu| = " << d.max_abs << " m (bitwise: " << d.bitwise << ")");
  CHECK(d.max_abs <= 1e-5);
}

TEST_CASE("GpuSolver: self-collision's buffers within maxStorageBufferRange, or an error naming them") {
  VKCLOTH_GPU_TEST_BEGIN(ctx);
  // 100 free particles: the vec4 state buffers need 1 600 bytes, self-collision's moves 3 200.
  ParticleSystem s;
  for (int i = 0; i < 100; ++i) {
    Particle p;
    p.position = {0.1 * i, 0.0, 0.0};
    p.mass = 0.01;
    s.particles.push_back(p);
  }
  s.finalize();
  SimParams params;
  params.self_collision.enabled = true;
  gpu::testing::SolverKnobs knobs;
  knobs.max_storage_buffer_bytes = 2000;
  auto refused = gpu::testing::create_solver(ctx, s, params, {}, knobs);
  REQUIRE(!refused.ok());
  CHECK(refused.error().code == ErrorCode::unsupported);
  CHECK(refused.error().message.find("self-collision moves") != std::string::npos);
  params.self_collision.enabled = false; // the same system fits without it
  CHECK(gpu::testing::create_solver(ctx, s, params, {}, knobs).ok());
}
