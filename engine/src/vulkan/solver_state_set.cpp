// SPDX-License-Identifier: MIT
// SolverBatch (solver_batch.hpp): the state set (its layout: passes/state_set.hpp; the batch's
// descriptor sets and texel views), how a pass binds it, and the specialisation constants of the
// state passes (the grid stencil, the fused variant, the fan-normal switch). The passes' pipelines
// are theirs (passes/); the buffers and readbacks are in solver_batch.cpp, the recording of the
// steps in solver_batch_record.cpp.
#include "internal/resources.hpp"

#include <algorithm>
#include <array>
#include <cstdint>
#include <cstring>
#include <utility>

#include <fmt/format.h>

#include "internal/pipelines.hpp"
#include "passes/state_set.hpp"
#include "solver_batch.hpp"
#include "kernel/layout/vkcloth_shared.h"

namespace vkcloth::gpu {

namespace sh = shared;

// The specialisation constants of force.comp and fused.comp, as 32-bit words by constant_id:
// 0..39 the grid stencil (force_body.glsl), 40 SC_WRITE_AUX (fused.comp only, a VkBool32; force.comp
// has no constant 40, and an entry for an id a shader lacks is ignored), 41 SC_COLLIDER_TYPES
// (common.glsl: a mask of collider types), 42 SC_NORMAL_FLAGS (force_body.glsl: the batch's normal
// path as its instance flag).
std::array<std::uint32_t, 43> SolverBatch::state_constants(bool write_aux, std::uint32_t types,
                                                           bool csr) const {
  static_assert(sizeof(Stencil) == 40 * 4);
  const Stencil st = csr ? Stencil{} : stencil; // Stencil{}: the defaults, no stencil
  std::array<std::uint32_t, 43> words{};
  std::memcpy(words.data(), &st, sizeof(st));
  words[40] = write_aux ? 1u : 0u;
  words[41] = types;
  words[42] = csr ? VKCLOTH_FLAG_HAS_GRID | VKCLOTH_FLAG_RING_NORMALS : normal_flag(normals);
  return words;
}

Result<void> SolverBatch::ensure_pipeline(VkPipeline& slot, const ShaderSource& shader,
                                          std::span<const std::uint32_t> constants,
                                          std::uint32_t stage) const {
  if (slot)
    return {};
  auto p = ctx->pipelines->pipeline(shader, constants, variant(stage));
  if (!p)
    return p.error();
  slot = *p;
  return {};
}

void SolverBatch::bind_state(VkCommandBuffer c, std::uint32_t read, bool stage_input,
                             std::uint32_t texel) const {
  const VkDescriptorSet bound[2] = {sets[read][stage_input ? 1 : 0],
                                    texel == no_texel_set ? VK_NULL_HANDLE : texel_sets[texel]};
  vk().vkCmdBindDescriptorSets(c, VK_PIPELINE_BIND_POINT_COMPUTE, layout, 0, texel == no_texel_set ? 1 : 2,
                               bound, 0, nullptr);
}

void SolverBatch::push_state(VkCommandBuffer c, const void* push) const {
  static_assert(sizeof(sh::PushConstants) == 32, "every pass's push constants are 32 bytes");
  vk().vkCmdPushConstants(c, layout, VK_SHADER_STAGE_COMPUTE_BIT, 0, sizeof(sh::PushConstants), push);
}

void SolverBatch::dispatch_particles(VkCommandBuffer c) const {
  vk().vkCmdDispatch(c, groups_x, groups_y, size()); // one dispatch serves every instance (gl_WorkGroupID.z)
}

void SolverBatch::dispatch_items(VkCommandBuffer c, std::uint32_t items) const {
  const std::uint32_t groups = (items + workgroup - 1) / workgroup;
  if (groups == 0)
    return;
  const std::uint32_t gx = std::min(groups, groups_x), gy = (groups + gx - 1) / gx;
  vk().vkCmdDispatch(c, gx, gy, size());
}

Result<DeviceLayout> SolverBatch::resolve_layout(const Context::Impl& ctx, const GpuSolverOptions& options,
                                                 bool implicit) {
  const bool decided = options.buffer_access != BufferAccess::automatic && options.workgroup_size != 0;
  DeviceLayout out = decided ? DeviceLayout{} : device_layout(ctx);
  if (options.buffer_access != BufferAccess::automatic)
    out.access = options.buffer_access;
  if (options.workgroup_size != 0) {
    const VkPhysicalDeviceLimits& lim = ctx.properties.limits;
    if (options.workgroup_size > lim.maxComputeWorkGroupSize[0] ||
        options.workgroup_size > lim.maxComputeWorkGroupInvocations)
      return make_error(
          ErrorCode::unsupported,
          fmt::format("GpuSolverOptions::workgroup_size {} is larger than device '{}' allows ({} "
                      "invocations: maxComputeWorkGroupSize[0] {}, maxComputeWorkGroupInvocations {})",
                      options.workgroup_size, ctx.name,
                      std::min(lim.maxComputeWorkGroupSize[0], lim.maxComputeWorkGroupInvocations),
                      lim.maxComputeWorkGroupSize[0], lim.maxComputeWorkGroupInvocations));
    out.workgroup_size = options.workgroup_size;
  }
  if (implicit)
    out.workgroup_size = VKCLOTH_WORKGROUP_SIZE; // implicit*.comp: shared arrays of this size
  return out;
}

// The Context's layouts of the state set (set 0: storage buffers, set 1: texel views), then this
// batch's sets and views.
Result<void> SolverBatch::init_state_sets() {
  auto layouts = ctx->pipelines->layouts(kStateBindings);
  if (!layouts)
    return layouts.error();
  set_layout = layouts->storage;
  texel_layout = layouts->texel;
  layout = layouts->layout;
  VKCLOTH_TRY(create_descriptor_sets());
  if (access == BufferAccess::texel_views) // the storage builds leave set 1 bound but unwritten, unused
    VKCLOTH_TRY(create_texel_views());
  return {};
}

// Four storage sets ([read][state / RK4 stage input], written by write_sets()) and three texel sets.
Result<void> SolverBatch::create_descriptor_sets() {
  const auto& v = vk();
  const VkDescriptorPoolSize sizes[2] = {
      {VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, 4 * VKCLOTH_BINDING_COUNT},
      {VK_DESCRIPTOR_TYPE_UNIFORM_TEXEL_BUFFER, VKCLOTH_TEXEL_BINDING_COUNT * 3}};
  VkDescriptorPoolCreateInfo dp{};
  dp.sType = VK_STRUCTURE_TYPE_DESCRIPTOR_POOL_CREATE_INFO;
  dp.maxSets = 4 + 3;
  dp.poolSizeCount = 2;
  dp.pPoolSizes = sizes;
  VKCLOTH_VK_TRY(v.vkCreateDescriptorPool(ctx->device, &dp, v.allocator, pool.init(*ctx)),
                 "vkCreateDescriptorPool");
  const VkDescriptorSetLayout layouts[4] = {set_layout, set_layout, set_layout, set_layout};
  VkDescriptorSetAllocateInfo ai{};
  ai.sType = VK_STRUCTURE_TYPE_DESCRIPTOR_SET_ALLOCATE_INFO;
  ai.descriptorPool = pool;
  ai.descriptorSetCount = 4;
  ai.pSetLayouts = layouts;
  VKCLOTH_VK_TRY(v.vkAllocateDescriptorSets(ctx->device, &ai, &sets[0][0]), "vkAllocateDescriptorSets");
  const VkDescriptorSetLayout texel_layouts[3] = {texel_layout, texel_layout, texel_layout};
  ai.descriptorSetCount = 3;
  ai.pSetLayouts = texel_layouts;
  VKCLOTH_VK_TRY(v.vkAllocateDescriptorSets(ctx->device, &ai, texel_sets),
                 "vkAllocateDescriptorSets (texel)");
  return {};
}

// Set k: its positions view (k = 0, 1: positions[k]; 2: stage positions) and the same shared
// views. Uniform texel buffer support is mandatory for these formats. Strain links are viewed as
// R32UI, 3 texels each (no RGB32 format is mandatory for texel buffers); an Edge is one RGBA32UI.
Result<void> SolverBatch::create_texel_views() {
  const TexelViewSpec views[] = {
      {pos[0].buffer, VK_FORMAT_R32G32B32A32_SFLOAT, &pos_views[0], "positions[0]"},
      {pos[1].buffer, VK_FORMAT_R32G32B32A32_SFLOAT, &pos_views[1], "positions[1]"},
      {stage_pos.buffer, VK_FORMAT_R32G32B32A32_SFLOAT, &pos_views[2], "stage positions"},
      {particle.buffer, VK_FORMAT_R32G32_UINT, &particle_view, "particle constants"},
      {vel.buffer, VK_FORMAT_R32G32B32A32_SFLOAT, &vel_view, "velocities"},
      {flags.buffer, VK_FORMAT_R32_UINT, &flags_view, "flags"},
      {instances.buffer, VK_FORMAT_R32G32B32A32_UINT, &instances_view, "instance parameters"},
      {ranges.buffer, VK_FORMAT_R32G32B32A32_UINT, &ranges_view, "adjacency ranges"},
      {edges.buffer, VK_FORMAT_R32G32B32A32_UINT, &edges_view, "adjacency"}};
  VKCLOTH_TRY(vkcloth::gpu::create_texel_views(*ctx, views));
  return create_buffer_views();
}

// The views of the buffers that are replaced while the batch lives (again whenever one is:
// ensure_strain_chains, ensure_tethers, ensure_collider_capacity, ensure_mesh_buffers): the strain
// links, the tethers, the colliders and the mesh colliders' nodes and triangles; then every texel set.
Result<void> SolverBatch::create_buffer_views() {
  static_assert(sizeof(sh::TetherSlot) == 8, "one RG32UI texel per TetherSlot");
  static_assert(sizeof(sh::MeshNode) == 2 * 16 && sizeof(sh::MeshTriangle) == 3 * 16);
  if (access != BufferAccess::texel_views || !texel_sets[0])
    return {}; // no views (init_pipelines), or not yet (create_buffers: create_texel_views makes them)
  static_assert(sizeof(sh::StrainLink) == 12, "three R32UI texels per StrainLink");
  const TexelViewSpec views[] = {
      {strain_links.buffer, VK_FORMAT_R32_UINT, &strain_links_view, "strain links"},
      {tethers.buffer, VK_FORMAT_R32G32_UINT, &tethers_view, "tethers"},
      {colliders.buffer, VK_FORMAT_R32G32B32A32_UINT, &colliders_view, "colliders"},
      {mesh_nodes.buffer, VK_FORMAT_R32G32B32A32_UINT, &mesh_nodes_view, "mesh collider nodes"},
      {mesh_tris.buffer, VK_FORMAT_R32G32B32A32_UINT, &mesh_tris_view, "mesh collider triangles"}};
  VKCLOTH_TRY(vkcloth::gpu::create_texel_views(*ctx, views));
  const std::pair<const BufferView*, std::uint32_t> shared_views[VKCLOTH_TEXEL_BINDING_COUNT - 1] = {
      {&particle_view, VKCLOTH_TEXEL_BINDING_PARTICLE},
      {&vel_view, VKCLOTH_TEXEL_BINDING_VEL},
      {&flags_view, VKCLOTH_TEXEL_BINDING_FLAGS},
      {&instances_view, VKCLOTH_TEXEL_BINDING_INSTANCES},
      {&ranges_view, VKCLOTH_TEXEL_BINDING_RANGES},
      {&edges_view, VKCLOTH_TEXEL_BINDING_EDGES},
      {&strain_links_view, VKCLOTH_TEXEL_BINDING_STRAIN_LINKS},
      {&tethers_view, VKCLOTH_TEXEL_BINDING_TETHERS},
      {&colliders_view, VKCLOTH_TEXEL_BINDING_COLLIDERS},
      {&mesh_nodes_view, VKCLOTH_TEXEL_BINDING_MESH_NODES},
      {&mesh_tris_view, VKCLOTH_TEXEL_BINDING_MESH_TRIS}};
  std::array<VkWriteDescriptorSet, VKCLOTH_TEXEL_BINDING_COUNT * 3> writes{};
  std::size_t w = 0;
  for (std::uint32_t k = 0; k < 3; ++k) {
    writes[w++] = texel_write(texel_sets[k], VKCLOTH_TEXEL_BINDING_POS_IN, pos_views[k]);
    for (auto [view, binding] : shared_views)
      writes[w++] = texel_write(texel_sets[k], binding, *view);
  }
  vk().vkUpdateDescriptorSets(ctx->device, static_cast<std::uint32_t>(w), writes.data(), 0, nullptr);
  return {};
}

// The topology's grid stencil (ClothTopology: the one detection rule, shared with the CPU) as
// specialisation constants, its constants in float as the edges are uploaded.
void SolverBatch::set_stencil(const ClothTopology& topology) {
  stencil = Stencil{};
  const GridStencil* st = topology.stencil();
  if (!st)
    return;
  stencil.enabled = 1;
  stencil.nx = topology.grid()->nx;
  stencil.ny = topology.grid()->ny;
  for (std::size_t k = 0; k < 12; ++k) {
    stencil.offset[k] = st->offset[k];
    stencil.rest[k] = float(st->rest_length[k]);
    stencil.stiffness[k] = float(st->stiffness[k]);
  }
  stencil.border = st->border_geometric ? 1u : 0u;
}

Result<void> SolverBatch::write_sets() {
  std::array<VkDescriptorBufferInfo, 4 * VKCLOTH_BINDING_COUNT> infos{};
  std::array<VkWriteDescriptorSet, 4 * VKCLOTH_BINDING_COUNT> writes{};
  std::size_t k = 0;
  for (std::uint32_t read = 0; read < 2; ++read)
    for (std::uint32_t src = 0; src < 2; ++src) {
      const Buffer* by_binding[VKCLOTH_BINDING_COUNT] = {};
      by_binding[VKCLOTH_BINDING_POS_IN] = src ? &stage_pos : &pos[read];
      by_binding[VKCLOTH_BINDING_VEL_IN] = src ? &stage_vel : &vel;
      by_binding[VKCLOTH_BINDING_FORCE_OUT] = src ? &force_stage : &force;
      by_binding[VKCLOTH_BINDING_VEL_FILT] = &vel_filt;
      by_binding[VKCLOTH_BINDING_NORMAL] = &normal;
      by_binding[VKCLOTH_BINDING_POS_BASE] = &pos[read];
      by_binding[VKCLOTH_BINDING_POS_OUT] = &pos[read ^ 1u];
      by_binding[VKCLOTH_BINDING_VEL] = &vel;
      by_binding[VKCLOTH_BINDING_STAGE_POS] = &stage_pos;
      by_binding[VKCLOTH_BINDING_STAGE_VEL] = &stage_vel;
      by_binding[VKCLOTH_BINDING_ACC_POS] = &acc_pos;
      by_binding[VKCLOTH_BINDING_ACC_VEL] = &acc_vel;
      by_binding[VKCLOTH_BINDING_PARTICLE] = &particle;
      by_binding[VKCLOTH_BINDING_OFFSETS] = &offsets;
      by_binding[VKCLOTH_BINDING_EDGES] = &edges;
      by_binding[VKCLOTH_BINDING_COLLIDERS] = &colliders;
      by_binding[VKCLOTH_BINDING_FLAGS] = &flags;
      by_binding[VKCLOTH_BINDING_INSTANCES] = &instances;
      by_binding[VKCLOTH_BINDING_STRAIN_LINKS] = &strain_links;
      by_binding[VKCLOTH_BINDING_TETHERS] = &tethers;
      by_binding[VKCLOTH_BINDING_UV] = &uv;
      by_binding[VKCLOTH_BINDING_VERTICES] = &vertices;
      by_binding[VKCLOTH_BINDING_MESH_NODES] = &mesh_nodes;
      by_binding[VKCLOTH_BINDING_MESH_TRIS] = &mesh_tris;
      by_binding[VKCLOTH_BINDING_VBD_ORDER] = &vbd_order;
      by_binding[VKCLOTH_BINDING_TARGETS] = &targets;
      by_binding[VKCLOTH_BINDING_FRAMES] = &frames;
      by_binding[VKCLOTH_BINDING_MESH_CACHE] = &mesh_cache;
      for (std::uint32_t b = 0; b < VKCLOTH_BINDING_COUNT; ++b, ++k) {
        infos[k] = VkDescriptorBufferInfo{by_binding[b]->buffer, 0, VK_WHOLE_SIZE};
        writes[k] = VkWriteDescriptorSet{};
        writes[k].sType = VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET;
        writes[k].dstSet = sets[read][src];
        writes[k].dstBinding = b;
        writes[k].descriptorCount = 1;
        writes[k].descriptorType = VK_DESCRIPTOR_TYPE_STORAGE_BUFFER;
        writes[k].pBufferInfo = &infos[k];
      }
    }
  vk().vkUpdateDescriptorSets(ctx->device, static_cast<std::uint32_t>(writes.size()), writes.data(), 0,
                              nullptr);
  for (const auto& pass : passes) // the sets of the passes that bind state buffers in their own
    VKCLOTH_TRY(pass->write_sets(*this));
  return {};
}

ImplicitInputs SolverBatch::implicit_inputs() const {
  return {{pos[0].buffer, pos[1].buffer},
          vel.buffer,
          force.buffer,
          normal.buffer,
          particle.buffer,
          offsets.buffer,
          edges.buffer,
          colliders.buffer,
          flags.buffer,
          instances.buffer,
          mesh_nodes.buffer,
          mesh_tris.buffer,
          mesh_cache.buffer};
}

} // namespace vkcloth::gpu
