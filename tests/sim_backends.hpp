// SPDX-License-Identifier: MIT
// The physics tests run against every backend: CPU float, CPU double and Vulkan (float, on the
// shared validated Context of the GPU tests). On CI (CI=true) a missing Vulkan device fails;
// elsewhere the Vulkan backend is left out with a message.
#pragma once

#include <doctest/doctest.h>

#include <algorithm>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include <glm/geometric.hpp>
#include <glm/vec3.hpp>

#include "gpu/gpu_test_util.hpp"
#include "vkcloth/vkcloth.hpp"

namespace vkcloth::test {

enum class Backend { cpu_float, cpu_double, vulkan };

inline const char* to_string(Backend b) {
  return b == Backend::cpu_float ? "cpu float" : b == Backend::cpu_double ? "cpu double" : "vulkan";
}
inline bool is_float(Backend b) {
  return b != Backend::cpu_double;
}

/// One solver behind a common face; state comes back in double whatever the backend computes in.
class Sim {
public:
  virtual ~Sim() = default;
  virtual Result<void> run(std::uint64_t steps) = 0;
  virtual std::vector<glm::dvec3> positions() = 0;
  virtual std::vector<glm::dvec3> velocities() = 0;
  virtual std::vector<glm::dvec3> forces() = 0;
  virtual std::vector<glm::dvec3> normals() = 0;
  virtual Result<void> set_params(SimParams params) = 0;
  virtual Result<void> set_pin_targets(std::span<const PinTarget> targets) = 0;
  virtual Result<void> teleport(const RigidJump& jump) = 0;
  virtual SimParams params() = 0;
  Result<void> step() { return run(1); }
  glm::dvec3 position(std::size_t i) { return positions().at(i); }
  glm::dvec3 velocity(std::size_t i) { return velocities().at(i); }
};

template <typename V> std::vector<glm::dvec3> widen(const V& v) {
  return std::vector<glm::dvec3>(v.begin(), v.end());
}

template <typename Real> class CpuSim final : public Sim {
public:
  explicit CpuSim(CpuSolver<Real> s) : s_(std::move(s)) {}
  Result<void> run(std::uint64_t steps) override { return s_.run(steps); }
  std::vector<glm::dvec3> positions() override { return widen(s_.positions()); }
  std::vector<glm::dvec3> velocities() override { return widen(s_.velocities()); }
  std::vector<glm::dvec3> forces() override { return widen(s_.forces()); }
  std::vector<glm::dvec3> normals() override { return widen(s_.normals()); }
  Result<void> set_params(SimParams params) override { return s_.set_params(std::move(params)); }
  Result<void> set_pin_targets(std::span<const PinTarget> targets) override {
    return s_.set_pin_targets(targets);
  }
  Result<void> teleport(const RigidJump& jump) override { return s_.teleport(jump); }
  SimParams params() override { return s_.params(); }

private:
  CpuSolver<Real> s_;
};

class GpuSim final : public Sim {
public:
  explicit GpuSim(gpu::GpuSolver s) : s_(std::move(s)) {}
  Result<void> run(std::uint64_t steps) override { return s_.simulate(steps); }
  std::vector<glm::dvec3> positions() override { return read(s_.positions()); }
  std::vector<glm::dvec3> velocities() override { return read(s_.velocities()); }
  std::vector<glm::dvec3> forces() override { return read(s_.forces()); }
  std::vector<glm::dvec3> normals() override { return read(s_.normals()); }
  Result<void> set_params(SimParams params) override { return s_.set_params(std::move(params)); }
  Result<void> set_pin_targets(std::span<const PinTarget> targets) override {
    return s_.set_pin_targets(targets);
  }
  Result<void> teleport(const RigidJump& jump) override { return s_.teleport(jump); }
  SimParams params() override { return s_.params(); }

private:
  static std::vector<glm::dvec3> read(const Result<std::vector<glm::vec3>>& r) {
    REQUIRE_MESSAGE(r.ok(), (r.ok() ? "" : r.error().message));
    return widen(*r);
  }
  gpu::GpuSolver s_;
};

/// The backends to test here: both CPU precisions, and Vulkan when a device is there.
inline std::vector<Backend> backends() {
  auto& shared = gpu::test::shared_context();
  if (shared.context)
    return {Backend::cpu_float, Backend::cpu_double, Backend::vulkan};
  if (gpu::test::on_ci())
    FAIL("CI=true but no Vulkan device: " << shared.error);
  MESSAGE("Vulkan backend left out, no device: " << shared.error);
  return {Backend::cpu_float, Backend::cpu_double};
}

/// The Vulkan backend runs on lavapipe (llvmpipe): the same expressions in the same order as the
/// CPU float solver, so the CPU's bits.
inline bool vulkan_gives_cpu_bits() {
  const auto& shared = gpu::test::shared_context();
  return shared.context && shared.context->device_name().find("llvmpipe") != std::string::npos;
}

/// Float-only backends (CPU float and Vulkan), for checks stated at float precision.
inline std::vector<Backend> float_backends() {
  std::vector<Backend> r;
  for (Backend b : backends())
    if (is_float(b))
      r.push_back(b);
  return r;
}

/// Creates a solver; the test fails (REQUIRE) when creation fails.
/// make_cloth(d), failing the test case on an error.
inline ParticleSystem grid_cloth(const ClothDesc& d) {
  auto sys = make_cloth(d);
  REQUIRE(sys.ok());
  return *sys;
}

inline std::unique_ptr<Sim> make_sim(Backend b, const ParticleSystem& system, const SimParams& params) {
  switch (b) {
  case Backend::cpu_float: {
    auto s = CpuSolver<float>::create(system, params);
    REQUIRE_MESSAGE(s.ok(), (s.ok() ? "" : s.error().message));
    return std::make_unique<CpuSim<float>>(std::move(*s));
  }
  case Backend::cpu_double: {
    auto s = CpuSolver<double>::create(system, params);
    REQUIRE_MESSAGE(s.ok(), (s.ok() ? "" : s.error().message));
    return std::make_unique<CpuSim<double>>(std::move(*s));
  }
  case Backend::vulkan: {
    auto s = gpu::GpuSolver::create(*gpu::test::shared_context().context, system, params);
    REQUIRE_MESSAGE(s.ok(), (s.ok() ? "" : s.error().message));
    return std::make_unique<GpuSim>(std::move(*s));
  }
  }
  return nullptr;
}

/// Steps `solver` through `scene`'s steps (the test fails on an error) and returns the largest
/// structural strain of every step (the cotton drops' strain targets).
inline double largest_strain_over_steps(const Scene& scene, CpuSolver<float>& solver) {
  double largest = 0.0;
  for (std::uint64_t k = 0; k < scene.steps; ++k) {
    REQUIRE(solver.step().ok());
    auto strain = structural_strain(scene.system, solver.positions());
    REQUIRE(strain.ok());
    largest = std::max(largest, strain->max);
  }
  return largest;
}

/// The largest distance between the first run's positions and each other run's (the float
/// backends' ends: GPU = CPU checks).
inline double largest_gap(const std::vector<std::vector<glm::dvec3>>& ends) {
  double worst = 0.0;
  for (std::size_t k = 1; k < ends.size(); ++k)
    for (std::size_t i = 0; i < ends[0].size(); ++i)
      worst = std::max(worst, glm::length(ends[k][i] - ends[0][i]));
  return worst;
}

/// Fails the test case if the shared Vulkan context reported validation messages during it.
struct ValidationScope {
  std::uint64_t start = count();
  static std::uint64_t count() {
    auto& shared = gpu::test::shared_context();
    return shared.context ? shared.context->validation_message_count() : 0;
  }
  ~ValidationScope() { CHECK_MESSAGE(count() == start, "Vulkan validation reported messages (see stderr)"); }
};

} // namespace vkcloth::test
