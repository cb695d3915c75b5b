// SPDX-License-Identifier: MIT
// The compute pipelines of one Context, made once and shared by every batch (GpuSolver,
// ClothWorld) on it: shader modules, descriptor set layouts, pipeline layouts, a VkPipelineCache,
// and the pipelines keyed by (shader, specialisation constants), e.g. force.comp per grid stencil
// x SC_NORMAL_FLAGS, fused.comp per stencil x SC_WRITE_AUX x SC_COLLIDER_TYPES x SC_NORMAL_FLAGS. Lookups
// happen when a batch is created or its parameters change, never per dispatch: batches keep the raw handles,
// which live as long as the Context's internals (each batch holds them). Internal to
// engine/src/vulkan.
#pragma once

#include "resources.hpp"
#include "vkcloth_shared.h"
#include "vkcloth/gpu/layout.hpp"

#include <map>
#include <mutex>
#include <span>
#include <tuple>
#include <utility>
#include <vector>

namespace vkcloth::gpu {

/// The storage bindings of implicit.comp, in descriptor-write order.
std::span<const std::uint32_t> implicit_bindings();
/// The storage bindings of self_collision.comp, in descriptor-write order.
std::span<const std::uint32_t> self_collision_bindings();
/// The storage bindings of strain_project.comp, in descriptor-write order.
std::span<const std::uint32_t> strain_project_bindings();

/// choose_layout() for `ctx`'s device (layout.cpp).
DeviceLayout device_layout(const Context::Impl& ctx);

/// The specialisation constant of the workgroup size (common.glsl local_size_x_id), beyond the
/// solver's constants 0..42 (solver_pipelines.cpp).
inline constexpr std::uint32_t kWorkgroupSizeConstant = 43;

/// Which build of a shader, its workgroup size (DeviceLayout) and the pass it runs. force,
/// integrate, fused and strain_*, self_collision have a *_texel and a *_storage build; the others
/// one build, `access` ignored. `workgroup_size` 0: the compiled VKCLOTH_WORKGROUP_SIZE
/// (implicit*.comp: always). `stage` (constant VKCLOTH_STAGE_CONSTANT, common.glsl SC_STAGE): the
/// one pass of a multi-pass shader this pipeline runs, or VKCLOTH_ANY_STAGE (the push constant's).
struct ShaderVariant {
  BufferAccess access = BufferAccess::texel_views;
  std::uint32_t workgroup_size = 0;
  std::uint32_t stage = VKCLOTH_ANY_STAGE;
  auto operator<=>(const ShaderVariant&) const = default;
};

class PipelineRegistry {
public:
  enum class Shader {
    force,
    integrate,
    fused,
    implicit,
    strain_links,
    strain_finish,
    vertices,
    self_collision,
    strain_project
  };

  /// Set 0 (storage buffers) and set 1 (texel views) of force/integrate/fused.comp and their
  /// layout (strain_links/strain_finish/vertices.comp use it too, set 0 only).
  struct SolverLayouts {
    VkDescriptorSetLayout storage = VK_NULL_HANDLE, texel = VK_NULL_HANDLE;
    VkPipelineLayout layout = VK_NULL_HANDLE;
  };
  /// The layouts of a pass with its own storage set (implicit.comp, self_collision.comp,
  /// strain_project.comp): that set and the pipeline layout; self_collision.comp's texel build also
  /// reads set 1, `texel` (the others: none).
  struct PassLayouts {
    VkDescriptorSetLayout set = VK_NULL_HANDLE;
    VkPipelineLayout layout = VK_NULL_HANDLE;
    VkDescriptorSetLayout texel = VK_NULL_HANDLE;
  };

  /// Makes nothing yet (the Context's allocation callbacks may still be unset): every object is
  /// created when first asked for.
  explicit PipelineRegistry(Context::Impl& ctx) : ctx_(ctx) {}
  PipelineRegistry(const PipelineRegistry&) = delete;
  PipelineRegistry& operator=(const PipelineRegistry&) = delete;

  Result<SolverLayouts> solver_layouts();
  Result<PassLayouts> implicit_layouts();
  Result<PassLayouts> self_collision_layouts();
  Result<PassLayouts> strain_project_layouts();
  using Variant = ShaderVariant;
  /// The pipeline of `shader` specialised with `constants` (ids 0..size-1, 32 bits each; empty:
  /// none), when `variant.workgroup_size` is set constant kWorkgroupSizeConstant, and when
  /// `variant.stage` is set constant VKCLOTH_STAGE_CONSTANT; created on
  /// first request; its layout is solver_layouts(), implicit_layouts(), self_collision_layouts() or
  /// strain_project_layouts().
  Result<VkPipeline> pipeline(Shader shader, std::span<const std::uint32_t> constants, Variant variant = {});
  /// The Context's pipeline cache (VK_NULL_HANDLE when it could not be made: caching is optional).
  VkPipelineCache cache();
  /// Compute pipelines made so far (testing::pipeline_count).
  std::size_t size() {
    const std::lock_guard lock(mutex_);
    return pipelines_.size();
  }

private:
  Result<SolverLayouts> solver_layouts_locked();
  /// The layouts of a shader with one set of storage buffers (implicit.comp, self_collision.comp).
  Result<PassLayouts> single_set_layouts_locked(std::span<const std::uint32_t> bindings, const char* name,
                                                DescriptorSetLayout& set, PipelineLayout& layout);
  Result<PassLayouts> self_collision_layouts_locked();
  VkPipelineCache cache_locked();
  Result<VkShaderModule> module_locked(Shader shader, BufferAccess access);

  Context::Impl& ctx_;
  std::mutex mutex_; // several solvers may be created on one Context from different threads
  PipelineCache cache_;
  bool cache_tried_ = false;
  DescriptorSetLayout solver_storage_, solver_texel_, implicit_set_, self_set_, self_texel_set_, project_set_;
  PipelineLayout solver_layout_, implicit_layout_, self_layout_, project_layout_;
  std::map<std::pair<Shader, BufferAccess>, ShaderModule> modules_;
  std::map<std::tuple<Shader, Variant, std::vector<std::uint32_t>>, Pipeline> pipelines_;
};

/// The solver's buffers a one-set pass (self_collision.comp, strain_project.comp) shares with the
/// main layout, at the same binding numbers.
struct OneSetInputs {
  VkBuffer pos[2], vel, particle, flags, instances, strain_links;
  /// The buffer of main-layout `binding` in the set of position parity `read` (POS_OUT: the
  /// positions that substep writes); VK_NULL_HANDLE for a binding of the pass's own.
  VkBuffer main_binding(std::uint32_t read, std::uint32_t binding) const;
};

/// A pass with one set of storage buffers and its own layout (self_collision.comp,
/// strain_project.comp): the Context's pipeline layout, and the layout of the texel build's set 1
/// (self_collision.comp; VK_NULL_HANDLE for the others). Its pipelines: PipelineRegistry::pipeline.
struct OneSetPass {
  VkPipelineLayout layout = VK_NULL_HANDLE;
  VkDescriptorSetLayout texel_set = VK_NULL_HANDLE;
};
/// `shader`'s (self_collision or strain_project) layouts from `ctx`'s registry, and `pool` with
/// the two parity sets of its layout (create_parity_sets), named `name`.
Result<OneSetPass> create_one_set_pass(Context::Impl& ctx, PipelineRegistry::Shader shader,
                                       DescriptorPool& pool, VkDescriptorSet (&sets)[2], const char* name);

} // namespace vkcloth::gpu
