// SPDX-License-Identifier: MIT
#include "pipelines.hpp"

#include <array>

#include <fmt/format.h>

#include "implicit_shared.h"
#include "vkcloth/shaders/force_comp_spv.hpp"
#include "vkcloth/shaders/fused_comp_spv.hpp"
#include "vkcloth/shaders/implicit_comp_spv.hpp"
#include "vkcloth/shaders/implicit_reduce_comp_spv.hpp"
#include "vkcloth/shaders/integrate_comp_spv.hpp"
#include "vkcloth/shaders/strain_finish_comp_spv.hpp"
#include "vkcloth/shaders/vertices_comp_spv.hpp"
#include "vkcloth/shaders/strain_links_comp_spv.hpp"
#include "vkcloth_shared.h"

namespace vkcloth::gpu {

namespace {

struct ShaderCode {
  std::span<const std::uint32_t> code;
  const char* name;
};

ShaderCode code_of(PipelineRegistry::Shader s) {
  using S = PipelineRegistry::Shader;
  switch (s) {
  case S::force:
    return {spirv::force_comp_spv, "force.comp"};
  case S::integrate:
    return {spirv::integrate_comp_spv, "integrate.comp"};
  case S::fused:
    return {spirv::fused_comp_spv, "fused.comp"};
  case S::implicit:
    return {spirv::implicit_comp_spv, "implicit.comp"};
  case S::implicit_reduce:
    return {spirv::implicit_reduce_comp_spv, "implicit_reduce.comp"};
  case S::strain_links:
    return {spirv::strain_links_comp_spv, "strain_links.comp"};
  case S::strain_finish:
    return {spirv::strain_finish_comp_spv, "strain_finish.comp"};
  case S::vertices:
    return {spirv::vertices_comp_spv, "vertices.comp"};
  }
  return {{}, "?"};
}

/// The storage bindings of implicit.comp / implicit_reduce.comp (implicit_shared.h).
constexpr std::uint32_t kImplicitBindings[] = {
    VKCLOTH_BINDING_POS_IN,         VKCLOTH_BINDING_FORCE_OUT,  VKCLOTH_BINDING_NORMAL,
    VKCLOTH_BINDING_POS_OUT,        VKCLOTH_BINDING_VEL,        VKCLOTH_BINDING_PARTICLE,
    VKCLOTH_BINDING_OFFSETS,        VKCLOTH_BINDING_EDGES,      VKCLOTH_BINDING_COLLIDERS,
    VKCLOTH_BINDING_FLAGS,          VKCLOTH_BINDING_INSTANCES,  VKCLOTH_BINDING_FAN_OFFSETS,
    VKCLOTH_BINDING_FANS,           VKCLOTH_BINDING_IMPL_VF,    VKCLOTH_BINDING_IMPL_KS,
    VKCLOTH_BINDING_IMPL_BLOCK_INV, VKCLOTH_BINDING_IMPL_X,     VKCLOTH_BINDING_IMPL_R,
    VKCLOTH_BINDING_IMPL_Z,         VKCLOTH_BINDING_IMPL_D,     VKCLOTH_BINDING_IMPL_Q,
    VKCLOTH_BINDING_IMPL_PARTIALS,  VKCLOTH_BINDING_IMPL_STATE, VKCLOTH_BINDING_IMPL_ARGS};

} // namespace

std::span<const std::uint32_t> implicit_bindings() {
  return kImplicitBindings;
}

VkPipelineCache PipelineRegistry::cache() {
  const std::lock_guard lock(mutex_);
  return cache_locked();
}

VkPipelineCache PipelineRegistry::cache_locked() {
  if (cache_tried_)
    return cache_;
  cache_tried_ = true;
  VkPipelineCacheCreateInfo ci{};
  ci.sType = VK_STRUCTURE_TYPE_PIPELINE_CACHE_CREATE_INFO;
  if (ctx_.vk.vkCreatePipelineCache(ctx_.device, &ci, ctx_.vk.allocator, cache_.init(ctx_)) != VK_SUCCESS)
    cache_.reset(); // optional: pipelines are then created without one
  return cache_;
}

Result<PipelineRegistry::SolverLayouts> PipelineRegistry::solver_layouts() {
  const std::lock_guard lock(mutex_);
  return solver_layouts_locked();
}

Result<PipelineRegistry::SolverLayouts> PipelineRegistry::solver_layouts_locked() {
  if (!solver_layout_) {
    std::array<std::uint32_t, VKCLOTH_BINDING_COUNT> storage{};
    for (std::uint32_t i = 0; i < storage.size(); ++i)
      storage[i] = i;
    auto sl = create_compute_set_layout(ctx_, storage, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, "solver");
    if (!sl)
      return sl.error();
    const std::uint32_t texel[] = {
        VKCLOTH_TEXEL_BINDING_POS_IN,       VKCLOTH_TEXEL_BINDING_PARTICLE,    VKCLOTH_TEXEL_BINDING_VEL,
        VKCLOTH_TEXEL_BINDING_FLAGS,        VKCLOTH_TEXEL_BINDING_INSTANCES,   VKCLOTH_TEXEL_BINDING_OFFSETS,
        VKCLOTH_TEXEL_BINDING_EDGES,        VKCLOTH_TEXEL_BINDING_FAN_OFFSETS, VKCLOTH_TEXEL_BINDING_FANS,
        VKCLOTH_TEXEL_BINDING_STRAIN_LINKS, VKCLOTH_TEXEL_BINDING_TETHERS};
    static_assert(std::size(texel) == VKCLOTH_TEXEL_BINDING_COUNT);
    auto tl =
        create_compute_set_layout(ctx_, texel, VK_DESCRIPTOR_TYPE_UNIFORM_TEXEL_BUFFER, "solver texel views");
    if (!tl)
      return tl.error();
    const VkDescriptorSetLayout sets[2] = {*sl, *tl};
    auto pl = create_pipeline_layout(ctx_, sets, VK_SHADER_STAGE_COMPUTE_BIT, sizeof(shared::PushConstants),
                                     "solver");
    if (!pl)
      return pl.error();
    solver_storage_ = std::move(*sl);
    solver_texel_ = std::move(*tl);
    solver_layout_ = std::move(*pl);
  }
  return SolverLayouts{solver_storage_, solver_texel_, solver_layout_};
}

Result<PipelineRegistry::ImplicitLayouts> PipelineRegistry::implicit_layouts() {
  const std::lock_guard lock(mutex_);
  return implicit_layouts_locked();
}

Result<PipelineRegistry::ImplicitLayouts> PipelineRegistry::implicit_layouts_locked() {
  if (!implicit_layout_) {
    auto sl =
        create_compute_set_layout(ctx_, kImplicitBindings, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, "implicit");
    if (!sl)
      return sl.error();
    const VkDescriptorSetLayout sets[1] = {*sl};
    auto pl = create_pipeline_layout(ctx_, sets, VK_SHADER_STAGE_COMPUTE_BIT, sizeof(shared::PushConstants),
                                     "implicit");
    if (!pl)
      return pl.error();
    implicit_set_ = std::move(*sl);
    implicit_layout_ = std::move(*pl);
  }
  return ImplicitLayouts{implicit_set_, implicit_layout_};
}

Result<VkShaderModule> PipelineRegistry::module_locked(Shader shader) {
  if (auto it = modules_.find(shader); it != modules_.end())
    return it->second.get();
  const ShaderCode c = code_of(shader);
  auto m = create_shader_module(ctx_, c.code, c.name);
  if (!m)
    return m.error();
  return modules_.emplace(shader, std::move(*m)).first->second.get();
}

Result<VkPipeline> PipelineRegistry::pipeline(Shader shader, std::span<const std::uint32_t> constants) {
  const std::lock_guard lock(mutex_);
  std::pair<Shader, std::vector<std::uint32_t>> key{shader, {constants.begin(), constants.end()}};
  if (auto it = pipelines_.find(key); it != pipelines_.end())
    return it->second.get();
  const bool implicit = shader == Shader::implicit || shader == Shader::implicit_reduce;
  VkPipelineLayout layout = VK_NULL_HANDLE;
  if (implicit) {
    auto l = implicit_layouts_locked();
    if (!l)
      return l.error();
    layout = l->layout;
  } else {
    auto l = solver_layouts_locked();
    if (!l)
      return l.error();
    layout = l->layout;
  }
  auto m = module_locked(shader);
  if (!m)
    return m.error();
  std::vector<VkSpecializationMapEntry> entries(constants.size());
  for (std::uint32_t k = 0; k < entries.size(); ++k)
    entries[k] = VkSpecializationMapEntry{k, k * 4, 4};
  const VkSpecializationInfo spec{static_cast<std::uint32_t>(entries.size()), entries.data(),
                                  constants.size_bytes(), constants.data()};
  const char* name = code_of(shader).name;
  VkComputePipelineCreateInfo ci{};
  ci.sType = VK_STRUCTURE_TYPE_COMPUTE_PIPELINE_CREATE_INFO;
  ci.stage = VkPipelineShaderStageCreateInfo{VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO,
                                             nullptr,
                                             0,
                                             VK_SHADER_STAGE_COMPUTE_BIT,
                                             *m,
                                             "main",
                                             constants.empty() ? nullptr : &spec};
  ci.layout = layout;
  Pipeline p;
  VKCLOTH_VK_TRY(
      ctx_.vk.vkCreateComputePipelines(ctx_.device, cache_locked(), 1, &ci, ctx_.vk.allocator, p.init(ctx_)),
      fmt::format("vkCreateComputePipelines ({})", name));
  return pipelines_.emplace(std::move(key), std::move(p)).first->second.get();
}

} // namespace vkcloth::gpu
