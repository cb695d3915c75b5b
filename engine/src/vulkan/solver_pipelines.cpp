// GpuSolver::Impl (solver_batch.hpp): descriptor set layouts, sets and texel views, the compute
// pipelines (force, integrate, the fused variants) and their specialisation constants (the grid
// stencil). The stepping, buffers and readbacks are in gpu_solver.cpp.
#include "vk_internal.hpp"

#include <array>
#include <cstdint>

#include <fmt/format.h>

#include "solver_batch.hpp"
#include "vkcloth/shaders/force_comp_spv.hpp"
#include "vkcloth/shaders/fused_comp_spv.hpp"
#include "vkcloth/shaders/integrate_comp_spv.hpp"
#include "vkcloth_shared.h"

namespace vkcloth::gpu {

namespace sh = shared;

namespace {

template <std::size_t N> Result<VkShaderModule> make_module(const DeviceFns& vk, VkDevice d, const std::uint32_t (&code)[N],
                                                            const char* name) {
  VkShaderModuleCreateInfo ci{};
  ci.sType = VK_STRUCTURE_TYPE_SHADER_MODULE_CREATE_INFO;
  ci.codeSize = N * sizeof(std::uint32_t);
  ci.pCode = code;
  VkShaderModule m = VK_NULL_HANDLE;
  VKCLOTH_VK_TRY(vk.vkCreateShaderModule(d, &ci, vk.allocator, &m), fmt::format("vkCreateShaderModule ({})", name));
  return m;
}


} // namespace

Result<void> GpuSolver::Impl::init_pipelines() {
  const auto& v = vk();
  const VkDevice d = ctx->device;
  std::array<VkDescriptorSetLayoutBinding, VKCLOTH_BINDING_COUNT> bindings{};
  for (std::uint32_t i = 0; i < bindings.size(); ++i)
    bindings[i] = VkDescriptorSetLayoutBinding{i, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, 1, VK_SHADER_STAGE_COMPUTE_BIT, nullptr};
  VkDescriptorSetLayoutCreateInfo li{};
  li.sType = VK_STRUCTURE_TYPE_DESCRIPTOR_SET_LAYOUT_CREATE_INFO;
  li.bindingCount = static_cast<std::uint32_t>(bindings.size());
  li.pBindings = bindings.data();
  VKCLOTH_VK_TRY(v.vkCreateDescriptorSetLayout(d, &li, v.allocator, &set_layout), "vkCreateDescriptorSetLayout");
  const VkDescriptorSetLayoutBinding texel_bindings[5] = {
      {VKCLOTH_TEXEL_BINDING_POS_IN, VK_DESCRIPTOR_TYPE_UNIFORM_TEXEL_BUFFER, 1, VK_SHADER_STAGE_COMPUTE_BIT, nullptr},
      {VKCLOTH_TEXEL_BINDING_PARTICLE, VK_DESCRIPTOR_TYPE_UNIFORM_TEXEL_BUFFER, 1, VK_SHADER_STAGE_COMPUTE_BIT, nullptr},
      {VKCLOTH_TEXEL_BINDING_VEL, VK_DESCRIPTOR_TYPE_UNIFORM_TEXEL_BUFFER, 1, VK_SHADER_STAGE_COMPUTE_BIT, nullptr},
      {VKCLOTH_TEXEL_BINDING_FLAGS, VK_DESCRIPTOR_TYPE_UNIFORM_TEXEL_BUFFER, 1, VK_SHADER_STAGE_COMPUTE_BIT, nullptr},
      {VKCLOTH_TEXEL_BINDING_INSTANCES, VK_DESCRIPTOR_TYPE_UNIFORM_TEXEL_BUFFER, 1, VK_SHADER_STAGE_COMPUTE_BIT, nullptr}};
  li.bindingCount = 5;
  li.pBindings = texel_bindings;
  VKCLOTH_VK_TRY(v.vkCreateDescriptorSetLayout(d, &li, v.allocator, &texel_layout), "vkCreateDescriptorSetLayout (texel)");

  const VkPushConstantRange range{VK_SHADER_STAGE_COMPUTE_BIT, 0, sizeof(sh::PushConstants)};
  VkPipelineLayoutCreateInfo pi{};
  pi.sType = VK_STRUCTURE_TYPE_PIPELINE_LAYOUT_CREATE_INFO;
  const VkDescriptorSetLayout set_layouts[2] = {set_layout, texel_layout};
  pi.setLayoutCount = 2;
  pi.pSetLayouts = set_layouts;
  pi.pushConstantRangeCount = 1;
  pi.pPushConstantRanges = &range;
  VKCLOTH_VK_TRY(v.vkCreatePipelineLayout(d, &pi, v.allocator, &layout), "vkCreatePipelineLayout");

  const VkDescriptorPoolSize sizes[2] = {{VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, 4 * VKCLOTH_BINDING_COUNT},
                                         {VK_DESCRIPTOR_TYPE_UNIFORM_TEXEL_BUFFER, 5 * 3}};
  VkDescriptorPoolCreateInfo dp{};
  dp.sType = VK_STRUCTURE_TYPE_DESCRIPTOR_POOL_CREATE_INFO;
  dp.maxSets = 4 + 3;
  dp.poolSizeCount = 2;
  dp.pPoolSizes = sizes;
  VKCLOTH_VK_TRY(v.vkCreateDescriptorPool(d, &dp, v.allocator, &pool), "vkCreateDescriptorPool");
  const VkDescriptorSetLayout layouts[4] = {set_layout, set_layout, set_layout, set_layout};
  VkDescriptorSetAllocateInfo ai{};
  ai.sType = VK_STRUCTURE_TYPE_DESCRIPTOR_SET_ALLOCATE_INFO;
  ai.descriptorPool = pool;
  ai.descriptorSetCount = 4;
  ai.pSetLayouts = layouts;
  VKCLOTH_VK_TRY(v.vkAllocateDescriptorSets(d, &ai, &sets[0][0]), "vkAllocateDescriptorSets");
  // The texel sets never change: positions[0/1] and the stage positions live as long as the solver.
  const VkDescriptorSetLayout texel_layouts[3] = {texel_layout, texel_layout, texel_layout};
  ai.descriptorSetCount = 3;
  ai.pSetLayouts = texel_layouts;
  VKCLOTH_VK_TRY(v.vkAllocateDescriptorSets(d, &ai, texel_sets), "vkAllocateDescriptorSets (texel)");
  const Buffer* viewed[3] = {&pos[0], &pos[1], &stage_pos};
  VkWriteDescriptorSet texel_writes[15]{};
  // The same views in all three sets: particle constants (sh::ParticleInfo), velocities, flags,
  // instance parameters.
  // Uniform texel buffer support is mandatory for these formats.
  const struct {
    const Buffer* buffer;
    VkFormat format;
    VkBufferView* view;
    std::uint32_t binding;
    const char* what;
  } shared_views[4] = {
      {&particle, VK_FORMAT_R32G32_UINT, &particle_view, VKCLOTH_TEXEL_BINDING_PARTICLE, "vkCreateBufferView (particle constants)"},
      {&vel, VK_FORMAT_R32G32B32A32_SFLOAT, &vel_view, VKCLOTH_TEXEL_BINDING_VEL, "vkCreateBufferView (velocities)"},
      {&flags, VK_FORMAT_R32_UINT, &flags_view, VKCLOTH_TEXEL_BINDING_FLAGS, "vkCreateBufferView (flags)"},
      {&instances, VK_FORMAT_R32G32B32A32_UINT, &instances_view, VKCLOTH_TEXEL_BINDING_INSTANCES,
       "vkCreateBufferView (instance parameters)"}};
  for (int b = 0; b < 4; ++b) {
    VkBufferViewCreateInfo bvi{};
    bvi.sType = VK_STRUCTURE_TYPE_BUFFER_VIEW_CREATE_INFO;
    bvi.buffer = shared_views[b].buffer->buffer;
    bvi.format = shared_views[b].format;
    bvi.offset = 0;
    bvi.range = VK_WHOLE_SIZE;
    VKCLOTH_VK_TRY(v.vkCreateBufferView(d, &bvi, v.allocator, shared_views[b].view), shared_views[b].what);
    for (int k = 0; k < 3; ++k) {
      VkWriteDescriptorSet& w = texel_writes[3 + 3 * b + k];
      w.sType = VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET;
      w.dstSet = texel_sets[k];
      w.dstBinding = shared_views[b].binding;
      w.descriptorCount = 1;
      w.descriptorType = VK_DESCRIPTOR_TYPE_UNIFORM_TEXEL_BUFFER;
      w.pTexelBufferView = shared_views[b].view;
    }
  }
  for (int k = 0; k < 3; ++k) {
    VkBufferViewCreateInfo vi{};
    vi.sType = VK_STRUCTURE_TYPE_BUFFER_VIEW_CREATE_INFO;
    vi.buffer = viewed[k]->buffer;
    vi.format = VK_FORMAT_R32G32B32A32_SFLOAT; // uniform texel buffer support is mandatory for it
    vi.offset = 0;
    vi.range = VK_WHOLE_SIZE;
    VKCLOTH_VK_TRY(v.vkCreateBufferView(d, &vi, v.allocator, &pos_views[k]), "vkCreateBufferView (positions)");
    texel_writes[k].sType = VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET;
    texel_writes[k].dstSet = texel_sets[k];
    texel_writes[k].dstBinding = VKCLOTH_TEXEL_BINDING_POS_IN;
    texel_writes[k].descriptorCount = 1;
    texel_writes[k].descriptorType = VK_DESCRIPTOR_TYPE_UNIFORM_TEXEL_BUFFER;
    texel_writes[k].pTexelBufferView = &pos_views[k];
  }
  v.vkUpdateDescriptorSets(d, 15, texel_writes, 0, nullptr);

  VkShaderModule modules[2] = {};
  auto destroy_modules = [&] {
    for (VkShaderModule m : modules)
      if (m) v.vkDestroyShaderModule(d, m, v.allocator);
  };
  {
    auto fm = make_module(v, d, spirv::force_comp_spv, "force.comp");
    if (!fm) return fm.error();
    modules[0] = *fm;
    auto im = make_module(v, d, spirv::integrate_comp_spv, "integrate.comp");
    if (!im) {
      destroy_modules();
      return im.error();
    }
    modules[1] = *im;
  }
  // Specialisation constants of force_body.glsl (force.comp, fused.comp): the grid stencil.
  static_assert(sizeof(Stencil) == 40 * 4);
  std::array<VkSpecializationMapEntry, 40> entries{};
  for (std::uint32_t k = 0; k < entries.size(); ++k) entries[k] = VkSpecializationMapEntry{k, k * 4, 4};
  const VkSpecializationInfo spec{static_cast<std::uint32_t>(entries.size()), entries.data(), sizeof(Stencil), &stencil};
  VkComputePipelineCreateInfo ci[2]{};
  for (int k = 0; k < 2; ++k) {
    ci[k].sType = VK_STRUCTURE_TYPE_COMPUTE_PIPELINE_CREATE_INFO;
    ci[k].stage = VkPipelineShaderStageCreateInfo{VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO, nullptr, 0,
                                                  VK_SHADER_STAGE_COMPUTE_BIT, modules[k], "main",
                                                  k == 1 ? nullptr : &spec};
    ci[k].layout = layout;
  }
  VkPipeline pipes[2] = {};
  const VkResult r = v.vkCreateComputePipelines(d, VK_NULL_HANDLE, 2, ci, v.allocator, pipes);
  destroy_modules();
  if (r != VK_SUCCESS) return vk_error(r, "vkCreateComputePipelines (force.comp, integrate.comp)");
  force_pipeline = pipes[0];
  integrate_pipeline = pipes[1];
  return {};
}

// The fused.comp variants the current parameters need ([0] and [1] x colliders in the batch or not).
Result<void> GpuSolver::Impl::ensure_fused() {
  const std::uint32_t col = any_colliders() ? 1u : 0u;
  if (!options.fused || (fused_pipes[0][col] && fused_pipes[1][col])) return {};
  const auto& v = vk();
  const VkDevice d = ctx->device;
  auto m = make_module(v, d, spirv::fused_comp_spv, "fused.comp");
  if (!m) return m.error();
  // Constant ids 0..39: the stencil; 40: SC_WRITE_AUX; 41: SC_COLLIDERS (fused.comp, common.glsl).
  struct Data {
    Stencil st;
    std::uint32_t write_aux, colliders; // VkBool32
  } data[2] = {{stencil, 0u, col}, {stencil, 1u, col}};
  static_assert(sizeof(Data) == 42 * 4);
  std::array<VkSpecializationMapEntry, 42> entries{};
  for (std::uint32_t k = 0; k < entries.size(); ++k) entries[k] = VkSpecializationMapEntry{k, k * 4, 4};
  VkSpecializationInfo spec[2];
  VkComputePipelineCreateInfo ci[2]{};
  for (int k = 0; k < 2; ++k) {
    spec[k] = VkSpecializationInfo{static_cast<std::uint32_t>(entries.size()), entries.data(), sizeof(Data), &data[k]};
    ci[k].sType = VK_STRUCTURE_TYPE_COMPUTE_PIPELINE_CREATE_INFO;
    ci[k].stage = VkPipelineShaderStageCreateInfo{VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO, nullptr, 0,
                                                  VK_SHADER_STAGE_COMPUTE_BIT, *m, "main", &spec[k]};
    ci[k].layout = layout;
  }
  VkPipeline pipes[2] = {};
  const VkResult r = v.vkCreateComputePipelines(d, VK_NULL_HANDLE, 2, ci, v.allocator, pipes);
  v.vkDestroyShaderModule(d, *m, v.allocator);
  if (r != VK_SUCCESS) return vk_error(r, "vkCreateComputePipelines (fused.comp)");
  for (int k = 0; k < 2; ++k) {
    if (fused_pipes[k][col]) v.vkDestroyPipeline(d, fused_pipes[k][col], v.allocator);
    fused_pipes[k][col] = pipes[k];
  }
  return {};
}

// Like CpuSolver::detect_stencil: the stencil applies when every interior particle's gather list
// (2 <= i < nx-2, 2 <= j < ny-2) is the same up to translation, in the same order, with the same
// float constants. Then the shaders' interior branch sums exactly the CSR terms in CSR order.
void GpuSolver::Impl::detect_stencil(const ParticleSystem& system) {
  stencil = Stencil{};
  if (!system.grid) return;
  const std::int64_t gx = system.grid->nx, gy = system.grid->ny;
  if (gx < 5 || gy < 5) return;
  const auto& off = system.adjacency.offsets;
  const auto& refs = system.adjacency.refs;
  const std::int64_t first = 2 * gx + 2;
  if (off[first + 1] - off[first] != 12) return;
  Stencil st;
  st.enabled = 1;
  st.nx = static_cast<std::uint32_t>(gx);
  st.ny = static_cast<std::uint32_t>(gy);
  for (int k = 0; k < 12; ++k) {
    const SpringRef& r = refs[off[first] + k];
    st.offset[k] = static_cast<std::int32_t>(std::int64_t(r.other) - first);
    st.rest[k] = float(system.springs[r.spring].rest_length);
    st.stiffness[k] = float(system.springs[r.spring].stiffness);
  }
  for (std::int64_t j = 2; j < gy - 2; ++j)
    for (std::int64_t i = 2; i < gx - 2; ++i) {
      const std::int64_t p = j * gx + i;
      if (off[p + 1] - off[p] != 12) return;
      for (int k = 0; k < 12; ++k) {
        const SpringRef& r = refs[off[p] + k];
        const Spring& sp = system.springs[r.spring];
        if (std::int64_t(r.other) - p != st.offset[k] || float(sp.rest_length) != st.rest[k] ||
            float(sp.stiffness) != st.stiffness[k])
          return;
      }
    }
  stencil = st;
  // Border particles (SC_BORDER): their lists must be the stencil entries whose neighbour lies in
  // the grid, in stencil order, with the same constants; offsets must be (di, dj) in [-2, 2]^2.
  std::int64_t di[12], dj[12];
  for (int k = 0; k < 12; ++k) {
    dj[k] = (st.offset[k] + 2 * gx + 2) / gx - 2;
    di[k] = st.offset[k] - dj[k] * gx;
    if (st.offset[k] + 2 * gx + 2 < 0 || dj[k] < -2 || dj[k] > 2 || di[k] < -2 || di[k] > 2) return;
  }
  for (std::int64_t j = 0; j < gy; ++j)
    for (std::int64_t i = 0; i < gx; ++i) {
      if (i >= 2 && i < gx - 2 && j >= 2 && j < gy - 2) continue; // checked above
      const std::int64_t p = j * gx + i;
      std::int64_t e = off[p];
      for (int k = 0; k < 12; ++k) {
        if (i + di[k] < 0 || i + di[k] >= gx || j + dj[k] < 0 || j + dj[k] >= gy) continue;
        if (e >= off[p + 1]) return;
        const SpringRef& r = refs[e++];
        const Spring& sp = system.springs[r.spring];
        if (std::int64_t(r.other) - p != st.offset[k] || float(sp.rest_length) != st.rest[k] ||
            float(sp.stiffness) != st.stiffness[k])
          return;
      }
      if (e != off[p + 1]) return;
    }
  stencil.border = 1;
}

Result<void> GpuSolver::Impl::write_sets() {
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
  vk().vkUpdateDescriptorSets(ctx->device, static_cast<std::uint32_t>(writes.size()), writes.data(), 0, nullptr);
  if (implicit)
    return implicit->write_sets({{pos[0].buffer, pos[1].buffer}, vel.buffer, force.buffer, normal.buffer, particle.buffer,
                                 offsets.buffer, edges.buffer, colliders.buffer, flags.buffer,
                                 instances.buffer});
  return {};
}

} // namespace vkcloth::gpu
