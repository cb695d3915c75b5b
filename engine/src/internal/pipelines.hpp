// SPDX-License-Identifier: MIT
// The compute pipelines of one Context, made once and shared by every batch (GpuSolver,
// ClothWorld) on it: shader modules, descriptor set layouts, pipeline layouts, a VkPipelineCache,
// and the pipelines keyed by (shader, specialisation constants), e.g. force.comp per grid stencil
// x SC_NORMAL_FLAGS, fused.comp per stencil x SC_WRITE_AUX x SC_COLLIDER_TYPES x SC_NORMAL_FLAGS.
// The registry knows no shader: each pass declares its shaders (ShaderSource) and the one binding
// table of their layout (BindingTable), and the registry makes what they name. Lookups happen when
// a batch is created or its parameters change, never per dispatch: passes keep the raw handles,
// which live as long as the Context's internals (each batch holds them). Internal to
// engine/src/vulkan.
#pragma once

#include "internal/resources.hpp"
#include "kernel/layout/vkcloth_shared.h"
#include "vkcloth/gpu/layout.hpp"

#include <map>
#include <mutex>
#include <span>
#include <tuple>
#include <utility>
#include <vector>

namespace vkcloth::gpu {

/// choose_layout() for `ctx`'s device (layout.cpp).
DeviceLayout device_layout(const Context::Impl& ctx);

/// The specialisation constant of the workgroup size (common.glsl local_size_x_id), beyond the
/// solver's constants 0..42 (solver_state_set.cpp).
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

/// A descriptor layout as the pass that owns it declares it, once: set 0's storage buffers and,
/// for shaders with a texel build, set 1's uniform texel buffer views (binding numbers from the
/// pass's shared header). The registry makes one layout per table (keyed by its address: declare
/// tables `inline constexpr` or at namespace scope, never on the stack).
struct BindingTable {
  const char* name;
  std::span<const std::uint32_t> storage;
  std::span<const std::uint32_t> texel = {}; // empty: no set 1
};

/// A compute shader as its pass declares it: its SPIR-V builds (shaders/CMakeLists.txt) and the
/// binding table of its layout. Keyed by address, as BindingTable.
struct ShaderSource {
  const char* name;                       // the source, for messages
  std::span<const std::uint32_t> texel;   // the *_texel build, or the shader's one build
  std::span<const std::uint32_t> storage; // the *_storage build; empty: one build only
  const BindingTable* bindings;           // its layout
  bool fixed_workgroup = false; // sizes shared arrays with VKCLOTH_WORKGROUP_SIZE: never specialised
};

class PipelineRegistry {
public:
  /// A binding table's set layouts (set 1: VK_NULL_HANDLE without texel bindings) and pipeline layout.
  struct Layouts {
    VkDescriptorSetLayout storage = VK_NULL_HANDLE, texel = VK_NULL_HANDLE;
    VkPipelineLayout layout = VK_NULL_HANDLE;
  };

  /// Makes nothing yet (the Context's allocation callbacks may still be unset): every object is
  /// created when first asked for.
  explicit PipelineRegistry(Context::Impl& ctx) : ctx_(ctx) {}
  PipelineRegistry(const PipelineRegistry&) = delete;
  PipelineRegistry& operator=(const PipelineRegistry&) = delete;

  /// The layouts of `table`, made on first request.
  Result<Layouts> layouts(const BindingTable& table);
  using Variant = ShaderVariant;
  /// The pipeline of `shader` specialised with `constants` (ids 0..size-1, 32 bits each; empty:
  /// none), when `variant.workgroup_size` is set constant kWorkgroupSizeConstant, and when
  /// `variant.stage` is set constant VKCLOTH_STAGE_CONSTANT; created on first request, with the
  /// layout of its binding table.
  Result<VkPipeline> pipeline(const ShaderSource& shader, std::span<const std::uint32_t> constants,
                              Variant variant = {});
  /// The Context's pipeline cache (VK_NULL_HANDLE when it could not be made: caching is optional).
  VkPipelineCache cache();
  /// Compute pipelines made so far (testing::pipeline_count).
  std::size_t size() {
    const std::lock_guard lock(mutex_);
    return pipelines_.size();
  }

private:
  struct LayoutObjects {
    DescriptorSetLayout storage, texel;
    PipelineLayout layout;
  };
  Result<Layouts> layouts_locked(const BindingTable& table);
  VkPipelineCache cache_locked();
  Result<VkShaderModule> module_locked(const ShaderSource& shader, BufferAccess access);

  Context::Impl& ctx_;
  std::mutex mutex_; // several solvers may be created on one Context from different threads
  PipelineCache cache_;
  bool cache_tried_ = false;
  std::map<const BindingTable*, LayoutObjects> layouts_;
  std::map<std::pair<const ShaderSource*, BufferAccess>, ShaderModule> modules_;
  std::map<std::tuple<const ShaderSource*, Variant, std::vector<std::uint32_t>>, Pipeline> pipelines_;
};

/// The solver's buffers a one-set pass (self_collision.comp, strain_project.comp) shares with the
/// main layout, at the same binding numbers.
struct OneSetInputs {
  VkBuffer pos[2], vel, particle, flags, instances, strain_links;
  VkBuffer acc_pos, acc_vel,
      stage_vel; // vbd's self-contact force and stiffness (self_collision.comp CONTACT)
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
/// `table`'s layouts from `ctx`'s registry, and `pool` with the two parity sets of its storage set
/// (create_parity_sets), named after the table.
Result<OneSetPass> create_one_set_pass(Context::Impl& ctx, const BindingTable& table, DescriptorPool& pool,
                                       VkDescriptorSet (&sets)[2]);

} // namespace vkcloth::gpu
