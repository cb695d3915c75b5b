// SPDX-License-Identifier: MIT
// The explicit integrators' update of a substep. fused.comp: one dispatch (forces, contacts and
// the Euler update; GpuSolverOptions::fused). Otherwise force.comp then integrate.comp, once per
// Euler substep or once per RK4 stage. Pipelines per collider types (SC_COLLIDER_TYPES: the
// shapes no instance has are compiled out), and fused.comp per SC_WRITE_AUX too: only the
// recording's last substep stores the forces and normals a host can observe.
#include <memory>

#include "internal/barriers.hpp"
#include "../solver_batch.hpp"
#include "pass.hpp"
#include "state_set.hpp"
#include "vkcloth/shaders/force_storage_comp_spv.hpp"
#include "vkcloth/shaders/force_texel_comp_spv.hpp"
#include "vkcloth/shaders/fused_storage_comp_spv.hpp"
#include "vkcloth/shaders/fused_texel_comp_spv.hpp"
#include "vkcloth/shaders/integrate_storage_comp_spv.hpp"
#include "vkcloth/shaders/integrate_texel_comp_spv.hpp"

namespace vkcloth::gpu {

namespace {

constexpr ShaderSource kForce{"force.comp", spirv::force_texel_comp_spv, spirv::force_storage_comp_spv,
                              &kStateBindings};
constexpr ShaderSource kIntegrate{"integrate.comp", spirv::integrate_texel_comp_spv,
                                  spirv::integrate_storage_comp_spv, &kStateBindings};
constexpr ShaderSource kFused{"fused.comp", spirv::fused_texel_comp_spv, spirv::fused_storage_comp_spv,
                              &kStateBindings};

class ExplicitUpdate final : public Pass {
public:
  const char* name() const override { return "explicit update"; }
  bool active(const SolverBatch& b) const override {
    const Integrator i = b.family().integrator;
    return i != Integrator::implicit_euler && i != Integrator::vbd;
  }

  Result<void> prepare(SolverBatch& b) override {
    if (!active(b))
      return {};
    const std::uint32_t types = b.collider_types();
    if (fused(b)) {
      for (std::uint32_t aux = 0; aux < 2; ++aux)
        VKCLOTH_TRY(b.ensure_pipeline(fused_[aux][types], kFused, b.state_constants(aux != 0, types)));
      return {};
    }
    const auto constants = b.state_constants(true, types);
    VKCLOTH_TRY(b.ensure_pipeline(force_[types], kForce, constants));
    return b.ensure_pipeline(integrate_[types], kIntegrate, constants);
  }

  std::uint32_t record(const SolverBatch& b, PassFrame& f) override {
    const auto& v = b.vk();
    const std::uint32_t types = b.collider_types();
    if (fused(b)) {
      // One dispatch per (sub)step; the descriptor set alternates with the parity.
      v.vkCmdBindPipeline(f.cmd, VK_PIPELINE_BIND_POINT_COMPUTE, fused_[f.last ? 1 : 0][types]);
      f.pc->stage = 0;
      b.bind_state(f.cmd, f.read, false, f.read);
      b.push_state(f.cmd, f.pc);
      if (!f.first)
        barriers::dispatch_to_dispatch(v, f.cmd); // previous step -> this step
      b.dispatch_particles(f.cmd);
      return 1;
    }
    const std::uint32_t stages = b.family().integrator == Integrator::rk4 ? 4 : 1;
    for (std::uint32_t k = 0; k < stages; ++k) {
      f.pc->stage = k;
      if (k < 2) // stage 0 reads the state; stages 1..3 the RK4 stage input, bound once
        b.bind_state(f.cmd, f.read, k > 0, k == 0 ? f.read : 2);
      b.push_state(f.cmd, f.pc);
      if (!f.first || k > 0)
        barriers::dispatch_to_dispatch(v, f.cmd); // integrate (previous stage/step) -> force
      v.vkCmdBindPipeline(f.cmd, VK_PIPELINE_BIND_POINT_COMPUTE, force_[types]);
      b.dispatch_particles(f.cmd);
      barriers::dispatch_to_dispatch(v, f.cmd); // force -> integrate
      v.vkCmdBindPipeline(f.cmd, VK_PIPELINE_BIND_POINT_COMPUTE, integrate_[types]);
      b.dispatch_particles(f.cmd);
    }
    return 2 * stages;
  }

private:
  static bool fused(const SolverBatch& b) {
    return b.solver_options().fused && b.family().integrator != Integrator::rk4;
  }
  VkPipeline fused_[2][VKCLOTH_COLLIDER_ALL_TYPES + 1] = {}; // [SC_WRITE_AUX][collider types]
  VkPipeline force_[VKCLOTH_COLLIDER_ALL_TYPES + 1] = {};
  VkPipeline integrate_[VKCLOTH_COLLIDER_ALL_TYPES + 1] = {};
};

} // namespace

std::unique_ptr<Pass> make_explicit_update() {
  return std::make_unique<ExplicitUpdate>();
}

} // namespace vkcloth::gpu
