// SPDX-License-Identifier: MIT
#include "pipelines.hpp"

#include <array>
#include <string>
#include <vector>

#include <fmt/format.h>

#include "implicit_shared.h"
#include "self_collision_shared.h"
#include "strain_projection_shared.h"
#include "vkcloth/shaders/force_storage_comp_spv.hpp"
#include "vkcloth/shaders/force_texel_comp_spv.hpp"
#include "vkcloth/shaders/fused_storage_comp_spv.hpp"
#include "vkcloth/shaders/fused_texel_comp_spv.hpp"
#include "vkcloth/shaders/implicit_comp_spv.hpp"
#include "vkcloth/shaders/self_collision_storage_comp_spv.hpp"
#include "vkcloth/shaders/self_collision_texel_comp_spv.hpp"
#include "vkcloth/shaders/integrate_storage_comp_spv.hpp"
#include "vkcloth/shaders/integrate_texel_comp_spv.hpp"
#include "vkcloth/shaders/strain_finish_storage_comp_spv.hpp"
#include "vkcloth/shaders/strain_finish_texel_comp_spv.hpp"
#include "vkcloth/shaders/strain_links_storage_comp_spv.hpp"
#include "vkcloth/shaders/strain_links_texel_comp_spv.hpp"
#include "vkcloth/shaders/strain_project_comp_spv.hpp"
#include "vkcloth/shaders/vertices_comp_spv.hpp"
#include "vkcloth_shared.h"

namespace vkcloth::gpu {

namespace {

struct ShaderCode {
  std::span<const std::uint32_t> code;
  const char* name;
};

/// The build of `s` for `access` (shaders/CMakeLists.txt: *_texel with VKCLOTH_TEXEL_VIEWS,
/// *_storage without; shaders with one build ignore `access`).
ShaderCode code_of(PipelineRegistry::Shader s, BufferAccess access) {
  using S = PipelineRegistry::Shader;
  const bool texel = access != BufferAccess::storage_buffers;
  switch (s) {
  case S::force:
    return texel ? ShaderCode{spirv::force_texel_comp_spv, "force.comp (texel views)"}
                 : ShaderCode{spirv::force_storage_comp_spv, "force.comp (storage buffers)"};
  case S::integrate:
    return texel ? ShaderCode{spirv::integrate_texel_comp_spv, "integrate.comp (texel views)"}
                 : ShaderCode{spirv::integrate_storage_comp_spv, "integrate.comp (storage buffers)"};
  case S::fused:
    return texel ? ShaderCode{spirv::fused_texel_comp_spv, "fused.comp (texel views)"}
                 : ShaderCode{spirv::fused_storage_comp_spv, "fused.comp (storage buffers)"};
  case S::implicit:
    return {spirv::implicit_comp_spv, "implicit.comp"};
  case S::strain_links:
    return texel ? ShaderCode{spirv::strain_links_texel_comp_spv, "strain_links.comp (texel views)"}
                 : ShaderCode{spirv::strain_links_storage_comp_spv, "strain_links.comp (storage buffers)"};
  case S::strain_finish:
    return texel ? ShaderCode{spirv::strain_finish_texel_comp_spv, "strain_finish.comp (texel views)"}
                 : ShaderCode{spirv::strain_finish_storage_comp_spv, "strain_finish.comp (storage buffers)"};
  case S::vertices:
    return {spirv::vertices_comp_spv, "vertices.comp"};
  case S::self_collision:
    return texel
               ? ShaderCode{spirv::self_collision_texel_comp_spv, "self_collision.comp (texel views)"}
               : ShaderCode{spirv::self_collision_storage_comp_spv, "self_collision.comp (storage buffers)"};
  case S::strain_project:
    return {spirv::strain_project_comp_spv, "strain_project.comp"};
  }
  return {{}, "?"};
}

/// Shaders compiled in one build only.
bool single_build(PipelineRegistry::Shader s) {
  using S = PipelineRegistry::Shader;
  return s == S::implicit || s == S::vertices || s == S::strain_project;
}

/// The storage bindings of implicit.comp (implicit_shared.h).
constexpr std::uint32_t kImplicitBindings[] = {VKCLOTH_BINDING_POS_IN,     VKCLOTH_BINDING_FORCE_OUT,
                                               VKCLOTH_BINDING_NORMAL,     VKCLOTH_BINDING_POS_OUT,
                                               VKCLOTH_BINDING_VEL,        VKCLOTH_BINDING_PARTICLE,
                                               VKCLOTH_BINDING_OFFSETS,    VKCLOTH_BINDING_EDGES,
                                               VKCLOTH_BINDING_COLLIDERS,  VKCLOTH_BINDING_FLAGS,
                                               VKCLOTH_BINDING_INSTANCES,  VKCLOTH_BINDING_IMPL_VF,
                                               VKCLOTH_BINDING_IMPL_KS,    VKCLOTH_BINDING_IMPL_BLOCK_INV,
                                               VKCLOTH_BINDING_IMPL_X,     VKCLOTH_BINDING_IMPL_R,
                                               VKCLOTH_BINDING_IMPL_Z,     VKCLOTH_BINDING_IMPL_D,
                                               VKCLOTH_BINDING_IMPL_Q,     VKCLOTH_BINDING_IMPL_PARTIALS,
                                               VKCLOTH_BINDING_IMPL_STATE, VKCLOTH_BINDING_IMPL_ARGS,
                                               VKCLOTH_BINDING_MESH_NODES, VKCLOTH_BINDING_MESH_TRIS};

/// The storage bindings of self_collision.comp (self_collision_shared.h).
constexpr std::uint32_t kSelfCollisionBindings[] = {
    VKCLOTH_BINDING_POS_OUT,     VKCLOTH_BINDING_VEL,         VKCLOTH_BINDING_PARTICLE,
    VKCLOTH_BINDING_FLAGS,       VKCLOTH_BINDING_INSTANCES,   VKCLOTH_BINDING_SELF_PARAMS,
    VKCLOTH_BINDING_SELF_REST,   VKCLOTH_BINDING_SELF_COUNTS, VKCLOTH_BINDING_SELF_STARTS,
    VKCLOTH_BINDING_SELF_BLOCKS, VKCLOTH_BINDING_SELF_KEYS,   VKCLOTH_BINDING_SELF_SORTED,
    VKCLOTH_BINDING_SELF_DELTA};

/// Set 1 of self_collision.comp's texel build: uniform texel buffer views (self_collision_shared.h).
constexpr std::uint32_t kSelfCollisionTexelBindings[] = {VKCLOTH_SELF_TEXEL_POS, VKCLOTH_SELF_TEXEL_VEL,
                                                         VKCLOTH_SELF_TEXEL_REST, VKCLOTH_SELF_TEXEL_STARTS,
                                                         VKCLOTH_SELF_TEXEL_SORTED};
static_assert(std::size(kSelfCollisionTexelBindings) == VKCLOTH_SELF_TEXEL_COUNT);

/// The storage bindings of strain_project.comp (strain_projection_shared.h).
constexpr std::uint32_t kStrainProjectBindings[] = {
    VKCLOTH_BINDING_POS_OUT,        VKCLOTH_BINDING_VEL,        VKCLOTH_BINDING_PARTICLE,
    VKCLOTH_BINDING_FLAGS,          VKCLOTH_BINDING_INSTANCES,  VKCLOTH_BINDING_STRAIN_LINKS,
    VKCLOTH_BINDING_PROJ_INCIDENCE, VKCLOTH_BINDING_PROJ_LINKS, VKCLOTH_BINDING_PROJ_GATHER,
    VKCLOTH_BINDING_PROJ_STATE,     VKCLOTH_BINDING_PROJ_ARGS};

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

std::span<const std::uint32_t> implicit_bindings() {
  return kImplicitBindings;
}

std::span<const std::uint32_t> self_collision_bindings() {
  return kSelfCollisionBindings;
}

std::span<const std::uint32_t> strain_project_bindings() {
  return kStrainProjectBindings;
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
    const std::uint32_t texel[] = {
        VKCLOTH_TEXEL_BINDING_POS_IN,    VKCLOTH_TEXEL_BINDING_PARTICLE,     VKCLOTH_TEXEL_BINDING_VEL,
        VKCLOTH_TEXEL_BINDING_FLAGS,     VKCLOTH_TEXEL_BINDING_INSTANCES,    VKCLOTH_TEXEL_BINDING_RANGES,
        VKCLOTH_TEXEL_BINDING_EDGES,     VKCLOTH_TEXEL_BINDING_STRAIN_LINKS, VKCLOTH_TEXEL_BINDING_TETHERS,
        VKCLOTH_TEXEL_BINDING_COLLIDERS, VKCLOTH_TEXEL_BINDING_MESH_NODES,   VKCLOTH_TEXEL_BINDING_MESH_TRIS};
    static_assert(std::size(texel) == VKCLOTH_TEXEL_BINDING_COUNT);
    VKCLOTH_TRY(
        create_layouts(ctx_, storage, texel, "solver", solver_storage_, &solver_texel_, solver_layout_));
  }
  return SolverLayouts{solver_storage_, solver_texel_, solver_layout_};
}

Result<PipelineRegistry::PassLayouts> PipelineRegistry::implicit_layouts() {
  const std::lock_guard lock(mutex_);
  return single_set_layouts_locked(kImplicitBindings, "implicit", implicit_set_, implicit_layout_);
}

Result<PipelineRegistry::PassLayouts> PipelineRegistry::self_collision_layouts() {
  const std::lock_guard lock(mutex_);
  return self_collision_layouts_locked();
}

// Set 0: the storage buffers; set 1: the texel build's views (the storage build uses set 0 only).
Result<PipelineRegistry::PassLayouts> PipelineRegistry::self_collision_layouts_locked() {
  if (!self_layout_)
    VKCLOTH_TRY(create_layouts(ctx_, kSelfCollisionBindings, kSelfCollisionTexelBindings, "self-collision",
                               self_set_, &self_texel_set_, self_layout_));
  return PassLayouts{self_set_, self_layout_, self_texel_set_};
}

Result<PipelineRegistry::PassLayouts> PipelineRegistry::strain_project_layouts() {
  const std::lock_guard lock(mutex_);
  return single_set_layouts_locked(kStrainProjectBindings, "strain projection", project_set_,
                                   project_layout_);
}

Result<PipelineRegistry::PassLayouts>
PipelineRegistry::single_set_layouts_locked(std::span<const std::uint32_t> bindings, const char* name,
                                            DescriptorSetLayout& set, PipelineLayout& layout) {
  if (!layout)
    VKCLOTH_TRY(create_layouts(ctx_, bindings, {}, name, set, nullptr, layout));
  return PassLayouts{set, layout};
}

Result<VkShaderModule> PipelineRegistry::module_locked(Shader shader, BufferAccess access) {
  if (auto it = modules_.find({shader, access}); it != modules_.end())
    return it->second.get();
  const ShaderCode c = code_of(shader, access);
  auto m = create_shader_module(ctx_, c.code, c.name);
  if (!m)
    return m.error();
  return modules_.emplace(std::pair{shader, access}, std::move(*m)).first->second.get();
}

Result<VkPipeline> PipelineRegistry::pipeline(Shader shader, std::span<const std::uint32_t> constants,
                                              Variant variant) {
  const bool implicit = shader == Shader::implicit, self = shader == Shader::self_collision,
             project = shader == Shader::strain_project;
  if (single_build(shader))
    variant.access = BufferAccess::texel_views; // one module, whatever was asked
  if (variant.access == BufferAccess::automatic)
    variant.access = device_layout(ctx_).access;
  if (implicit || self || project || variant.workgroup_size == VKCLOTH_WORKGROUP_SIZE)
    variant.workgroup_size = 0; // implicit, self_collision, strain_project.comp size shared arrays with it
  const std::lock_guard lock(mutex_);
  std::tuple<Shader, Variant, std::vector<std::uint32_t>> key{
      shader, variant, {constants.begin(), constants.end()}};
  if (auto it = pipelines_.find(key); it != pipelines_.end())
    return it->second.get();
  VkPipelineLayout layout = VK_NULL_HANDLE;
  if (implicit || self || project) {
    auto l = implicit
                 ? single_set_layouts_locked(kImplicitBindings, "implicit", implicit_set_, implicit_layout_)
             : self ? self_collision_layouts_locked()
                    : single_set_layouts_locked(kStrainProjectBindings, "strain projection", project_set_,
                                                project_layout_);
    if (!l)
      return l.error();
    layout = l->layout;
  } else {
    auto l = solver_layouts_locked();
    if (!l)
      return l.error();
    layout = l->layout;
  }
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
  const char* name = code_of(shader, variant.access).name;
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
  default:
    return VK_NULL_HANDLE;
  }
}

Result<OneSetPass> create_one_set_pass(Context::Impl& ctx, PipelineRegistry::Shader shader,
                                       DescriptorPool& pool, VkDescriptorSet (&sets)[2], const char* name) {
  const bool self = shader == PipelineRegistry::Shader::self_collision;
  auto layouts = self ? ctx.pipelines->self_collision_layouts() : ctx.pipelines->strain_project_layouts();
  if (!layouts)
    return layouts.error();
  const std::size_t bindings = self ? self_collision_bindings().size() : strain_project_bindings().size();
  VKCLOTH_TRY(create_parity_sets(ctx, layouts->set, static_cast<std::uint32_t>(bindings), pool, sets, name));
  return OneSetPass{layouts->layout, layouts->texel};
}

} // namespace vkcloth::gpu
