// SPDX-License-Identifier: MIT
// Shared helpers of the GPU tests: one validated Context per process, the CI/skip rule, the
// per-test-case validation check, CPU-vs-GPU comparison.
#pragma once

#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "vkcloth/vkcloth.hpp"

namespace vkcloth::gpu::test {

/// GPU = CPU float: how far apart their positions may be after 100 steps (m).
inline constexpr double gpu_cpu_tolerance = 1e-5;

inline bool on_ci() {
  const char* v = std::getenv("CI");
  return v && (std::strcmp(v, "true") == 0 || std::strcmp(v, "1") == 0);
}

struct SharedContext {
  std::optional<Context> context;
  std::string error;
};

/// One Context for the whole run, created with validation and synchronization validation.
inline SharedContext& shared_context() {
  static SharedContext s = [] {
    SharedContext r;
    ContextOptions o;
    o.validation = true;
    auto c = Context::create(o);
    if (c)
      r.context.emplace(std::move(c.value()));
    else
      r.error = std::string(to_string(c.error().code)) + ": " + c.error().message;
    return r;
  }();
  return s;
}

/// Fails every validation message emitted during one test case.
struct ValidationGuard {
  const Context& context;
  std::uint64_t start = context.validation_message_count();
  ~ValidationGuard() {
    CHECK_MESSAGE(context.validation_message_count() == start,
                  "Vulkan validation reported messages (see stderr)");
  }
};

/// Max |a - b| over all components; `bitwise` when every float is identical.
struct Diff {
  double max_abs = 0.0;
  bool bitwise = true;
};
inline Diff diff(std::span<const glm::vec3> a, std::span<const glm::vec3> b) {
  Diff d;
  REQUIRE(a.size() == b.size());
  for (std::size_t i = 0; i < a.size(); ++i)
    for (int k = 0; k < 3; ++k) {
      const double e = std::abs(double(a[i][k]) - double(b[i][k]));
      d.max_abs = std::isnan(e) ? INFINITY : std::max(d.max_abs, e);
      if (std::memcmp(&a[i][k], &b[i][k], sizeof(float)) != 0)
        d.bitwise = false;
    }
  return d;
}

/// The scene files of `dir` (samples/scenes), sorted by name.
inline std::vector<std::filesystem::path> scene_files(const std::filesystem::path& dir) {
  std::vector<std::filesystem::path> files;
  for (const auto& entry : std::filesystem::directory_iterator(dir))
    if (entry.path().extension() == ".json")
      files.push_back(entry.path());
  std::sort(files.begin(), files.end());
  return files;
}

/// A scene run `steps` steps by the CPU solver (float) and by a GpuSolver, from the same start.
struct CpuGpuRun {
  Scene scene;
  std::optional<CpuSolver<float>> cpu;
  std::optional<GpuSolver> gpu;
};
inline CpuGpuRun run_cpu_and_gpu(Context& ctx, const std::filesystem::path& file,
                                 std::span<const std::string> overrides, std::uint64_t steps) {
  auto scene = load_scene_file(file, overrides);
  REQUIRE_MESSAGE(scene.ok(), (scene.ok() ? "" : scene.error().message));
  CpuGpuRun r{std::move(*scene), std::nullopt, std::nullopt};
  auto cpu = CpuSolver<float>::create(r.scene.system, r.scene.params);
  REQUIRE(cpu.ok());
  auto gpu = GpuSolver::create(ctx, r.scene.system, r.scene.params);
  REQUIRE(gpu.ok());
  r.cpu.emplace(std::move(*cpu));
  r.gpu.emplace(std::move(*gpu));
  REQUIRE(r.cpu->run(steps).ok());
  REQUIRE(r.gpu->simulate(steps).ok());
  return r;
}

/// A small nx x ny cloth's topology: vertical with its default pinned corners, or horizontal and free.
inline std::shared_ptr<const ClothTopology> make_topology(std::uint32_t nx, std::uint32_t ny,
                                                          bool horizontal = false) {
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
  auto t = ClothTopology::create(*s);
  REQUIRE(t.ok());
  return *t;
}

} // namespace vkcloth::gpu::test

/// Starts a GPU test case on `shared` (a SharedContext-like {context, error}): binds `ctx` to its
/// validated Context and checks validation at the end; without a device skips (or fails on CI).
#define VKCLOTH_TEST_WITH_CONTEXT(ctx, shared)                                                               \
  auto& vkcloth_shared_ = (shared);                                                                          \
  if (!vkcloth_shared_.context) {                                                                            \
    if (::vkcloth::gpu::test::on_ci())                                                                       \
      FAIL("CI=true but no Vulkan device: " << vkcloth_shared_.error);                                       \
    MESSAGE("skipped, no Vulkan device: " << vkcloth_shared_.error);                                         \
    return;                                                                                                  \
  }                                                                                                          \
  ::vkcloth::gpu::Context& ctx = *vkcloth_shared_.context;                                                   \
  REQUIRE(ctx.validation_enabled());                                                                         \
  ::vkcloth::gpu::test::ValidationGuard vkcloth_guard_ {                                                     \
    ctx                                                                                                      \
  }

/// Starts a GPU test case on the shared compute Context.
#define VKCLOTH_GPU_TEST_BEGIN(ctx) VKCLOTH_TEST_WITH_CONTEXT(ctx, ::vkcloth::gpu::test::shared_context())
