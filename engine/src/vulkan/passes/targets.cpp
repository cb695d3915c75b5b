// SPDX-License-Identifier: MIT
// Attachments and motion constraints (targets.comp; docs/model.md "Attachments and motion
// constraints"): before the update, pinned particles onto their targets; after the substep's last
// pass, free particles back within reach. The batch records each substep's targets into TARGETS
// before the first (SolverBatch::record_targets). And the cloth's frame (docs/model.md "Inertia and
// teleport"): its jump first, its carry last (FRAMES, SolverBatch::record_frames). Four passes of
// the list, two classes.
#include <memory>

#include "internal/barriers.hpp"
#include "../solver_batch.hpp"
#include "pass.hpp"
#include "state_set.hpp"
#include "vkcloth/shaders/targets_comp_spv.hpp"

namespace vkcloth::gpu {

namespace {

constexpr ShaderSource kTargets{"targets.comp", spirv::targets_comp_spv, {}, &kStateBindings};

class TargetsPass final : public Pass {
public:
  explicit TargetsPass(std::uint32_t stage) : stage_(stage) {}

  const char* name() const override {
    return stage_ == VKCLOTH_TARGETS_DRIVE ? "pinned particles onto their targets"
                                           : "free particles within reach of their targets";
  }
  bool active(const SolverBatch& b) const override { return b.any_targets(); }

  Result<void> prepare(SolverBatch& b) override {
    return active(b) ? b.ensure_pipeline(pipeline_, kTargets, {}, stage_) : Result<void>{};
  }

  std::uint32_t record(const SolverBatch& b, PassFrame& f) override {
    const auto& v = b.vk();
    // Set 0 only: POS_BASE is positions[read] (the drive), POS_OUT positions[read ^ 1] (the hold).
    b.bind_state(f.cmd, f.read, false, SolverBatch::no_texel_set);
    v.vkCmdBindPipeline(f.cmd, VK_PIPELINE_BIND_POINT_COMPUTE, pipeline_);
    auto pc = shared::push_from<shared::TargetsPush>(*f.pc);
    pc.stage = stage_;
    pc.target_count = b.targets_per_slot();
    b.push_state(f.cmd, &pc);
    if (!f.first)
      barriers::dispatch_to_dispatch(v, f.cmd); // the previous pass (or substep) -> this one
    b.dispatch_items(f.cmd, pc.target_count);
    return 1;
  }

private:
  std::uint32_t stage_;
  VkPipeline pipeline_ = VK_NULL_HANDLE;
};

/// The cloth's frame, over every particle: VKCLOTH_FRAME_JUMP or VKCLOTH_FRAME_CARRY.
class FramePass final : public Pass {
public:
  explicit FramePass(std::uint32_t stage) : stage_(stage) {}

  const char* name() const override {
    return stage_ == VKCLOTH_FRAME_JUMP ? "the cloth's frame jump" : "the cloth carried with its frame";
  }
  bool active(const SolverBatch& b) const override {
    return stage_ == VKCLOTH_FRAME_JUMP ? b.frame_jumps_now() : b.frame_carries_now();
  }

  Result<void> prepare(SolverBatch& b) override {
    return b.any_frame() ? b.ensure_pipeline(pipeline_, kTargets, {}, stage_) : Result<void>{};
  }

  std::uint32_t record(const SolverBatch& b, PassFrame& f) override {
    const auto& v = b.vk();
    // Set 0 only: the jump moves positions[read], the carry reads it and positions[read ^ 1].
    b.bind_state(f.cmd, f.read, false, SolverBatch::no_texel_set);
    v.vkCmdBindPipeline(f.cmd, VK_PIPELINE_BIND_POINT_COMPUTE, pipeline_);
    auto pc = shared::push_from<shared::TargetsPush>(*f.pc); // target_count unused here
    pc.stage = stage_;
    b.push_state(f.cmd, &pc);
    if (!f.first)
      barriers::dispatch_to_dispatch(v, f.cmd); // the previous pass (or substep) -> this one
    b.dispatch_particles(f.cmd);
    return 1;
  }

private:
  std::uint32_t stage_;
  VkPipeline pipeline_ = VK_NULL_HANDLE;
};

} // namespace

std::unique_ptr<Pass> make_frame_jump() {
  return std::make_unique<FramePass>(VKCLOTH_FRAME_JUMP);
}
std::unique_ptr<Pass> make_frame_carry() {
  return std::make_unique<FramePass>(VKCLOTH_FRAME_CARRY);
}
std::unique_ptr<Pass> make_drive_targets() {
  return std::make_unique<TargetsPass>(VKCLOTH_TARGETS_DRIVE);
}
std::unique_ptr<Pass> make_hold_targets() {
  return std::make_unique<TargetsPass>(VKCLOTH_TARGETS_HOLD);
}

} // namespace vkcloth::gpu
