// SPDX-License-Identifier: MIT
// strain_finish.comp's per-particle passes on the positions a substep writes (SC_STAGE fixes one
// per pipeline): stage 0, the tethers (before Provot's sweeps; no collider code); stage 1, the
// colliders' projection after stretch control (a correction may have pulled a particle into one);
// stage 2, the same after self-collision (a move may have pushed one in). Three passes of the list,
// one class.
#include <array>
#include <memory>

#include "internal/barriers.hpp"
#include "../solver_batch.hpp"
#include "pass.hpp"
#include "state_set.hpp"
#include "vkcloth/shaders/strain_finish_storage_comp_spv.hpp"
#include "vkcloth/shaders/strain_finish_texel_comp_spv.hpp"

namespace vkcloth::gpu {

namespace {

constexpr ShaderSource kStrainFinish{"strain_finish.comp", spirv::strain_finish_texel_comp_spv,
                                     spirv::strain_finish_storage_comp_spv, &kStateBindings};

class FinishPass final : public Pass {
public:
  enum Stage : std::uint32_t { tethers = 0, after_stretch = 1, after_self_collision = 2 };
  explicit FinishPass(Stage stage) : stage_(stage) {}

  const char* name() const override {
    return stage_ == tethers         ? "tethers"
           : stage_ == after_stretch ? "contacts after stretch control"
                                     : "contacts after self-collision";
  }
  bool active(const SolverBatch& b) const override {
    switch (stage_) {
    case tethers:
      return b.any_tethers();
    case after_stretch:
      return b.any_stretch() && b.any_colliders();
    case after_self_collision:
      return b.self_iterations() > 0 && b.any_colliders();
    }
    return false;
  }

  Result<void> prepare(SolverBatch& b) override {
    if (!active(b))
      return {};
    const std::uint32_t types = collider_types(b);
    std::array<std::uint32_t, 42> constants{}; // ids 0..41, of which strain_finish.comp has only 41
    constants[41] = types;                     // SC_COLLIDER_TYPES
    return b.ensure_pipeline(pipelines_[types], kStrainFinish, constants, stage_);
  }

  std::uint32_t record(const SolverBatch& b, PassFrame& f) override {
    const auto& v = b.vk();
    // Set 1 of the positions being written: the pass reads positions[write] through its texel view.
    b.bind_state(f.cmd, f.read, false, f.read ^ 1u);
    v.vkCmdBindPipeline(f.cmd, VK_PIPELINE_BIND_POINT_COMPUTE, pipelines_[collider_types(b)]);
    shared::PushConstants pc = *f.pc;
    pc.stage = stage_;
    b.push_state(f.cmd, &pc);
    barriers::dispatch_to_dispatch(v, f.cmd); // the previous pass -> this one
    b.dispatch_particles(f.cmd);
    return 1;
  }

private:
  std::uint32_t collider_types(const SolverBatch& b) const {
    return stage_ == tethers ? 0u : b.collider_types();
  }
  Stage stage_;
  VkPipeline pipelines_[VKCLOTH_COLLIDER_ALL_TYPES + 1] = {}; // [collider types]
};

} // namespace

std::unique_ptr<Pass> make_tethers() {
  return std::make_unique<FinishPass>(FinishPass::tethers);
}
std::unique_ptr<Pass> make_contacts_after_stretch() {
  return std::make_unique<FinishPass>(FinishPass::after_stretch);
}
std::unique_ptr<Pass> make_contacts_after_self_collision() {
  return std::make_unique<FinishPass>(FinishPass::after_self_collision);
}

} // namespace vkcloth::gpu
