// SPDX-License-Identifier: MIT
#include "strain_projection_gpu.hpp"

#include <algorithm>
#include <tuple>

#include <fmt/format.h>

#include "internal/kernel.hpp"
#include "internal/barriers.hpp"
#include "internal/pipelines.hpp"
#include "vkcloth/shaders/strain_project_comp_spv.hpp"

namespace vkcloth::gpu {

namespace sh = shared;

Result<std::unique_ptr<StrainProjectionGpu>>
StrainProjectionGpu::create(const std::shared_ptr<Context::Impl>& ctx, const ClothTopology& topology,
                            std::uint32_t instances, bool allow_map) {
  std::unique_ptr<StrainProjectionGpu> s(new StrainProjectionGpu());
  s->ctx_ = ctx;
  s->count_ = static_cast<std::uint32_t>(topology.size());
  s->links_ = static_cast<std::uint32_t>(topology.strain_links().size());
  s->instances_ = instances;
  s->cg_cap_ = kernel::projection_cg_cap(s->links_);
  // The most loop iterations one phase costs an invocation (strain_project.comp): a pass over the
  // links plus a reduction tree, or a pass over the particles walking their links.
  const auto offsets = topology.strain_incidence_offsets();
  std::uint32_t degree = 0;
  for (std::size_t p = 0; p + 1 < offsets.size(); ++p)
    degree = std::max(degree, offsets[p + 1] - offsets[p]);
  const std::uint32_t W = VKCLOTH_WORKGROUP_SIZE;
  const std::uint64_t link_phase = (s->links_ + W - 1) / W + 8,
                      particle_phase = std::uint64_t((s->count_ + W - 1) / W) * (1 + degree);
  const std::uint64_t phase = std::max(link_phase, particle_phase) + 1; // + the phase loop's own
  if (phase > VKCLOTH_PROJ_LOOP_BUDGET)
    return make_error(
        ErrorCode::unsupported,
        fmt::format("stretch_limit.method projection: {} strain links over {} particles are too many "
                    "for the one workgroup that projects a cloth on Vulkan; use method both",
                    s->links_, s->count_));
  s->phases_per_dispatch_ = static_cast<std::uint32_t>(VKCLOTH_PROJ_LOOP_BUDGET / phase);
  if ((4 + std::uint64_t(instances)) * 4 > 65536) // the arguments' reset is one vkCmdUpdateBuffer
    return make_error(
        ErrorCode::unsupported,
        fmt::format("stretch_limit.method projection: {} instances of one topology in one batch are "
                    "more than the 16 380 it takes; use method both",
                    instances));
  VKCLOTH_TRY(s->create_buffers(offsets.size() + topology.strain_incidence().size(), allow_map));
  VKCLOTH_TRY(s->create_sets());
  return s;
}

std::vector<std::uint32_t> StrainProjectionGpu::incidence_data(const ClothTopology& topology) {
  std::vector<std::uint32_t> out(topology.strain_incidence_offsets().begin(),
                                 topology.strain_incidence_offsets().end());
  out.insert(out.end(), topology.strain_incidence().begin(), topology.strain_incidence().end());
  return out;
}

Result<void> StrainProjectionGpu::create_buffers(std::uint64_t incidence_words, bool allow_map) {
  const VkBufferUsageFlags usage = VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_TRANSFER_DST_BIT;
  const std::tuple<Buffer*, VkDeviceSize, const char*> buffers[] = {
      {&incidence_, incidence_words * 4, "strain projection: each particle's links"},
      {&link_state_, VkDeviceSize(instances_) * links_ * 32, "strain projection: link state"},
      {&gathered_, VkDeviceSize(instances_) * count_ * 16, "strain projection: gathers"},
      {&state_, VkDeviceSize(instances_) * sizeof(sh::ProjState), "strain projection: state"}};
  for (auto [b, bytes, what] : buffers) {
    auto r =
        create_buffer(*ctx_, std::max<VkDeviceSize>(bytes, 16), usage, MemoryUse::device, allow_map, what);
    if (!r)
      return r.error();
    *b = std::move(*r);
  }
  args_reset_.assign(4 + std::size_t(instances_), 0u);
  args_reset_[0] = args_reset_[1] = 1u;
  args_reset_[2] = instances_;
  auto a = create_buffer(*ctx_, args_reset_.size() * 4, usage | VK_BUFFER_USAGE_INDIRECT_BUFFER_BIT,
                         MemoryUse::device, allow_map, "strain projection: indirect arguments");
  if (!a)
    return a.error();
  args_ = std::move(*a);
  return {};
}

namespace {

/// strain_project.comp's one binding table (strain_projection_shared.h) and its one build (shared
/// arrays sized with VKCLOTH_WORKGROUP_SIZE).
constexpr BindingTable kStrainProjectBindings{"strain projection", sh::strain_project_bindings};
constexpr ShaderSource kStrainProject{
    "strain_project.comp", spirv::strain_project_comp_spv, {}, &kStrainProjectBindings, true};

} // namespace

// The Context's layout and pipeline; this batch's pool and two sets (position parity).
Result<void> StrainProjectionGpu::create_sets() {
  auto pass = create_one_set_pass(*ctx_, kStrainProjectBindings, pool_, sets_);
  if (!pass)
    return pass.error();
  layout_ = pass->layout;
  auto pipeline = ctx_->pipelines->pipeline(kStrainProject, {});
  if (!pipeline)
    return pipeline.error();
  pass_ = *pipeline;
  return {};
}

Result<void> StrainProjectionGpu::write_sets(const OneSetInputs& in) {
  VKCLOTH_TRY(write_parity_sets(*ctx_, sets_, sh::strain_project_bindings,
                                [&](std::uint32_t read, std::uint32_t binding) -> VkBuffer {
                                  switch (binding) {
                                  case VKCLOTH_BINDING_PROJ_INCIDENCE:
                                    return incidence_.buffer;
                                  case VKCLOTH_BINDING_PROJ_LINKS:
                                    return link_state_.buffer;
                                  case VKCLOTH_BINDING_PROJ_GATHER:
                                    return gathered_.buffer;
                                  case VKCLOTH_BINDING_PROJ_STATE:
                                    return state_.buffer;
                                  case VKCLOTH_BINDING_PROJ_ARGS:
                                    return args_.buffer;
                                  default:
                                    return in.main_binding(read, binding);
                                  }
                                }));
  return {};
}

std::uint32_t StrainProjectionGpu::record_substep(VkCommandBuffer c, std::uint32_t read,
                                                  const sh::PushConstants& main_pc, std::uint32_t newton) {
  const auto& v = ctx_->vk;
  v.vkCmdBindDescriptorSets(c, VK_PIPELINE_BIND_POINT_COMPUTE, layout_, 0, 1, &sets_[read], 0, nullptr);
  v.vkCmdBindPipeline(c, VK_PIPELINE_BIND_POINT_COMPUTE, pass_);
  auto pc = sh::push_from<sh::ProjectionPush>(main_pc);
  pc.links = links_;
  pc.cg_cap = cg_cap_;
  pc.phase_budget = phases_per_dispatch_;
  // The worst case: every Newton iteration runs LINKS, cg_cap x (GATHER, MATVEC, UPDATE,
  // DIRECTION) and APPLY.
  const std::uint64_t phases = std::uint64_t(newton) * (2 + 4ull * cg_cap_);
  const auto dispatches =
      static_cast<std::uint32_t>((phases + phases_per_dispatch_ - 1) / phases_per_dispatch_);
  barriers::before_host_edit(v, c); // the last substep's dispatches read and wrote the arguments
  v.vkCmdUpdateBuffer(c, args_.buffer, 0, args_reset_.size() * 4, args_reset_.data());
  barriers::host_edit_to_indirect(v, c);
  for (std::uint32_t k = 0; k < dispatches; ++k) {
    pc.stage = k;
    v.vkCmdPushConstants(c, layout_, VK_SHADER_STAGE_COMPUTE_BIT, 0, sizeof(pc), &pc);
    barriers::implicit_pass(v, c); // the tethers (or the last dispatch) -> this one, its arguments too
    v.vkCmdDispatchIndirect(c, args_.buffer, 0);
  }
  return dispatches;
}

} // namespace vkcloth::gpu
