// SPDX-License-Identifier: MIT
#include "backend.hpp"

#include <fmt/format.h>

#include "vkcloth/cpu_solver.hpp"

namespace vkcloth::cli {
namespace {

template <typename Real> class CpuBackend final : public SimBackend {
public:
  explicit CpuBackend(CpuSolver<Real> solver) : solver_(std::move(solver)) {}

  Result<void> step(std::uint64_t n) override { return solver_.run(n); }

  Result<void> read_state(std::vector<glm::dvec3>& positions, std::vector<glm::dvec3>& velocities) override {
    const auto p = solver_.positions();
    const auto v = solver_.velocities();
    positions.assign(p.begin(), p.end());
    velocities.assign(v.begin(), v.end());
    return {};
  }

  Result<StrainStats> strain(const ParticleSystem& system) override {
    return structural_strain(system, solver_.positions());
  }

  std::uint64_t step_index() const override { return solver_.step_index(); }
  SolveStats last_solve() const override { return solver_.last_solve(); }
  std::optional<SelfCollisionStats> self_collision_stats() const override {
    return solver_.self_collision_stats();
  }
  double time() const override { return solver_.time(); }
  std::vector<Collider> colliders() const override { return solver_.params().colliders; }

private:
  CpuSolver<Real> solver_;
};

template <typename Real> Result<std::unique_ptr<SimBackend>> make_cpu(const Scene& scene) {
  auto solver = CpuSolver<Real>::create(scene.system, scene.params);
  if (!solver)
    return solver.error();
  return std::unique_ptr<SimBackend>(std::make_unique<CpuBackend<Real>>(std::move(*solver)));
}

} // namespace

std::optional<Precision> parse_precision(std::string_view name) {
  if (name == "float")
    return Precision::float32;
  if (name == "double")
    return Precision::float64;
  return std::nullopt;
}

const char* to_string(Precision p) {
  return p == Precision::float32 ? "float" : "double";
}

Result<std::unique_ptr<SimBackend>> make_backend(std::string_view name, const Scene& scene,
                                                 Precision precision) {
  if (name == "cpu")
    return precision == Precision::float32 ? make_cpu<float>(scene) : make_cpu<double>(scene);
  if (name == "vulkan")
    return make_vulkan_backend(scene, precision);
  return make_error(ErrorCode::invalid_argument,
                    fmt::format("unknown backend \"{}\" (known: cpu, vulkan)", name));
}

} // namespace vkcloth::cli
