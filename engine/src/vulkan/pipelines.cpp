// SPDX-License-Identifier: MIT
#include "internal/pipelines.hpp"

#include <array>
#include <string>
#include <vector>

#include <fmt/format.h>

#include "kernel/layout/vkcloth_shared.h"

namespace vkcloth::gpu {

namespace {

/// Set 0 of `storage` storage buffers and, unless `texel` is empty, set 1 of `texel` uniform texel
/// buffer views (into *texel_set), and their pipeline layout with the push constants; named `name`.
Result<void> create_layouts(Context::Impl& ctx, std::span<const std::uint32_t> storage,
                            std::span<const std::uint32_t> texel, const std::string& name,
                            DescriptorSetLayout& storage_set, DescriptorSetLayout* texel_set,
                            PipelineLayout& layout) {
  auto sl = create_compute_set_layout(ctx, storage, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, name.c_str());
  if (!sl)
    return sl.error();
  std::vector<VkDescriptorSetLayout> sets{*sl};
  DescriptorSetLayout tl;
  if (!texel.empty()) {
    auto t = create_compute_set_layout(ctx, texel, VK_DESCRIPTOR_TYPE_UNIFORM_TEXEL_BUFFER,
                                       (name + " texel views").c_str());
    if (!t)
      return t.error();
    tl = std::move(*t);
    sets.push_back(tl);
  }
  auto pl = create_pipeline_layout(ctx, sets, VK_SHADER_STAGE_COMPUTE_BIT, sizeof(shared::PushConstants),
                                   name.c_str());
  if (!pl)
    return pl.error();
  storage_set = std::move(*sl);
  if (texel_set)
    *texel_set = std::move(tl);
  layout = std::move(*pl);
  return {};
}

} // namespace

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

Result<PipelineRegistry::Layouts> PipelineRegistry::layouts(const BindingTable& table) {
  const std::lock_guard lock(mutex_);
  return layouts_locked(table);
}

Result<PipelineRegistry::Layouts> PipelineRegistry::layouts_locked(const BindingTable& table) {
  auto it = layouts_.find(&table);
  if (it == layouts_.end()) {
    LayoutObjects made;
    VKCLOTH_TRY(create_layouts(ctx_, table.storage, table.texel, table.name, made.storage,
                               table.texel.empty() ? nullptr : &made.texel, made.layout));
    it = layouts_.emplace(&table, std::move(made)).first;
  }
  return Layouts{it->second.storage, it->second.texel, it->second.layout};
}

namespace {

/// The build of `shader` for `access`: *_texel (VKCLOTH_TEXEL_VIEWS) or *_storage; a shader of one
/// build has it in `texel`.
std::span<const std::uint32_t> code_of(const ShaderSource& shader, BufferAccess access) {
  return access == BufferAccess::storage_buffers && !shader.storage.empty() ? shader.storage : shader.texel;
}

std::string build_name(const ShaderSource& shader, BufferAccess access) {
  if (shader.storage.empty())
    return shader.name;
  return fmt::format("{} ({})", shader.name,
                     access == BufferAccess::storage_buffers ? "storage buffers" : "texel views");
}

} // namespace

Result<VkShaderModule> PipelineRegistry::module_locked(const ShaderSource& shader, BufferAccess access) {
  if (auto it = modules_.find({&shader, access}); it != modules_.end())
    return it->second.get();
  auto m = create_shader_module(ctx_, code_of(shader, access), build_name(shader, access).c_str());
  if (!m)
    return m.error();
  return modules_.emplace(std::pair{&shader, access}, std::move(*m)).first->second.get();
}

Result<VkPipeline> PipelineRegistry::pipeline(const ShaderSource& shader,
                                              std::span<const std::uint32_t> constants, Variant variant) {
  if (shader.storage.empty())
    variant.access = BufferAccess::texel_views; // one module, whatever was asked
  if (variant.access == BufferAccess::automatic)
    variant.access = device_layout(ctx_).access;
  if (shader.fixed_workgroup || variant.workgroup_size == VKCLOTH_WORKGROUP_SIZE)
    variant.workgroup_size = 0; // the compiled size (shared arrays sized with it, or the default)
  const std::lock_guard lock(mutex_);
  std::tuple<const ShaderSource*, Variant, std::vector<std::uint32_t>> key{
      &shader, variant, {constants.begin(), constants.end()}};
  if (auto it = pipelines_.find(key); it != pipelines_.end())
    return it->second.get();
  auto l = layouts_locked(*shader.bindings);
  if (!l)
    return l.error();
  const VkPipelineLayout layout = l->layout;
  auto m = module_locked(shader, variant.access);
  if (!m)
    return m.error();
  // Constants 0..size-1, then the workgroup size (kWorkgroupSizeConstant) when it is not the
  // compiled one, then the stage.
  std::vector<std::uint32_t> words(constants.begin(), constants.end());
  std::vector<VkSpecializationMapEntry> entries(constants.size());
  for (std::uint32_t k = 0; k < entries.size(); ++k)
    entries[k] = VkSpecializationMapEntry{k, k * 4, 4};
  if (variant.workgroup_size) {
    static_assert(kWorkgroupSizeConstant >= 43, "after the solver's constants 0..42");
    entries.push_back({kWorkgroupSizeConstant, static_cast<std::uint32_t>(words.size() * 4), 4});
    words.push_back(variant.workgroup_size);
  }
  if (variant.stage != VKCLOTH_ANY_STAGE) {
    static_assert(VKCLOTH_STAGE_CONSTANT > kWorkgroupSizeConstant);
    entries.push_back({VKCLOTH_STAGE_CONSTANT, static_cast<std::uint32_t>(words.size() * 4), 4});
    words.push_back(variant.stage);
  }
  const VkSpecializationInfo spec{static_cast<std::uint32_t>(entries.size()), entries.data(),
                                  words.size() * sizeof(std::uint32_t), words.data()};
  const std::string name = build_name(shader, variant.access);
  VkComputePipelineCreateInfo ci{};
  ci.sType = VK_STRUCTURE_TYPE_COMPUTE_PIPELINE_CREATE_INFO;
  ci.stage = VkPipelineShaderStageCreateInfo{VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO,
                                             nullptr,
                                             0,
                                             VK_SHADER_STAGE_COMPUTE_BIT,
                                             *m,
                                             "main",
                                             entries.empty() ? nullptr : &spec};
  ci.layout = layout;
  Pipeline p;
  VKCLOTH_VK_TRY(
      ctx_.vk.vkCreateComputePipelines(ctx_.device, cache_locked(), 1, &ci, ctx_.vk.allocator, p.init(ctx_)),
      fmt::format("vkCreateComputePipelines ({})", name));
  return pipelines_.emplace(std::move(key), std::move(p)).first->second.get();
}

VkBuffer OneSetInputs::main_binding(std::uint32_t read, std::uint32_t binding) const {
  switch (binding) {
  case VKCLOTH_BINDING_POS_IN:
    return pos[read]; // the positions at the substep's start
  case VKCLOTH_BINDING_POS_OUT:
    return pos[read ^ 1u]; // the positions this substep writes
  case VKCLOTH_BINDING_VEL:
    return vel;
  case VKCLOTH_BINDING_PARTICLE:
    return particle;
  case VKCLOTH_BINDING_FLAGS:
    return flags;
  case VKCLOTH_BINDING_INSTANCES:
    return instances;
  case VKCLOTH_BINDING_STRAIN_LINKS:
    return strain_links;
  case VKCLOTH_BINDING_ACC_POS:
    return acc_pos;
  case VKCLOTH_BINDING_ACC_VEL:
    return acc_vel;
  case VKCLOTH_BINDING_STAGE_VEL:
    return stage_vel;
  default:
    return VK_NULL_HANDLE;
  }
}

Result<OneSetPass> create_one_set_pass(Context::Impl& ctx, const BindingTable& table, DescriptorPool& pool,
                                       VkDescriptorSet (&sets)[2]) {
  auto layouts = ctx.pipelines->layouts(table);
  if (!layouts)
    return layouts.error();
  VKCLOTH_TRY(create_parity_sets(ctx, layouts->storage, static_cast<std::uint32_t>(table.storage.size()),
                                 pool, sets, table.name));
  return OneSetPass{layouts->layout, layouts->texel};
}

} // namespace vkcloth::gpu
