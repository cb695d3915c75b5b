// SPDX-License-Identifier: MIT
// SolverBatch's recording: the passes of each step into the caller's command buffer, in order,
// each after the barrier that orders it (barriers.hpp says why each barrier is there). The
// buffers, uploads and readbacks: solver_batch.cpp; the descriptor sets and pipelines:
// solver_pipelines.cpp.
#include "solver_batch.hpp"

#include <algorithm>
#include <utility>

#include "barriers.hpp"
#include "implicit_gpu.hpp"
#include "vkcloth_shared.h"

namespace vkcloth::gpu {

namespace sh = shared;

void SolverBatch::record_collider_motion(VkCommandBuffer c, double h) {
  for (Slot& s : slots)
    for (Collider& col : s.params.colliders)
      if (col.moving())
        col = col.posed_at(h);
  const auto packed = packed_colliders();
  barriers::before_host_edit(vk(), c); // the last substep's reads of the colliders finish first (WAR)
  record_buffer_update(c, colliders, packed.data(), packed.size() * sizeof(sh::Collider));
  barriers::transfer_to_compute(vk(), c); // the new poses -> this substep's passes
}

// Later changes travel in the command buffer: each recording carries the values it steps with, so
// frames in flight never see a buffer the host rewrote under them (docs/embedding.md).
void SolverBatch::record_params_update(VkCommandBuffer c) {
  if (!params_dirty)
    return;
  barriers::before_host_edit(vk(), c); // earlier steps' reads of the parameters finish first
  const auto ip = packed_instance_params();
  record_buffer_update(c, instances, ip.data(), ip.size() * sizeof(sh::InstanceParams));
  const auto col = packed_colliders();
  record_buffer_update(c, colliders, col.data(), col.size() * sizeof(sh::Collider));
  if (self_collision) {
    const auto sp = packed_self_params();
    record_buffer_update(c, self_collision->params(), sp.data(), sp.size() * sizeof(sh::SelfParams));
  }
  params_dirty = false; // before_steps() next makes the transfer writes visible to the dispatches
}

void SolverBatch::record_buffer_update(VkCommandBuffer c, const Buffer& dst, const void* data,
                                       std::size_t bytes) const {
  constexpr std::size_t max_update = 65536; // vkCmdUpdateBuffer's limit per call
  for (std::size_t at = 0; at < bytes; at += max_update)
    vk().vkCmdUpdateBuffer(c, dst.buffer, at, std::min(max_update, bytes - at),
                           static_cast<const char*>(data) + at);
}

void SolverBatch::record(VkCommandBuffer c, std::uint32_t steps) {
  if (steps == 0)
    return;
  record_params_update(c);
  barriers::before_steps(vk(), c);
  bool first = true;
  for (std::uint32_t s = 0; s < steps; ++s) {
    pc.step = static_cast<std::uint32_t>(recorded + 1); // 1-based number of the step being computed
    const bool moving = any_moving_colliders();
    const double h = family().substeps == 1 ? family().dt : family().dt / double(family().substeps);
    for (std::uint32_t k = 0; k < family().substeps; ++k) {
      if (moving) // a substep meets the colliders where they are at its end (as CpuSolver::step)
        record_collider_motion(c, h);
      record_substep(c, first, s + 1 == steps && k + 1 == family().substeps);
      first = false;
      parity ^= 1u; // positions[read ^ 1] now holds the new state
    }
    ++recorded;
    for (Slot& slot : slots)
      if (!slot.diverged) {
        ++slot.step;
        slot.time += slot.params.dt;
      }
  }
  if (options.interleaved_vertices)
    record_vertices(c);
}

// vertices.comp packs the current positions, the normals and the uvs into one Vertex per
// particle, reading POS_IN of the set whose read index is the current one.
void SolverBatch::record_vertices(VkCommandBuffer c) {
  const auto& v = vk();
  barriers::dispatch_to_dispatch(v, c); // the last pass's positions and normals -> this pass
  v.vkCmdBindPipeline(c, VK_PIPELINE_BIND_POINT_COMPUTE, vertices_pipeline);
  v.vkCmdBindDescriptorSets(c, VK_PIPELINE_BIND_POINT_COMPUTE, layout, 0, 1, &sets[parity][0], 0, nullptr);
  v.vkCmdPushConstants(c, layout, VK_SHADER_STAGE_COMPUTE_BIT, 0, sizeof(pc), &pc);
  v.vkCmdDispatch(c, groups_x, groups_y, size());
  ++dispatches_;
}

void SolverBatch::record_copy_slot(VkCommandBuffer c, const SolverBatch& from, std::uint32_t from_slot,
                                   std::uint32_t to_slot) const {
  const VkBufferCopy region{from.slot_offset(from_slot), slot_offset(to_slot), slot_bytes()};
  // Into positions[0], the new batch's current buffer; every step rewrites all of positions[1].
  const std::pair<const Buffer*, const Buffer*> copies[] = {
      {&from.pos[from.parity], &pos[0]}, {&from.vel, &vel}, {&from.normal, &normal}, {&from.force, &force}};
  for (auto [src, dst] : copies)
    vk().vkCmdCopyBuffer(c, src->buffer, dst->buffer, 1, &region);
}

void SolverBatch::record_substep(VkCommandBuffer c, bool first, bool last) {
  record_update(c, first, last);
  if (any_stretch())
    record_stretch(c, parity);
  if (const std::uint32_t iterations = self_iterations()) {
    dispatches_ += self_collision->record_substep(c, parity, pc, iterations);
    if (any_colliders())
      record_finish_pass(c, parity, 2); // a move may have pushed a particle into a collider
  }
}

void SolverBatch::record_finish_pass(VkCommandBuffer c, std::uint32_t read, std::uint32_t stage) {
  const auto& v = vk();
  // Set 1 of the positions being written: the pass reads positions[write] through its texel view.
  const VkDescriptorSet bound_sets[2] = {sets[read][0], texel_sets[read ^ 1u]};
  v.vkCmdBindDescriptorSets(c, VK_PIPELINE_BIND_POINT_COMPUTE, layout, 0, 2, bound_sets, 0, nullptr);
  v.vkCmdBindPipeline(c, VK_PIPELINE_BIND_POINT_COMPUTE,
                      finish_pipes[stage][stage == 0 ? 0u : collider_types()]);
  sh::PushConstants spc = pc;
  spc.stage = stage;
  v.vkCmdPushConstants(c, layout, VK_SHADER_STAGE_COMPUTE_BIT, 0, sizeof(spc), &spc);
  barriers::dispatch_to_dispatch(v, c); // the previous pass -> this one
  v.vkCmdDispatch(c, groups_x, groups_y, size());
  ++dispatches_;
}

// The tethers per particle, Provot's sweeps (one dispatch per colour: its links share no
// particle) or the fast projection (strain_project.comp), then the colliders' projection per
// particle; each pass after a barrier. Instances with fewer
// sweeps, without tethers, colliders or stretch control skip what they do not need
// (strain_finish.comp, strain_links.comp).
void SolverBatch::record_stretch(VkCommandBuffer c, std::uint32_t read) {
  const auto& v = vk();
  std::uint32_t sweeps = 0;
  for (const Slot& s : slots) {
    const StretchLimit& sl = s.params.stretch_limit;
    if (sl.provot())
      sweeps = std::max(sweeps, sl.iterations);
  }
  if (any_tethers())
    record_finish_pass(c, read, 0); // binds the sets the sweeps use too
  // Set 1 of the positions being written: the sweeps read positions[write] through its texel view.
  const VkDescriptorSet bound_sets[2] = {sets[read][0], texel_sets[read ^ 1u]};
  v.vkCmdBindDescriptorSets(c, VK_PIPELINE_BIND_POINT_COMPUTE, layout, 0, 2, bound_sets, 0, nullptr);
  auto spc = sh::push_from<sh::StrainLinksPush>(pc);
  if (sweeps)
    v.vkCmdBindPipeline(c, VK_PIPELINE_BIND_POINT_COMPUTE, strain_links_pipeline);
  for (std::uint32_t sweep = 0; sweep < sweeps; ++sweep)
    for (std::size_t k = 0; k + 1 < strain_colours.size(); ++k) {
      spc.stage = sweep;
      spc.link_first = strain_colours[k];
      spc.link_count = strain_colours[k + 1] - strain_colours[k];
      const std::uint32_t groups = (spc.link_count + workgroup - 1) / workgroup;
      const std::uint32_t gx = std::min(groups, groups_x), gy = (groups + gx - 1) / gx;
      v.vkCmdPushConstants(c, layout, VK_SHADER_STAGE_COMPUTE_BIT, 0, sizeof(spc), &spc);
      barriers::dispatch_to_dispatch(v, c); // the previous pass or colour -> this colour
      v.vkCmdDispatch(c, gx, gy, size());
      ++dispatches_;
    }
  if (const std::uint32_t newton = projection_iterations())
    dispatches_ += projection->record_substep(c, read, pc, newton);
  if (any_colliders())
    record_finish_pass(c, read, 1);
}

void SolverBatch::record_update(VkCommandBuffer c, bool first, bool last) {
  const auto& v = vk();
  const std::uint32_t read = parity;
  if (family().integrator == Integrator::implicit_euler) {
    dispatches_ += implicit->record_substep(c, read, pc, family(), collider_types(), first);
    return;
  }
  const std::uint32_t instances_z = size(); // one dispatch serves every instance (gl_WorkGroupID.z)
  const bool rk4 = family().integrator == Integrator::rk4;
  if (options.fused && !rk4) {
    // One dispatch per (sub)step (fused.comp); the descriptor set alternates with the parity.
    v.vkCmdBindPipeline(c, VK_PIPELINE_BIND_POINT_COMPUTE, fused_pipes[last ? 1 : 0][collider_types()]);
    pc.stage = 0;
    const VkDescriptorSet bound_sets[2] = {sets[read][0], texel_sets[read]};
    v.vkCmdBindDescriptorSets(c, VK_PIPELINE_BIND_POINT_COMPUTE, layout, 0, 2, bound_sets, 0, nullptr);
    v.vkCmdPushConstants(c, layout, VK_SHADER_STAGE_COMPUTE_BIT, 0, sizeof(pc), &pc);
    if (!first)
      barriers::dispatch_to_dispatch(v, c); // previous step -> this step
    v.vkCmdDispatch(c, groups_x, groups_y, instances_z);
    ++dispatches_;
    return;
  }
  const std::uint32_t stages = rk4 ? 4 : 1;
  VkDescriptorSet bound = VK_NULL_HANDLE;
  for (std::uint32_t k = 0; k < stages; ++k) {
    pc.stage = k;
    const VkDescriptorSet set = sets[read][k == 0 ? 0 : 1];
    if (set != bound) {
      const VkDescriptorSet bound_sets[2] = {set, texel_sets[k == 0 ? read : 2]};
      v.vkCmdBindDescriptorSets(c, VK_PIPELINE_BIND_POINT_COMPUTE, layout, 0, 2, bound_sets, 0, nullptr);
      bound = set;
    }
    v.vkCmdPushConstants(c, layout, VK_SHADER_STAGE_COMPUTE_BIT, 0, sizeof(pc), &pc);
    if (!first || k > 0)
      barriers::dispatch_to_dispatch(v, c); // integrate (previous stage/step) -> force
    v.vkCmdBindPipeline(c, VK_PIPELINE_BIND_POINT_COMPUTE, force_pipes[collider_types()]);
    v.vkCmdDispatch(c, groups_x, groups_y, instances_z);
    barriers::dispatch_to_dispatch(v, c); // force -> integrate
    v.vkCmdBindPipeline(c, VK_PIPELINE_BIND_POINT_COMPUTE, integrate_pipes[collider_types()]);
    v.vkCmdDispatch(c, groups_x, groups_y, instances_z);
    dispatches_ += 2;
  }
}

} // namespace vkcloth::gpu
