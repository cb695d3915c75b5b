// SPDX-License-Identifier: MIT
// Vertex block descent's update of a substep (Integrator::vbd; the method: engine/src/core/vbd.cpp).
// vbd.comp, one pipeline per phase: BEGIN over every particle, then for each iteration one dispatch
// per colour of the topology (ClothTopology::vertex_order, uploaded as VBD_ORDER), then FINISH.
// The state set of the substep's parity: POS_IN = positions[read] (the start), POS_OUT the iterate.
// VEL_FILT and STAGE_POS, the explicit integrators' scratch, hold the targets and the pushes; with
// self-contact as an energy, ACC_POS, ACC_VEL and STAGE_VEL each sweep's contact forces and
// stiffness, which SelfCollisionGpu's CONTACT pass writes before the sweep's colours.
#include <memory>

#include "internal/barriers.hpp"
#include "../solver_batch.hpp"
#include "pass.hpp"
#include "self_collision_gpu.hpp"
#include "state_set.hpp"
#include "vkcloth/shaders/vbd_comp_spv.hpp"

namespace vkcloth::gpu {

namespace {

constexpr ShaderSource kVbd{"vbd.comp", spirv::vbd_comp_spv, {}, &kStateBindings};

class VbdUpdate final : public Pass {
public:
  const char* name() const override { return "vbd update"; }
  bool active(const SolverBatch& b) const override { return b.family().integrator == Integrator::vbd; }

  Result<void> prepare(SolverBatch& b) override {
    if (!active(b))
      return {};
    const std::uint32_t types = b.collider_types();
    const auto constants = b.state_constants(true, types, true); // the CSR gather, every normal path
    for (std::uint32_t stage : {VKCLOTH_VBD_BEGIN, VKCLOTH_VBD_SOLVE, VKCLOTH_VBD_FINISH})
      VKCLOTH_TRY(b.ensure_pipeline(pipelines_[stage][types], kVbd, constants, stage));
    return {};
  }

  std::uint32_t record(const SolverBatch& b, PassFrame& f) override {
    const auto& v = b.vk();
    const std::uint32_t types = b.collider_types();
    b.bind_state(f.cmd, f.read, false, SolverBatch::no_texel_set); // vbd.comp has one (storage) build
    auto pc = shared::push_from<shared::VbdPush>(*f.pc);
    auto run = [&](std::uint32_t stage) {
      pc.stage = stage;
      b.push_state(f.cmd, &pc);
      v.vkCmdBindPipeline(f.cmd, VK_PIPELINE_BIND_POINT_COMPUTE, pipelines_[stage][types]);
    };
    run(VKCLOTH_VBD_BEGIN);
    if (!f.first)
      barriers::dispatch_to_dispatch(v, f.cmd); // the previous substep's passes -> this one
    b.dispatch_particles(f.cmd);
    std::uint32_t dispatches = 1;
    // Self-contact as an energy (an instance's SelfCollision::stiffness): the lists of the first
    // guesses, then each sweep's contact forces, in the self-collision pass's layout.
    SelfCollisionGpu* const self = b.any_self_energy() ? b.self_collision() : nullptr;
    pc.contact = self ? 1u : 0u;
    if (self)
      dispatches += self->record_sweep_lists(f.cmd, f.read, *f.pc);
    const auto colours = b.topology().vertex_colour_offsets();
    // Instances of a batch share their sweeps: the world batches vbd instances by their iterations.
    for (std::uint32_t it = 0; it < b.family().vbd_iterations; ++it) {
      if (self) {
        dispatches += self->record_sweep_contact(f.cmd, f.read, *f.pc);
        b.bind_state(f.cmd, f.read, false, SolverBatch::no_texel_set);
      }
      if (it == 0 || self)
        run(VKCLOTH_VBD_SOLVE);
      for (std::size_t c = 0; c + 1 < colours.size(); ++c) {
        pc.colour_first = colours[c];
        pc.colour_count = colours[c + 1] - colours[c];
        b.push_state(f.cmd, &pc);
        barriers::dispatch_to_dispatch(v, f.cmd); // the begin or the previous colour -> this colour
        b.dispatch_items(f.cmd, pc.colour_count);
        ++dispatches;
      }
    }
    run(VKCLOTH_VBD_FINISH);
    barriers::dispatch_to_dispatch(v, f.cmd); // the last colour -> the velocities
    b.dispatch_particles(f.cmd);
    return dispatches + 1;
  }

private:
  VkPipeline pipelines_[3][VKCLOTH_COLLIDER_ALL_TYPES + 1] = {}; // [VKCLOTH_VBD_*][collider types]
};

} // namespace

std::unique_ptr<Pass> make_vbd_update() {
  return std::make_unique<VbdUpdate>();
}

} // namespace vkcloth::gpu
