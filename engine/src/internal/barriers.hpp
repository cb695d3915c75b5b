// SPDX-License-Identifier: MIT
// Every pipeline barrier vkcloth records (solver, world, renderer, offscreen target) lives here,
// each saying why it is needed and what it orders. Classic vkCmdPipelineBarrier (core 1.0, so an
// adopted device needs no synchronization2 feature). The solver uses global memory barriers: one
// costs the same as a buffer barrier on current drivers and covers all of its buffers at once.
// Image layout transitions and queue-family ownership transfers need per-resource barriers:
// image() / buffer() build them, pipeline() records them (as niagara's resources.h).
#pragma once

#include "internal/vk_internal.hpp"

#include <array>
#include <span>
#include <vector>

namespace vkcloth::gpu::barriers {

inline void memory(const VolkDeviceTable& vk, VkCommandBuffer cmd, VkPipelineStageFlags src_stage,
                   VkAccessFlags src_access, VkPipelineStageFlags dst_stage, VkAccessFlags dst_access) {
  VkMemoryBarrier b{};
  b.sType = VK_STRUCTURE_TYPE_MEMORY_BARRIER;
  b.srcAccessMask = src_access;
  b.dstAccessMask = dst_access;
  vk.vkCmdPipelineBarrier(cmd, src_stage, dst_stage, 0, 1, &b, 0, nullptr, 0, nullptr);
}

/// Start of record_steps(): everything recorded or submitted earlier on the queue (uploads,
/// fills, copies, the previous batch's dispatches, a renderer's reads of the buffers) completes,
/// and its writes become visible, before the first dispatch reads or writes any buffer.
inline void before_steps(const VolkDeviceTable& vk, VkCommandBuffer cmd) {
  memory(vk, cmd, VK_PIPELINE_STAGE_ALL_COMMANDS_BIT, VK_ACCESS_MEMORY_WRITE_BIT,
         VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, VK_ACCESS_SHADER_READ_BIT | VK_ACCESS_SHADER_WRITE_BIT);
}

/// Between two dispatches (force -> integrate, integrate -> next force, RK4 stage -> stage):
/// RAW: the previous pass's storage writes (forces, filtered velocities, normals, new positions,
/// stage buffers, flags) are visible to the next pass's reads; WAR: the previous pass's reads
/// finish before the next pass overwrites what it read (execution dependency).
inline void dispatch_to_dispatch(const VolkDeviceTable& vk, VkCommandBuffer cmd) {
  memory(vk, cmd, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, VK_ACCESS_SHADER_WRITE_BIT,
         VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, VK_ACCESS_SHADER_READ_BIT | VK_ACCESS_SHADER_WRITE_BIT);
}

/// After the last dispatch: its writes become visible to a consumer (`dst`), e.g. vertex input
/// for drawing, transfer for copies, host for mapped reads.
inline void after_steps(const VolkDeviceTable& vk, VkCommandBuffer cmd, VkPipelineStageFlags dst_stage,
                        VkAccessFlags dst_access) {
  memory(vk, cmd, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, VK_ACCESS_SHADER_WRITE_BIT, dst_stage, dst_access);
}

/// Before a readback: every earlier command's writes (dispatches, fills, copies) are visible to
/// the copy into the staging buffer and to host reads of mapped memory.
inline void before_readback(const VolkDeviceTable& vk, VkCommandBuffer cmd) {
  memory(vk, cmd, VK_PIPELINE_STAGE_ALL_COMMANDS_BIT, VK_ACCESS_MEMORY_WRITE_BIT,
         VK_PIPELINE_STAGE_TRANSFER_BIT | VK_PIPELINE_STAGE_HOST_BIT,
         VK_ACCESS_TRANSFER_READ_BIT | VK_ACCESS_HOST_READ_BIT);
}

/// After a staging copy (solver readbacks, the offscreen target's frame copy): the copy's writes
/// are visible to host reads of the mapped memory.
inline void transfer_to_host(const VolkDeviceTable& vk, VkCommandBuffer cmd) {
  memory(vk, cmd, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_ACCESS_TRANSFER_WRITE_BIT, VK_PIPELINE_STAGE_HOST_BIT,
         VK_ACCESS_HOST_READ_BIT);
}

/// After uploads (fills and staging copies): their writes are visible to the dispatches.
inline void transfer_to_compute(const VolkDeviceTable& vk, VkCommandBuffer cmd) {
  memory(vk, cmd, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_ACCESS_TRANSFER_WRITE_BIT,
         VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, VK_ACCESS_SHADER_READ_BIT | VK_ACCESS_SHADER_WRITE_BIT);
}

/// ClothWorld moving instances into a rebuilt batch: every earlier command's writes (the old
/// batch's dispatches, the new batch's fills and uploads) are visible to the copies, which also
/// wait for earlier reads of the destination (a fresh buffer: none, but cheap to state).
inline void before_batch_copy(const VolkDeviceTable& vk, VkCommandBuffer cmd) {
  memory(vk, cmd, VK_PIPELINE_STAGE_ALL_COMMANDS_BIT, VK_ACCESS_MEMORY_WRITE_BIT,
         VK_PIPELINE_STAGE_TRANSFER_BIT, VK_ACCESS_TRANSFER_READ_BIT | VK_ACCESS_TRANSFER_WRITE_BIT);
}

/// An empty submission's only command (CommandContext::wait_for_earlier_work): everything
/// submitted earlier on the queue completes before it, so its fence signals only then (an
/// execution dependency chain; no memory is accessed).
inline void drain(const VolkDeviceTable& vk, VkCommandBuffer cmd) {
  memory(vk, cmd, VK_PIPELINE_STAGE_ALL_COMMANDS_BIT, 0, VK_PIPELINE_STAGE_ALL_COMMANDS_BIT, 0);
}

/// After those copies: visible to the next steps, to a renderer's vertex reads and to the host
/// (the old batch's divergence flags are read right after this submission).
inline void after_batch_copy(const VolkDeviceTable& vk, VkCommandBuffer cmd) {
  memory(vk, cmd, VK_PIPELINE_STAGE_TRANSFER_BIT | VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT,
         VK_ACCESS_TRANSFER_WRITE_BIT | VK_ACCESS_SHADER_WRITE_BIT,
         VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT | VK_PIPELINE_STAGE_VERTEX_INPUT_BIT |
             VK_PIPELINE_STAGE_HOST_BIT,
         VK_ACCESS_SHADER_READ_BIT | VK_ACCESS_SHADER_WRITE_BIT | VK_ACCESS_VERTEX_ATTRIBUTE_READ_BIT |
             VK_ACCESS_HOST_READ_BIT);
}

} // namespace vkcloth::gpu::barriers

namespace vkcloth::gpu::barriers {

/// Before the host's own edits recorded into the command buffer (vkCmdUpdateBuffer of a held
/// particle, of changed parameters and colliders): every earlier access (dispatches' reads and
/// writes, the renderer's vertex reads) completes and earlier writes are visible before the
/// transfer writes (WAR, WAW). For parameters, before_steps() then makes them visible (RAW).
inline void before_host_edit(const VolkDeviceTable& vk, VkCommandBuffer cmd) {
  memory(vk, cmd, VK_PIPELINE_STAGE_ALL_COMMANDS_BIT, VK_ACCESS_MEMORY_WRITE_BIT,
         VK_PIPELINE_STAGE_TRANSFER_BIT, VK_ACCESS_TRANSFER_WRITE_BIT);
}

/// After those edits: the transfer writes are visible to the next steps and to vertex reads.
inline void after_host_edit(const VolkDeviceTable& vk, VkCommandBuffer cmd) {
  memory(vk, cmd, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_ACCESS_TRANSFER_WRITE_BIT,
         VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT | VK_PIPELINE_STAGE_VERTEX_INPUT_BIT,
         VK_ACCESS_SHADER_READ_BIT | VK_ACCESS_SHADER_WRITE_BIT | VK_ACCESS_VERTEX_ATTRIBUTE_READ_BIT);
}

} // namespace vkcloth::gpu::barriers

namespace vkcloth::gpu::barriers {

/// Between two passes of the implicit step (passes/implicit_gpu.hpp): like dispatch_to_dispatch, and the
/// writes of the indirect dispatch arguments (by a reducing pass's last workgroup) become visible
/// to the next indirect dispatches' argument reads (DRAW_INDIRECT stage). The WAR on those
/// arguments (read by an earlier dispatch, rewritten by a later pass) is covered because
/// DRAW_INDIRECT is logically earlier than COMPUTE_SHADER in the source scope; a pass that
/// rewrites the arguments it was dispatched with read them before any of its invocations ran.
inline void implicit_pass(const VolkDeviceTable& vk, VkCommandBuffer cmd) {
  memory(vk, cmd, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, VK_ACCESS_SHADER_WRITE_BIT,
         VK_PIPELINE_STAGE_DRAW_INDIRECT_BIT | VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT,
         VK_ACCESS_INDIRECT_COMMAND_READ_BIT | VK_ACCESS_SHADER_READ_BIT | VK_ACCESS_SHADER_WRITE_BIT);
}

/// After the host resets the strain projection's indirect arguments (vkCmdUpdateBuffer, after
/// before_host_edit): the transfer writes are visible to the indirect dispatches' argument reads
/// and to the shader, which reads and rewrites them.
inline void host_edit_to_indirect(const VolkDeviceTable& vk, VkCommandBuffer cmd) {
  memory(vk, cmd, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_ACCESS_TRANSFER_WRITE_BIT,
         VK_PIPELINE_STAGE_DRAW_INDIRECT_BIT | VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT,
         VK_ACCESS_INDIRECT_COMMAND_READ_BIT | VK_ACCESS_SHADER_READ_BIT | VK_ACCESS_SHADER_WRITE_BIT);
}

} // namespace vkcloth::gpu::barriers

namespace vkcloth::gpu::barriers {

/// A whole-image (one mip, one layer) barrier of `aspect`, no queue-family transfer.
inline VkImageMemoryBarrier image(VkImage img, VkAccessFlags src_access, VkAccessFlags dst_access,
                                  VkImageLayout old_layout, VkImageLayout new_layout,
                                  VkImageAspectFlags aspect = VK_IMAGE_ASPECT_COLOR_BIT) {
  VkImageMemoryBarrier b{};
  b.sType = VK_STRUCTURE_TYPE_IMAGE_MEMORY_BARRIER;
  b.srcAccessMask = src_access;
  b.dstAccessMask = dst_access;
  b.oldLayout = old_layout;
  b.newLayout = new_layout;
  b.srcQueueFamilyIndex = b.dstQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
  b.image = img;
  b.subresourceRange = {aspect, 0, 1, 0, 1};
  return b;
}

/// A whole-buffer barrier; `src_family` != `dst_family` makes it a queue-family ownership transfer.
inline VkBufferMemoryBarrier buffer(VkBuffer buf, VkAccessFlags src_access, VkAccessFlags dst_access,
                                    std::uint32_t src_family = VK_QUEUE_FAMILY_IGNORED,
                                    std::uint32_t dst_family = VK_QUEUE_FAMILY_IGNORED) {
  VkBufferMemoryBarrier b{};
  b.sType = VK_STRUCTURE_TYPE_BUFFER_MEMORY_BARRIER;
  b.srcAccessMask = src_access;
  b.dstAccessMask = dst_access;
  b.srcQueueFamilyIndex = src_family;
  b.dstQueueFamilyIndex = dst_family;
  b.buffer = buf;
  b.offset = 0;
  b.size = VK_WHOLE_SIZE;
  return b;
}

/// Records per-resource barriers between `src_stage` and `dst_stage`.
inline void pipeline(const VolkDeviceTable& vk, VkCommandBuffer cmd, VkPipelineStageFlags src_stage,
                     VkPipelineStageFlags dst_stage, std::span<const VkBufferMemoryBarrier> buffers,
                     std::span<const VkImageMemoryBarrier> images) {
  vk.vkCmdPipelineBarrier(cmd, src_stage, dst_stage, 0, 0, nullptr,
                          static_cast<std::uint32_t>(buffers.size()), buffers.data(),
                          static_cast<std::uint32_t>(images.size()), images.data());
}

/// Texture upload, before the copy: UNDEFINED -> TRANSFER_DST_OPTIMAL for the copy's writes. A
/// fresh image: nothing earlier to wait for (TOP_OF_PIPE, no source access); old contents dropped.
inline void texture_before_upload(const VolkDeviceTable& vk, VkCommandBuffer cmd, VkImage img) {
  const VkImageMemoryBarrier b = image(img, 0, VK_ACCESS_TRANSFER_WRITE_BIT, VK_IMAGE_LAYOUT_UNDEFINED,
                                       VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL);
  pipeline(vk, cmd, VK_PIPELINE_STAGE_TOP_OF_PIPE_BIT, VK_PIPELINE_STAGE_TRANSFER_BIT, {}, {&b, 1});
}

/// Texture upload, after the copy: TRANSFER_DST -> SHADER_READ_ONLY_OPTIMAL; the copy's writes
/// become visible to the fragment shader's sampling (every later draw of the renderer).
inline void texture_after_upload(const VolkDeviceTable& vk, VkCommandBuffer cmd, VkImage img) {
  const VkImageMemoryBarrier b =
      image(img, VK_ACCESS_TRANSFER_WRITE_BIT, VK_ACCESS_SHADER_READ_BIT,
            VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL);
  pipeline(vk, cmd, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_PIPELINE_STAGE_FRAGMENT_SHADER_BIT, {}, {&b, 1});
}

/// The offscreen target's render pass does its image layout transitions itself: colour
/// UNDEFINED -> COLOR_ATTACHMENT_OPTIMAL at the start (contents cleared) and -> TRANSFER_SRC_OPTIMAL
/// at the end (for the readback copy); depth UNDEFINED -> DEPTH_STENCIL_ATTACHMENT_OPTIMAL. These
/// two subpass dependencies order those transitions:
/// [0] external -> subpass: the previous frame's readback copy (transfer read of the colour image)
///     and its attachment writes finish before this frame's transition, clears and writes (WAR, WAW);
/// [1] subpass -> external: the colour writes and the final transition happen before the readback
///     copy's transfer read (RAW).
inline std::array<VkSubpassDependency, 2> offscreen_subpass_dependencies() {
  constexpr VkPipelineStageFlags attachments = VK_PIPELINE_STAGE_COLOR_ATTACHMENT_OUTPUT_BIT |
                                               VK_PIPELINE_STAGE_EARLY_FRAGMENT_TESTS_BIT |
                                               VK_PIPELINE_STAGE_LATE_FRAGMENT_TESTS_BIT;
  std::array<VkSubpassDependency, 2> dep{};
  dep[0].srcSubpass = VK_SUBPASS_EXTERNAL;
  dep[0].dstSubpass = 0;
  dep[0].srcStageMask = VK_PIPELINE_STAGE_TRANSFER_BIT | attachments;
  dep[0].srcAccessMask = VK_ACCESS_COLOR_ATTACHMENT_WRITE_BIT | VK_ACCESS_DEPTH_STENCIL_ATTACHMENT_WRITE_BIT;
  dep[0].dstStageMask = attachments;
  dep[0].dstAccessMask = VK_ACCESS_COLOR_ATTACHMENT_READ_BIT | VK_ACCESS_COLOR_ATTACHMENT_WRITE_BIT |
                         VK_ACCESS_DEPTH_STENCIL_ATTACHMENT_READ_BIT |
                         VK_ACCESS_DEPTH_STENCIL_ATTACHMENT_WRITE_BIT;
  dep[1].srcSubpass = 0;
  dep[1].dstSubpass = VK_SUBPASS_EXTERNAL;
  dep[1].srcStageMask = VK_PIPELINE_STAGE_COLOR_ATTACHMENT_OUTPUT_BIT;
  dep[1].srcAccessMask = VK_ACCESS_COLOR_ATTACHMENT_WRITE_BIT;
  dep[1].dstStageMask = VK_PIPELINE_STAGE_TRANSFER_BIT;
  dep[1].dstAccessMask = VK_ACCESS_TRANSFER_READ_BIT;
  return dep;
}

/// One half of a queue-family ownership transfer of `buffers` (the drawn buffers, EXCLUSIVE
/// sharing, compute and graphics families apart: docs/embedding.md section 6). The RELEASE half
/// is recorded on the source family's queue after its last use (`stage` / `access`: that use;
/// the destination scope is ignored, BOTTOM_OF_PIPE), the ACQUIRE half on the destination
/// family's queue after waiting on the semaphore the release's submission signals (`stage` /
/// `access`: the next use there; the source scope is ignored, TOP_OF_PIPE). Equal families make
/// them plain barriers (one queue: the same recording order stays valid).
inline void queue_transfer(const VolkDeviceTable& vk, VkCommandBuffer cmd, std::span<const VkBuffer> buffers,
                           bool release, std::uint32_t src_family, std::uint32_t dst_family,
                           VkPipelineStageFlags stage, VkAccessFlags access) {
  std::vector<VkBufferMemoryBarrier> b;
  for (VkBuffer buf : buffers)
    b.push_back(buffer(buf, release ? access : 0, release ? 0 : access, src_family, dst_family));
  constexpr VkPipelineStageFlags top = VK_PIPELINE_STAGE_TOP_OF_PIPE_BIT,
                                 bottom = VK_PIPELINE_STAGE_BOTTOM_OF_PIPE_BIT;
  pipeline(vk, cmd, release ? stage : top, release ? bottom : stage, b, {});
}

} // namespace vkcloth::gpu::barriers
