// SPDX-License-Identifier: MIT
// `--backend vulkan`: the GpuSolver on a Context of its own (VKCLOTH_DEVICE picks the device,
// VKCLOTH_VALIDATION=1 turns on the Khronos validation layer).
#include <fmt/format.h>

#include "backend.hpp"
#include "vkcloth/gpu/gpu_solver.hpp"

namespace vkcloth::cli {
namespace {

class VulkanBackend final : public SimBackend {
public:
  VulkanBackend(gpu::Context context, gpu::GpuSolver solver)
      : context_(std::move(context)), solver_(std::move(solver)) {}

  Result<void> step(std::uint64_t n) override { return solver_.simulate(n); }

  Result<void> read_state(std::vector<glm::dvec3>& positions, std::vector<glm::dvec3>& velocities) override {
    auto p = solver_.positions();
    if (!p)
      return p.error();
    auto v = solver_.velocities();
    if (!v)
      return v.error();
    positions.assign(p->begin(), p->end());
    velocities.assign(v->begin(), v->end());
    return {};
  }

  Result<StrainStats> strain(const ParticleSystem& system) override {
    auto p = solver_.positions();
    if (!p)
      return p.error();
    return structural_strain(system, std::span<const glm::vec3>(*p));
  }

  std::uint64_t step_index() const override { return solver_.step_index(); }
  SolveStats last_solve() const override { return solver_.last_solve(); }
  double time() const override { return solver_.time(); }
  std::vector<Collider> colliders() const override { return solver_.params().colliders; }

private:
  gpu::Context context_; // declared first: destroyed after the solver
  gpu::GpuSolver solver_;
};

} // namespace

Result<std::unique_ptr<SimBackend>> make_vulkan_backend(const Scene& scene, Precision precision) {
  if (precision != Precision::float32)
    return make_error(ErrorCode::invalid_argument,
                      "--precision double is CPU only: the Vulkan solver computes in float");
  auto context = gpu::Context::create();
  if (!context)
    return context.error();
  auto solver = gpu::GpuSolver::create(*context, scene.system, scene.params);
  if (!solver)
    return solver.error();
  return std::unique_ptr<SimBackend>(
      std::make_unique<VulkanBackend>(std::move(*context), std::move(*solver)));
}

} // namespace vkcloth::cli
