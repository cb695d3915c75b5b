// SPDX-License-Identifier: MIT
// SolverBatch's recording: the passes of each step (passes/passes.cpp) into the caller's command
// buffer, in list order, each after the barrier that orders it (barriers.hpp says why each barrier
// is there); before them, what the host changed (parameters, collider poses). The buffers, uploads
// and readbacks: solver_batch.cpp; the state set: solver_state_set.cpp.
#include "solver_batch.hpp"

#include <algorithm>
#include <utility>

#include "internal/barriers.hpp"
#include "kernel/layout/vkcloth_shared.h"

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

// Each instance's targets at substep k's end (the colliders posed there) into its TARGETS range,
// VKCLOTH_NO_TARGET after its last, as many entries as the instance with the most has (the
// passes' dispatch); in double until the one conversion to float, as CpuSolver's.
void SolverBatch::record_targets(VkCommandBuffer c, std::uint32_t k) {
  const std::uint32_t n = targets_per_slot();
  std::vector<sh::Target> packed(n);
  std::vector<vkcloth::detail::TargetEntry> entries;
  barriers::before_host_edit(vk(), c); // the last substep's reads of the targets finish first (WAR)
  for (std::uint32_t s = 0; s < size(); ++s) {
    slots[s].targets.at_substep(slots[s].params, k, family().substeps, entries);
    for (std::uint32_t i = 0; i < n; ++i) {
      sh::Target& t = packed[i];
      if (i >= entries.size()) {
        t = sh::Target{};
        t.particle = VKCLOTH_NO_TARGET;
        continue;
      }
      const vkcloth::detail::TargetEntry& e = entries[i];
      const glm::vec3 x(e.position), v(e.velocity);
      t = sh::Target{x.x, x.y, x.z, e.particle, v.x, v.y, v.z, float(e.reach)};
    }
    record_buffer_update(c, targets, packed.data(), packed.size() * sizeof(sh::Target),
                         VkDeviceSize(s) * count * sizeof(sh::Target));
  }
  barriers::transfer_to_compute(vk(), c); // the targets -> this substep's passes
}

// Each instance's frame step (detail::frame_step, as CpuSolver::step) into FRAMES: the jump as
// rows and shift, the carry's inputs, in float as the CPU converts them.
void SolverBatch::record_frames(VkCommandBuffer c, std::uint32_t k, const std::vector<Collider>& before) {
  std::vector<sh::FrameMotion> packed(size());
  frame_jump_now = frame_carry_now = false;
  const auto put = [](sh::vec4& out, glm::dvec3 v, double w) {
    const glm::vec3 f(v);
    out = sh::vec4{f.x, f.y, f.z, float(w)};
  };
  for (std::uint32_t s = 0; s < size(); ++s) {
    Slot& slot = slots[s];
    const vkcloth::detail::FrameStep f =
        vkcloth::detail::frame_step(slot.params, before[s], vkcloth::detail::frame_collider(slot.params),
                                    k == 0 ? slot.host_jump : std::nullopt);
    if (slot.params.inertia.enabled())
      slot.frame_last = vkcloth::detail::frame_collider(slot.params);
    sh::FrameMotion& m = packed[s];
    if (f.jump) {
      const vkcloth::detail::JumpRows rows = vkcloth::detail::jump_rows(*f.jump);
      const glm::vec3 shift(rows.shift);
      put(m.row0, rows.r0, shift.x);
      put(m.row1, rows.r1, shift.y);
      put(m.row2, rows.r2, shift.z);
      m.jump = 1;
      slot.targets.teleport(*f.jump);
      frame_jump_now = true;
    }
    if (f.carry) {
      put(m.dv, f.dv, f.carry_linear);
      put(m.omega0, f.omega0, f.carry_angular);
      put(m.omega1, f.omega1, 0.0);
      put(m.c0, f.c0, 0.0);
      put(m.c1, f.c1, 0.0);
      m.carry = 1;
      frame_carry_now = true;
    }
  }
  if (!frame_jump_now && !frame_carry_now)
    return;
  barriers::before_host_edit(vk(), c); // the last substep's reads of the frames finish first (WAR)
  record_buffer_update(c, frames, packed.data(), packed.size() * sizeof(sh::FrameMotion));
  barriers::transfer_to_compute(vk(), c); // the frames -> this substep's passes
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
  if (!mesh_tris_pending.empty()) { // a skinned mesh's new pose, into the buffers of its counts
    record_buffer_update(c, mesh_nodes, mesh_nodes_pending.data(),
                         mesh_nodes_pending.size() * sizeof(sh::MeshNode));
    record_buffer_update(c, mesh_tris, mesh_tris_pending.data(),
                         mesh_tris_pending.size() * sizeof(sh::MeshTriangle));
    mesh_nodes_pending.clear();
    mesh_tris_pending.clear();
  }
  for (const auto& pass : passes) // the passes' own parameters (self-collision's)
    pass->write_params(*this, c);
  params_dirty = false; // before_steps() next makes the transfer writes visible to the dispatches
}

void SolverBatch::record_buffer_update(VkCommandBuffer c, const Buffer& dst, const void* data,
                                       std::size_t bytes, VkDeviceSize offset) const {
  constexpr std::size_t max_update = 65536; // vkCmdUpdateBuffer's limit per call
  for (std::size_t at = 0; at < bytes; at += max_update)
    vk().vkCmdUpdateBuffer(c, dst.buffer, offset + at, std::min(max_update, bytes - at),
                           static_cast<const char*>(data) + at);
}

void SolverBatch::record(VkCommandBuffer c, std::uint32_t steps) {
  if (steps == 0)
    return;
  record_params_update(c);
  if (mesh_cache_clear) {                // other meshes: every search entry empty (radius 0)
    barriers::before_host_edit(vk(), c); // earlier steps' reads and writes of the entries finish first
    vk().vkCmdFillBuffer(c, mesh_cache.buffer, 0, VK_WHOLE_SIZE, 0);
    mesh_cache_clear = false;
  }
  barriers::before_steps(vk(), c);
  bool first = true;
  for (std::uint32_t s = 0; s < steps; ++s) {
    pc.step = static_cast<std::uint32_t>(recorded + 1); // 1-based number of the step being computed
    const bool moving = any_moving_colliders();
    const bool targets_now = any_targets();
    const bool frames_now = any_frame();
    const double h = family().substeps == 1 ? family().dt : family().dt / double(family().substeps);
    for (std::uint32_t k = 0; k < family().substeps; ++k) {
      std::vector<Collider> frame_before(frames_now ? size() : 0);
      for (std::uint32_t i = 0; i < frame_before.size(); ++i)
        frame_before[i] =
            slots[i].frame_last ? *slots[i].frame_last : vkcloth::detail::frame_collider(slots[i].params);
      if (moving) // a substep meets the colliders where they are at its end (as CpuSolver::step)
        record_collider_motion(c, h);
      for (Slot& slot : slots) // and the hosts' frames
        vkcloth::detail::advance_host_frame(slot.params, h);
      if (frames_now) // before the targets: a jump moves the host's targets too
        record_frames(c, k, frame_before);
      if (targets_now)
        record_targets(c, k);
      record_passes(c, Pass::When::substep, first, s + 1 == steps && k + 1 == family().substeps);
      first = false;
      parity ^= 1u; // positions[read ^ 1] now holds the new state
    }
    ++recorded;
    for (Slot& slot : slots) {
      slot.targets.end_step(); // the host's targets held where they arrived
      slot.host_jump.reset();  // recorded into this step's first substep
    }
    frame_jump_now = frame_carry_now = false;
    for (Slot& slot : slots)
      if (!slot.diverged) {
        ++slot.step;
        slot.time += slot.params.dt;
      }
  }
  record_passes(c, Pass::When::recording_end, false, true);
}

void SolverBatch::record_passes(VkCommandBuffer c, Pass::When when, bool first, bool last) {
  PassFrame frame{c, parity, &pc, first, last};
  for (const auto& pass : passes)
    if (pass->when() == when && pass->active(*this)) {
      dispatches_ += pass->record(*this, frame);
      frame.first = false; // only the first dispatch of the recording follows before_steps()
    }
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

} // namespace vkcloth::gpu
