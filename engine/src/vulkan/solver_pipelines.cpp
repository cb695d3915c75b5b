// SPDX-License-Identifier: MIT
// SolverBatch (solver_batch.hpp): descriptor set layouts, sets and texel views, the compute
// pipelines (force, integrate, the fused variants) and their specialisation constants (the grid
// stencil, the fused variant, the fan-normal switch). The buffers and readbacks are in
// solver_batch.cpp, the recording of the steps in solver_batch_record.cpp.
#include "resources.hpp"

#include <algorithm>
#include <array>
#include <cstdint>
#include <cstring>
#include <utility>

#include <fmt/format.h>

#include "pipelines.hpp"
#include "solver_batch.hpp"
#include "vkcloth_shared.h"

namespace vkcloth::gpu {

namespace sh = shared;

namespace {

/// The specialisation constants of force.comp and fused.comp, as 32-bit words by constant_id:
/// 0..39 the grid stencil (force_body.glsl), 40 SC_WRITE_AUX (fused.comp only, a VkBool32; force.comp
/// has no constant 40, and an entry for an id a shader lacks is ignored), 41 SC_COLLIDER_TYPES
/// (common.glsl: a mask of collider types), 42 SC_NORMAL_FLAGS (force_body.glsl: the batch's normal
/// path as its instance flag).
std::array<std::uint32_t, 43> solver_constants(const SolverBatch::Stencil& st, bool write_aux,
                                               std::uint32_t collider_types, SolverBatch::Normals normals) {
  static_assert(sizeof(SolverBatch::Stencil) == 40 * 4);
  std::array<std::uint32_t, 43> words{};
  std::memcpy(words.data(), &st, sizeof(st));
  words[40] = write_aux ? 1u : 0u;
  words[41] = collider_types;
  words[42] = SolverBatch::normal_flag(normals);
  return words;
}

} // namespace

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

// The Context's layouts (set 0: storage buffers, set 1: texel views), then this batch's sets and
// views, then the Context's pipelines for this batch's stencil.
Result<void> SolverBatch::init_pipelines() {
  auto layouts = ctx->pipelines->solver_layouts();
  if (!layouts)
    return layouts.error();
  set_layout = layouts->storage;
  texel_layout = layouts->texel;
  layout = layouts->layout;
  VKCLOTH_TRY(create_descriptor_sets());
  if (access == BufferAccess::texel_views) // the storage builds leave set 1 bound but unwritten, unused
    VKCLOTH_TRY(create_texel_views());
  return create_pipelines();
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
      {edges.buffer, VK_FORMAT_R32G32B32A32_UINT, &edges_view, "adjacency"},
      {strain_links.buffer, VK_FORMAT_R32_UINT, &strain_links_view, "strain links"}};
  static_assert(sizeof(sh::StrainLink) == 12, "three R32UI texels per StrainLink");
  VKCLOTH_TRY(vkcloth::gpu::create_texel_views(*ctx, views));
  return create_buffer_views();
}

// The views of the buffers that are replaced while the batch lives (again whenever one is:
// ensure_tethers, ensure_collider_capacity, ensure_mesh_buffers): the tethers, the colliders and
// the mesh colliders' nodes and triangles; then every texel set.
Result<void> SolverBatch::create_buffer_views() {
  static_assert(sizeof(sh::TetherSlot) == 8, "one RG32UI texel per TetherSlot");
  static_assert(sizeof(sh::MeshNode) == 2 * 16 && sizeof(sh::MeshTriangle) == 3 * 16);
  if (access != BufferAccess::texel_views || !texel_sets[0])
    return {}; // no views (init_pipelines), or not yet (create_buffers: create_texel_views makes them)
  const TexelViewSpec views[] = {
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

// Provot's sweeps and vertices.comp, from the Context's registry, in the batch's build (texel
// views or storage buffers) and workgroup size (resolve_layout); the passes specialised with the
// batch's collider types come from ensure_fused and ensure_collider_pipelines.
Result<void> SolverBatch::create_pipelines() {
  using Shader = PipelineRegistry::Shader;
  const PipelineRegistry::Variant variant{access, workgroup};
  auto lp = ctx->pipelines->pipeline(Shader::strain_links, {}, variant);
  if (!lp)
    return lp.error();
  strain_links_pipeline = *lp;
  if (options.interleaved_vertices) {
    auto vp = ctx->pipelines->pipeline(Shader::vertices, {}, variant);
    if (!vp)
      return vp.error();
    vertices_pipeline = *vp;
  }
  return {};
}

// The fused.comp variants the current parameters need ([0] and [1] x the collider types in the
// batch); the registry makes each variant once per Context.
Result<void> SolverBatch::ensure_fused() {
  const std::uint32_t types = collider_types();
  if (!options.fused || (fused_pipes[0][types] && fused_pipes[1][types]))
    return {};
  for (std::uint32_t aux = 0; aux < 2; ++aux) {
    const auto constants = solver_constants(stencil, aux != 0, types, normals);
    auto p = ctx->pipelines->pipeline(PipelineRegistry::Shader::fused, constants, {access, workgroup});
    if (!p)
      return p.error();
    fused_pipes[aux][types] = *p;
  }
  return {};
}

// The variants the current parameters need of the passes specialised with the batch's collider
// types (SC_COLLIDER_TYPES, as ensure_fused): force.comp (with the grid stencil and the fan
// switch) and integrate.comp where the batch runs the two-pass layout, and strain_finish.comp per
// stage (the tethers' with no collider code); each made once per Context.
Result<void> SolverBatch::ensure_collider_pipelines() {
  using Shader = PipelineRegistry::Shader;
  const std::uint32_t types = collider_types();
  const Integrator integrator = family().integrator;
  const bool two_pass =
      integrator != Integrator::implicit_euler && (!options.fused || integrator == Integrator::rk4);
  if (implicit) { // its FORCE and FINISH passes: CSR gather (no stencil), every normal path as the flags say
    auto words = solver_constants(Stencil{}, true, types, Normals::grid); // Stencil{}: the defaults
    words[42] = VKCLOTH_FLAG_HAS_GRID | VKCLOTH_FLAG_RING_NORMALS; // SC_NORMAL_FLAGS: both, the default
    VKCLOTH_TRY(implicit->ensure_collider_passes(types, words));
  }
  if (two_pass && !force_pipes[types]) {
    const auto constants = solver_constants(stencil, true, types, normals);
    auto fp = ctx->pipelines->pipeline(Shader::force, constants, {access, workgroup});
    if (!fp)
      return fp.error();
    auto ip = ctx->pipelines->pipeline(Shader::integrate, constants, {access, workgroup});
    if (!ip)
      return ip.error();
    force_pipes[types] = *fp;
    integrate_pipes[types] = *ip;
  }
  // strain_finish.comp's stages where record_stretch and record_substep use them: the tethers, the
  // colliders after stretch control, the colliders after self-collision.
  const bool needed[3] = {any_tethers(), any_stretch() && any_colliders(),
                          self_iterations() > 0 && any_colliders()};
  for (std::uint32_t stage = 0; stage < 3; ++stage) {
    const std::uint32_t t = stage == 0 ? 0u : types;
    if (!needed[stage] || finish_pipes[stage][t])
      continue;
    std::array<std::uint32_t, 42> constants{}; // ids 0..41, of which strain_finish.comp has only 41
    constants[41] = t;                         // SC_COLLIDER_TYPES
    auto p = ctx->pipelines->pipeline(Shader::strain_finish, constants, {access, workgroup, stage});
    if (!p)
      return p.error();
    finish_pipes[stage][t] = *p;
  }
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
  if (self_collision)
    VKCLOTH_TRY(self_collision->write_sets(one_set_inputs()));
  if (projection)
    VKCLOTH_TRY(projection->write_sets(one_set_inputs()));
  if (implicit)
    return implicit->write_sets({{pos[0].buffer, pos[1].buffer},
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
                                 mesh_tris.buffer});
  return {};
}

} // namespace vkcloth::gpu
