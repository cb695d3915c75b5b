// SPDX-License-Identifier: MIT
// The Vulkan implicit-Euler step against the CPU reference (float) on the sample scenes. Not bit
// for bit: the CG dot products are summed in a different (fixed) order on the GPU (workgroup
// trees, then one workgroup over the partials) than on the CPU (sequential), so alpha and beta
// differ by float rounding and CG may stop one iteration apart. The positions then differ by about
// cg_tolerance x |dv| dt per step plus rounding, damped by the scheme: a few 1e-6 m after 200 steps
// on the samples; the stated tolerance is 1e-4 m (scene size 1 m), or 3x the CPU's own float-vs-
// double spread on a scene that amplifies rounding (the tablecloth sliding on its sphere).
#include <doctest/doctest.h>

#include <algorithm>
#include <filesystem>

#include <glm/geometric.hpp>
#include <string>
#include <vector>

#include "gpu_test_util.hpp"

using namespace vkcloth;

TEST_CASE("GPU implicit Euler matches the CPU implicit solver on the sample scenes") {
  VKCLOTH_GPU_TEST_BEGIN(ctx);
  for (const auto& file : gpu::test::scene_files(VKCLOTH_SAMPLES_SCENES_DIR)) {
    // The self-colliding scenes at 24 x 24 (each of several cloths at 12 x 12) instead of their own
    // sizes: their implicit substeps at full size take minutes on lavapipe under the validation
    // layer; the self-collision tests run them at full size with their own integrator.
    std::vector<std::string> overrides = {"integrator.method=implicit_euler"};
    auto as_is = load_scene_file(file);
    REQUIRE(as_is.ok());
    if (as_is->params.self_collision.enabled && as_is->cloths.empty())
      overrides.push_back("cloth.resolution=[24,24]");
    for (std::size_t k = 0; as_is->params.self_collision.enabled && k + 1 < as_is->cloths.size(); ++k)
      overrides.push_back("cloths." + std::to_string(k) + ".resolution=[12,12]");
    const std::uint64_t steps = 200;
    auto run = gpu::test::run_cpu_and_gpu(ctx, file, overrides, steps);
    const Scene& scene = run.scene;
    auto& cpu = run.cpu;
    auto& gpu = run.gpu;
    auto gp = gpu->positions();
    REQUIRE(gp.ok());
    const auto d = gpu::test::diff(cpu->positions(), *gp);
    MESSAGE(file.filename().string() << ": max |p_cpu - p_gpu| after " << steps << " implicit steps = "
                                     << d.max_abs << " m; CG iterations cpu " << cpu->last_solve().iterations
                                     << " (residual " << cpu->last_solve().residual << "), gpu "
                                     << gpu->last_solve().iterations << " (residual "
                                     << gpu->last_solve().residual << ")");
    // A scene more sensitive than that (a free tablecloth sliding on a sphere: an unstable
    // equilibrium) amplifies any rounding: there the GPU must stay within 3x of what the CPU's own
    // float rounding does (float vs double), which a wrong GPU step would exceed by far.
    double bound = 1e-4;
    if (d.max_abs >= bound) {
      auto ref = CpuSolver<double>::create(scene.system, scene.params);
      REQUIRE(ref.ok());
      REQUIRE(ref->run(steps).ok());
      double spread = 0.0;
      for (std::size_t p = 0; p < ref->positions().size(); ++p)
        spread = std::max(spread, glm::length(glm::dvec3(cpu->positions()[p]) - ref->positions()[p]));
      MESSAGE("  sensitive scene: CPU float vs double after " << steps << " steps = " << spread << " m");
      bound = std::max(bound, 3.0 * spread);
    }
    CHECK(d.max_abs < bound);
    CHECK(gpu->last_solve().residual <= scene.params.cg_tolerance); // converged to the scene's tolerance
  }
}

TEST_CASE(
    "GPU implicit Euler: the stiff cloth is stable at dt = 0.02, CG in one workgroup or per iteration") {
  VKCLOTH_GPU_TEST_BEGIN(ctx);
  ClothDesc d;
  d.nx = d.ny = 24; // 24 x 24 and 60 steps: ~200 CG iterations per step on lavapipe, twice
  d.origin = {-0.5, 0.0, 0.5};
  d.particle_mass = 0.5 / (24.0 * 24.0);
  d.stiffness = {10000.0, 2000.0, 2000.0};
  SimParams p;
  p.integrator = Integrator::implicit_euler;
  auto cpu = CpuSolver<float>::create(*make_cloth(d), p);
  REQUIRE(cpu.ok());
  REQUIRE(cpu->run(60).ok());
  using D = gpu::GpuSolverOptions::CgDispatch;
  for (D mode : {D::one_workgroup, D::per_iteration}) {
    gpu::GpuSolverOptions o;
    o.cg_dispatch = mode;
    auto gpu = gpu::GpuSolver::create(ctx, *make_cloth(d), p, o);
    REQUIRE(gpu.ok());
    double worst_residual = 0.0;
    for (int k = 0; k < 60; ++k) {
      REQUIRE(gpu->simulate(1).ok());
      const SolveStats st = gpu->last_solve();
      // Converged, or the whole cap used: a loop cut short (llvmpipe's loop cap) would show here.
      CHECK((st.residual <= p.cg_tolerance || st.iterations == p.cg_max_iterations));
      worst_residual = std::max(worst_residual, st.residual);
    }
    CHECK(gpu->implicit_one_workgroup() == (mode == D::one_workgroup));
    auto gp = gpu->positions();
    REQUIRE(gp.ok());
    const auto diff = gpu::test::diff(cpu->positions(), *gp);
    const SolveStats g = gpu->last_solve(), c = cpu->last_solve();
    MESSAGE("stiff 24x24, 60 steps, " << (mode == D::one_workgroup ? "one workgroup" : "per iteration")
                                      << ": max |p_cpu - p_gpu| = " << diff.max_abs
                                      << " m; CG iterations per step gpu " << g.mean_iterations() << ", cpu "
                                      << c.mean_iterations() << "; worst residual " << worst_residual);
    CHECK(diff.max_abs < 1e-5);
    CHECK(g.solves == 60);
    // At a condition number ~1e5 in float, rounding moves the iteration where CG crosses the
    // tolerance: measured per step 75.0 on the CPU, 85.6 per iteration (tree sums), 109.1 in one
    // workgroup (strided sums, then the tree) for the same positions (6e-8 m).
    CHECK(g.mean_iterations() >= 0.8 * c.mean_iterations());
    CHECK(g.mean_iterations() <= (mode == D::one_workgroup ? 1.6 : 1.3) * c.mean_iterations());
  }
}

TEST_CASE("GPU implicit Euler: one workgroup for a cloth too large for it is an error naming the option") {
  VKCLOTH_GPU_TEST_BEGIN(ctx);
  ClothDesc d;
  d.nx = d.ny = 400; // 160 000 particles of 12 springs: past one workgroup's loop budget
  SimParams p;
  p.integrator = Integrator::implicit_euler;
  gpu::GpuSolverOptions o;
  o.cg_dispatch = gpu::GpuSolverOptions::CgDispatch::one_workgroup;
  auto gpu = gpu::GpuSolver::create(ctx, *make_cloth(d), p, o);
  REQUIRE_FALSE(gpu.ok());
  CHECK(gpu.error().code == ErrorCode::unsupported);
  CHECK(gpu.error().message.find("cg_dispatch = one_workgroup: 160000 particles") != std::string::npos);
  o.cg_dispatch = gpu::GpuSolverOptions::CgDispatch::automatic; // falls back to per_iteration
  auto fine = gpu::GpuSolver::create(ctx, *make_cloth(d), p, o);
  REQUIRE(fine.ok());
  CHECK_FALSE(fine->implicit_one_workgroup()); // chosen at creation
}
