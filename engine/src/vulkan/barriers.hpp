// Every pipeline barrier the Vulkan solver records lives here, each saying what it orders.
// Classic vkCmdPipelineBarrier with global memory barriers (core 1.0, so an adopted device needs
// no synchronization2 feature); a global barrier costs the same as a buffer barrier on current
// drivers and covers all of the solver's buffers at once.
#pragma once

#include "vk_internal.hpp"

namespace vkcloth::gpu::barriers {

inline void memory(const VolkDeviceTable& vk, VkCommandBuffer cmd, VkPipelineStageFlags src_stage, VkAccessFlags src_access,
                   VkPipelineStageFlags dst_stage, VkAccessFlags dst_access) {
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
  memory(vk, cmd, VK_PIPELINE_STAGE_ALL_COMMANDS_BIT, VK_ACCESS_MEMORY_WRITE_BIT, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT,
         VK_ACCESS_SHADER_READ_BIT | VK_ACCESS_SHADER_WRITE_BIT);
}

/// Between two dispatches (force -> integrate, integrate -> next force, RK4 stage -> stage):
/// RAW: the previous pass's storage writes (forces, filtered velocities, normals, new positions,
/// stage buffers, flags) are visible to the next pass's reads; WAR: the previous pass's reads
/// finish before the next pass overwrites what it read (execution dependency).
inline void dispatch_to_dispatch(const VolkDeviceTable& vk, VkCommandBuffer cmd) {
  memory(vk, cmd, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, VK_ACCESS_SHADER_WRITE_BIT, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT,
         VK_ACCESS_SHADER_READ_BIT | VK_ACCESS_SHADER_WRITE_BIT);
}

/// After the last dispatch: its writes become visible to a consumer (`dst`), e.g. vertex input
/// for drawing, transfer for copies, host for mapped reads.
inline void after_steps(const VolkDeviceTable& vk, VkCommandBuffer cmd, VkPipelineStageFlags dst_stage, VkAccessFlags dst_access) {
  memory(vk, cmd, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, VK_ACCESS_SHADER_WRITE_BIT, dst_stage, dst_access);
}

/// Before a readback: every earlier command's writes (dispatches, fills, copies) are visible to
/// the copy into the staging buffer and to host reads of mapped memory.
inline void before_readback(const VolkDeviceTable& vk, VkCommandBuffer cmd) {
  memory(vk, cmd, VK_PIPELINE_STAGE_ALL_COMMANDS_BIT, VK_ACCESS_MEMORY_WRITE_BIT,
         VK_PIPELINE_STAGE_TRANSFER_BIT | VK_PIPELINE_STAGE_HOST_BIT, VK_ACCESS_TRANSFER_READ_BIT | VK_ACCESS_HOST_READ_BIT);
}

/// After a staging copy (readback): the copy's writes are visible to host reads.
inline void transfer_to_host(const VolkDeviceTable& vk, VkCommandBuffer cmd) {
  memory(vk, cmd, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_ACCESS_TRANSFER_WRITE_BIT, VK_PIPELINE_STAGE_HOST_BIT,
         VK_ACCESS_HOST_READ_BIT);
}

/// After uploads (fills and staging copies): their writes are visible to the dispatches.
inline void transfer_to_compute(const VolkDeviceTable& vk, VkCommandBuffer cmd) {
  memory(vk, cmd, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_ACCESS_TRANSFER_WRITE_BIT, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT,
         VK_ACCESS_SHADER_READ_BIT | VK_ACCESS_SHADER_WRITE_BIT);
}

/// ClothWorld moving instances into a rebuilt batch: every earlier command's writes (the old
/// batch's dispatches, the new batch's fills and uploads) are visible to the copies, which also
/// wait for earlier reads of the destination (a fresh buffer: none, but cheap to state).
inline void before_batch_copy(const VolkDeviceTable& vk, VkCommandBuffer cmd) {
  memory(vk, cmd, VK_PIPELINE_STAGE_ALL_COMMANDS_BIT, VK_ACCESS_MEMORY_WRITE_BIT, VK_PIPELINE_STAGE_TRANSFER_BIT,
         VK_ACCESS_TRANSFER_READ_BIT | VK_ACCESS_TRANSFER_WRITE_BIT);
}

/// After those copies: visible to the next steps, to a renderer's vertex reads and to the host
/// (the old batch's divergence flags are read right after this submission).
inline void after_batch_copy(const VolkDeviceTable& vk, VkCommandBuffer cmd) {
  memory(vk, cmd, VK_PIPELINE_STAGE_TRANSFER_BIT | VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, VK_ACCESS_TRANSFER_WRITE_BIT |
         VK_ACCESS_SHADER_WRITE_BIT, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT | VK_PIPELINE_STAGE_VERTEX_INPUT_BIT |
         VK_PIPELINE_STAGE_HOST_BIT, VK_ACCESS_SHADER_READ_BIT | VK_ACCESS_SHADER_WRITE_BIT |
         VK_ACCESS_VERTEX_ATTRIBUTE_READ_BIT | VK_ACCESS_HOST_READ_BIT);
}

} // namespace vkcloth::gpu::barriers

namespace vkcloth::gpu::barriers {

/// Before the host's own edits of the state buffers (vkCmdUpdateBuffer of a held particle):
/// every earlier access (dispatches' writes, the renderer's vertex reads) completes and earlier
/// writes are visible before the transfer writes.
inline void before_host_edit(const VolkDeviceTable& vk, VkCommandBuffer cmd) {
  memory(vk, cmd, VK_PIPELINE_STAGE_ALL_COMMANDS_BIT, VK_ACCESS_MEMORY_WRITE_BIT, VK_PIPELINE_STAGE_TRANSFER_BIT,
         VK_ACCESS_TRANSFER_WRITE_BIT);
}

/// After those edits: the transfer writes are visible to the next steps and to vertex reads.
inline void after_host_edit(const VolkDeviceTable& vk, VkCommandBuffer cmd) {
  memory(vk, cmd, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_ACCESS_TRANSFER_WRITE_BIT,
         VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT | VK_PIPELINE_STAGE_VERTEX_INPUT_BIT,
         VK_ACCESS_SHADER_READ_BIT | VK_ACCESS_SHADER_WRITE_BIT | VK_ACCESS_VERTEX_ATTRIBUTE_READ_BIT);
}

} // namespace vkcloth::gpu::barriers

namespace vkcloth::gpu::barriers {

/// Between two passes of the implicit step (implicit_gpu.hpp): like dispatch_to_dispatch, and the
/// reduce pass's writes of the indirect dispatch arguments become visible to the next indirect
/// dispatches' argument reads (DRAW_INDIRECT stage). The WAR on those arguments (read by an
/// earlier dispatch, rewritten by a later reduce) is covered because DRAW_INDIRECT is logically
/// earlier than COMPUTE_SHADER in the source scope.
inline void implicit_pass(const VolkDeviceTable& vk, VkCommandBuffer cmd) {
  memory(vk, cmd, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, VK_ACCESS_SHADER_WRITE_BIT,
         VK_PIPELINE_STAGE_DRAW_INDIRECT_BIT | VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT,
         VK_ACCESS_INDIRECT_COMMAND_READ_BIT | VK_ACCESS_SHADER_READ_BIT | VK_ACCESS_SHADER_WRITE_BIT);
}

} // namespace vkcloth::gpu::barriers
