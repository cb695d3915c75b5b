// SPDX-License-Identifier: MIT
#include "self_collision_gpu.hpp"

#include <algorithm>
#include <array>
#include <utility>
#include <tuple>

#include "internal/kernel.hpp"
#include "internal/self_collision.hpp"
#include "internal/barriers.hpp"
#include "internal/pipelines.hpp"
#include "vkcloth/shaders/self_collision_storage_comp_spv.hpp"
#include "vkcloth/shaders/self_collision_texel_comp_spv.hpp"

namespace vkcloth::gpu {

namespace sh = shared;

Result<std::unique_ptr<SelfCollisionGpu>> SelfCollisionGpu::create(const std::shared_ptr<Context::Impl>& ctx,
                                                                   std::uint32_t count,
                                                                   std::uint32_t instances,
                                                                   std::uint32_t groups_max_x, bool allow_map,
                                                                   BufferAccess access) {
  std::unique_ptr<SelfCollisionGpu> s(new SelfCollisionGpu());
  s->ctx_ = ctx;
  s->count_ = count;
  s->instances_ = instances;
  s->table_ = kernel::self_table_size(count);
  s->groups_max_x_ = std::max<std::uint32_t>(groups_max_x, 1);
  // The largest view is the bucket starts' (table + 1 per instance); a batch past the limit runs
  // the storage build, which reads the same values (a speed choice: the same bits either way).
  const std::uint64_t texels = std::uint64_t(instances) * (std::uint64_t(s->table_) + 1);
  if (access == BufferAccess::texel_views && texels <= ctx->properties.limits.maxTexelBufferElements)
    s->access_ = BufferAccess::texel_views;
  VKCLOTH_TRY(s->create_buffers(allow_map));
  VKCLOTH_TRY(s->create_sets());
  return s;
}

Result<void> SelfCollisionGpu::create_buffers(bool allow_map) {
  Context::Impl& ctx = *ctx_;
  // UNIFORM_TEXEL_BUFFER: the texel build views rest positions, starts and the sorted table.
  const VkBufferUsageFlags usage = VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_TRANSFER_DST_BIT |
                                   VK_BUFFER_USAGE_UNIFORM_TEXEL_BUFFER_BIT;
  const VkDeviceSize per_particle = VkDeviceSize(instances_) * count_;
  const VkDeviceSize buckets = VkDeviceSize(instances_) * table_;
  const std::tuple<Buffer*, VkDeviceSize, const char*> device_buffers[] = {
      {&rest_, VkDeviceSize(count_) * 16, "self-collision: rest positions"},
      {&counts_, buckets * 4, "self-collision: bucket counts"},
      {&starts_, (buckets + instances_) * 4, "self-collision: bucket starts"},
      {&blocks_, buckets / VKCLOTH_SELF_SCAN_BLOCK * 4, "self-collision: scan blocks"},
      {&keys_, per_particle * 4, "self-collision: cell keys"},
      {&sorted_, per_particle * 8, "self-collision: sorted particles"},
      {&delta_, per_particle * 32, "self-collision: moves and velocity changes"},
      {&built_, per_particle * 16, "self-collision: positions at the lists' build"},
      {&listed_, per_particle * 4, "self-collision: list lengths"},
      {&list_, per_particle * 4 * VKCLOTH_SELF_LIST_CAPACITY, "self-collision: neighbour lists"},
      {&stale_, VkDeviceSize(instances_) * 8, "self-collision: lists stale"}};
  for (auto [b, bytes, what] : device_buffers) {
    auto r = create_buffer(ctx, std::max<VkDeviceSize>(bytes, 16), usage, MemoryUse::device, allow_map, what);
    if (!r)
      return r.error();
    *b = std::move(*r);
  }
  auto p = create_buffer(ctx, VkDeviceSize(instances_) * sizeof(sh::SelfParams), usage,
                         MemoryUse::host_upload, true, "self-collision: parameters");
  if (!p)
    return p.error();
  params_ = std::move(*p);
  return {};
}

namespace {

/// self_collision.comp's one binding table (self_collision_shared.h) and its two builds (its
/// scan's shared arrays are sized with VKCLOTH_WORKGROUP_SIZE).
constexpr BindingTable kSelfCollisionBindings{"self-collision", sh::self_collision_bindings,
                                              sh::self_collision_texel_bindings};
constexpr ShaderSource kSelfCollision{"self_collision.comp", spirv::self_collision_texel_comp_spv,
                                      spirv::self_collision_storage_comp_spv, &kSelfCollisionBindings, true};

} // namespace

// The Context's layout and pipelines (one per pass: ShaderVariant::stage); this batch's pool and two
// sets (position parity), and for the texel build a pool and two sets of views.
Result<void> SelfCollisionGpu::create_sets() {
  auto pass = create_one_set_pass(*ctx_, kSelfCollisionBindings, pool_, sets_);
  if (!pass)
    return pass.error();
  layout_ = pass->layout;
  for (std::uint32_t stage = 0; stage < kPasses; ++stage) {
    auto p = ctx_->pipelines->pipeline(kSelfCollision, {}, {access_, 0, stage});
    if (!p)
      return p.error();
    passes_[stage] = *p;
  }
  if (access_ == BufferAccess::texel_views)
    VKCLOTH_TRY(create_parity_sets(*ctx_, pass->texel_set, VKCLOTH_SELF_TEXEL_COUNT, texel_pool_, texel_sets_,
                                   "self-collision texel views", VK_DESCRIPTOR_TYPE_UNIFORM_TEXEL_BUFFER));
  return {};
}

// Set 1 of parity `read`: positions[read ^ 1] (the positions that substep writes) and the views
// every parity shares. Made once: the buffers they view live as long as the batch (the ones a
// batch replaces, colliders and tethers, are not read here).
Result<void> SelfCollisionGpu::write_texel_sets(const OneSetInputs& in) {
  if (sorted_view_ != VK_NULL_HANDLE)
    return {};
  const TexelViewSpec views[] = {
      {in.pos[0], VK_FORMAT_R32G32B32A32_SFLOAT, &pos_views_[0], "self-collision: positions[0]"},
      {in.pos[1], VK_FORMAT_R32G32B32A32_SFLOAT, &pos_views_[1], "self-collision: positions[1]"},
      {in.vel, VK_FORMAT_R32G32B32A32_SFLOAT, &vel_view_, "self-collision: velocities"},
      {rest_.buffer, VK_FORMAT_R32G32B32A32_SFLOAT, &rest_view_, "self-collision: rest positions"},
      {starts_.buffer, VK_FORMAT_R32_UINT, &starts_view_, "self-collision: bucket starts"},
      {sorted_.buffer, VK_FORMAT_R32G32_UINT, &sorted_view_, "self-collision: sorted particles"}};
  VKCLOTH_TRY(create_texel_views(*ctx_, views));
  std::array<VkWriteDescriptorSet, 2 * VKCLOTH_SELF_TEXEL_COUNT> writes{};
  std::size_t w = 0;
  for (std::uint32_t read = 0; read < 2; ++read) {
    const std::pair<const BufferView*, std::uint32_t> bound[VKCLOTH_SELF_TEXEL_COUNT] = {
        {&pos_views_[read ^ 1u], VKCLOTH_SELF_TEXEL_POS},
        {&vel_view_, VKCLOTH_SELF_TEXEL_VEL},
        {&rest_view_, VKCLOTH_SELF_TEXEL_REST},
        {&starts_view_, VKCLOTH_SELF_TEXEL_STARTS},
        {&sorted_view_, VKCLOTH_SELF_TEXEL_SORTED}};
    for (auto [view, binding] : bound)
      writes[w++] = texel_write(texel_sets_[read], binding, *view);
  }
  ctx_->vk.vkUpdateDescriptorSets(ctx_->device, static_cast<std::uint32_t>(w), writes.data(), 0, nullptr);
  return {};
}

Result<void> SelfCollisionGpu::write_sets(const OneSetInputs& in) {
  VKCLOTH_TRY(write_parity_sets(*ctx_, sets_, sh::self_collision_bindings,
                                [&](std::uint32_t read, std::uint32_t binding) -> VkBuffer {
                                  switch (binding) {
                                  case VKCLOTH_BINDING_SELF_PARAMS:
                                    return params_.buffer;
                                  case VKCLOTH_BINDING_SELF_REST:
                                    return rest_.buffer;
                                  case VKCLOTH_BINDING_SELF_COUNTS:
                                    return counts_.buffer;
                                  case VKCLOTH_BINDING_SELF_STARTS:
                                    return starts_.buffer;
                                  case VKCLOTH_BINDING_SELF_BLOCKS:
                                    return blocks_.buffer;
                                  case VKCLOTH_BINDING_SELF_KEYS:
                                    return keys_.buffer;
                                  case VKCLOTH_BINDING_SELF_SORTED:
                                    return sorted_.buffer;
                                  case VKCLOTH_BINDING_SELF_DELTA:
                                    return delta_.buffer;
                                  case VKCLOTH_BINDING_SELF_BUILT:
                                    return built_.buffer;
                                  case VKCLOTH_BINDING_SELF_LISTED:
                                    return listed_.buffer;
                                  case VKCLOTH_BINDING_SELF_LIST:
                                    return list_.buffer;
                                  case VKCLOTH_BINDING_SELF_STALE:
                                    return stale_.buffer;
                                  default:
                                    return in.main_binding(read, binding);
                                  }
                                }));
  return access_ == BufferAccess::texel_views ? write_texel_sets(in) : Result<void>{};
}

std::vector<sh::SelfParams> SelfCollisionGpu::packed(std::span<const SimParams* const> params) {
  std::vector<sh::SelfParams> out;
  for (const SimParams* p : params) {
    const SelfCollision& sc = p->self_collision;
    const auto k = vkcloth::detail::self_constants<float>(sc); // as CpuSolver<float>::self_collide
    const float energy = vkcloth::detail::self_contact_energy<float>(*p) ? k.stiffness : 0.0f; // vbd's sweeps
    out.push_back({sc.enabled ? sc.iterations : 0u, k.thickness, k.inv_cell, k.friction, k.reach2,
                   k.half_skin2, energy, 0u});
  }
  return out;
}

void SelfCollisionGpu::bind(VkCommandBuffer c, std::uint32_t read) const {
  const VkDescriptorSet bound[2] = {sets_[read], texel_sets_[read]};
  ctx_->vk.vkCmdBindDescriptorSets(c, VK_PIPELINE_BIND_POINT_COMPUTE, layout_, 0,
                                   access_ == BufferAccess::texel_views ? 2 : 1, bound, 0, nullptr);
}

// `items` invocations of `pc.stage` (64 per workgroup, rows of at most groups_max_x_ workgroups),
// every instance.
void SelfCollisionGpu::dispatch(VkCommandBuffer c, const sh::SelfPush& pc, std::uint64_t items) const {
  const auto& v = ctx_->vk;
  barriers::dispatch_to_dispatch(v, c); // the previous pass (or the substep's update) -> this one
  v.vkCmdBindPipeline(c, VK_PIPELINE_BIND_POINT_COMPUTE, passes_[pc.stage]);
  v.vkCmdPushConstants(c, layout_, VK_SHADER_STAGE_COMPUTE_BIT, 0, sizeof(pc), &pc);
  const std::uint64_t groups =
      std::max<std::uint64_t>((items + VKCLOTH_WORKGROUP_SIZE - 1) / VKCLOTH_WORKGROUP_SIZE, 1);
  const std::uint64_t gx = std::min<std::uint64_t>(groups, groups_max_x_);
  v.vkCmdDispatch(c, std::uint32_t(gx), std::uint32_t((groups + gx - 1) / gx), instances_);
}

// The hash (COUNT .. SORT), with CHECK before it and LIST after it when `lists`.
std::uint32_t SelfCollisionGpu::record_build(VkCommandBuffer c, sh::SelfPush& pc, bool lists) const {
  std::uint32_t dispatches = 0;
  auto pass = [&](std::uint32_t stage, std::uint64_t items) {
    pc.stage = stage;
    dispatch(c, pc, items);
    ++dispatches;
  };
  if (lists)
    pass(VKCLOTH_SELF_CHECK, count_);
  pass(VKCLOTH_SELF_COUNT, count_);
  pass(VKCLOTH_SELF_SCAN_BLOCKS, std::uint64_t(table_ / VKCLOTH_SELF_SCAN_BLOCK) * VKCLOTH_WORKGROUP_SIZE);
  pass(VKCLOTH_SELF_SCAN_TOP, 1);
  pass(VKCLOTH_SELF_SCAN_ADD, std::uint64_t(table_) + 1);
  pass(VKCLOTH_SELF_SCATTER, count_);
  pass(VKCLOTH_SELF_SORT, table_);
  if (lists)
    pass(VKCLOTH_SELF_LIST, count_);
  return dispatches;
}

std::uint32_t SelfCollisionGpu::record_substep(VkCommandBuffer c, std::uint32_t read,
                                               const sh::PushConstants& main_pc, std::uint32_t iterations) {
  bind(c, read);
  auto pc = sh::push_from<sh::SelfPush>(main_pc);
  pc.table_size = table_;
  pc.in_sweeps = 0;
  std::uint32_t dispatches = 0;
  for (std::uint32_t it = 0; it < iterations; ++it) {
    pc.iteration = it;
    if (it == 0 || lists_) // the hash (and the lists): each pass's stages decide whether to build
      dispatches += record_build(c, pc, lists_);
    for (std::uint32_t stage : {VKCLOTH_SELF_COLLIDE, VKCLOTH_SELF_APPLY}) {
      pc.stage = stage;
      dispatch(c, pc, count_);
      ++dispatches;
    }
  }
  return dispatches;
}

// Binds this pass's sets for vbd's sweeps and gives their push constants (the energy instances').
sh::SelfPush SelfCollisionGpu::begin_sweep_pass(VkCommandBuffer c, std::uint32_t read,
                                                const sh::PushConstants& main_pc) const {
  bind(c, read);
  auto pc = sh::push_from<sh::SelfPush>(main_pc);
  pc.table_size = table_;
  pc.iteration = 0;
  pc.in_sweeps = 1;
  return pc;
}

std::uint32_t SelfCollisionGpu::record_sweep_lists(VkCommandBuffer c, std::uint32_t read,
                                                   const sh::PushConstants& main_pc) const {
  auto pc = begin_sweep_pass(c, read, main_pc);
  return record_build(c, pc, true);
}

std::uint32_t SelfCollisionGpu::record_sweep_contact(VkCommandBuffer c, std::uint32_t read,
                                                     const sh::PushConstants& main_pc) const {
  auto pc = begin_sweep_pass(c, read, main_pc);
  pc.stage = VKCLOTH_SELF_CONTACT;
  dispatch(c, pc, count_);
  return 1;
}

} // namespace vkcloth::gpu
