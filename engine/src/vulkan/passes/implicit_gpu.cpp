// SPDX-License-Identifier: MIT
#include "implicit_gpu.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <span>
#include <utility>
#include <vector>
#include <tuple>

#include <fmt/format.h>

#include "internal/barriers.hpp"
#include "internal/pipelines.hpp"
#include "kernel/layout/implicit_shared.h"
#include "vkcloth/shaders/implicit_comp_spv.hpp"

namespace vkcloth::gpu {

namespace sh = shared;

Result<std::unique_ptr<ImplicitGpu>> ImplicitGpu::create(const std::shared_ptr<Context::Impl>& ctx,
                                                         std::uint32_t count, std::uint64_t entries,
                                                         std::uint32_t groups_x, std::uint32_t groups_y,
                                                         std::uint32_t one_workgroup_budget, bool allow_map) {
  std::unique_ptr<ImplicitGpu> s(new ImplicitGpu());
  s->ctx_ = ctx;
  s->count_ = count;
  s->groups_x_ = groups_x;
  s->groups_y_ = groups_y;
  s->budget_ = one_workgroup_budget;
  VKCLOTH_TRY(s->create_buffers(entries, allow_map));
  VKCLOTH_TRY(s->create_pipelines());
  return s;
}

Result<void> ImplicitGpu::create_buffers(std::uint64_t entries, bool allow_map) {
  Context::Impl& ctx = *ctx_;
  const VkBufferUsageFlags usage = VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_TRANSFER_DST_BIT;
  const VkDeviceSize vec4_bytes = std::max<VkDeviceSize>(VkDeviceSize(count_) * 16, 16);
  const std::uint64_t groups = std::uint64_t(groups_x_) * groups_y_;
  const std::tuple<Buffer*, VkDeviceSize, const char*> device_buffers[] = {
      {&vf_, 3 * vec4_bytes,
       "implicit: filtered velocities, then the forces the filter removed, then the contact axes"},
      {&block_inv_, 2 * vec4_bytes, "implicit: block-Jacobi preconditioner"},
      {&x_, vec4_bytes, "implicit: CG x"},
      {&r_, vec4_bytes, "implicit: CG r"},
      {&z_, vec4_bytes, "implicit: CG z"},
      {&d_, vec4_bytes, "implicit: CG d"},
      {&q_, vec4_bytes, "implicit: CG q"},
      {&ks_, std::max<VkDeviceSize>(entries * 32, 32), "implicit: spring blocks"},
      {&partials_, std::max<VkDeviceSize>(groups * 16, 16), "implicit: partial sums"}};
  for (auto [b, bytes, what] : device_buffers) {
    auto r = create_buffer(ctx, bytes, usage, MemoryUse::device, allow_map, what);
    if (!r)
      return r.error();
    *b = std::move(*r);
  }
  auto st = create_buffer(ctx, sizeof(sh::CgState), VK_BUFFER_USAGE_STORAGE_BUFFER_BIT,
                          MemoryUse::host_readback, true, "implicit: CG state");
  if (!st)
    return st.error();
  state_ = std::move(*st);
  sh::CgState init{};
  init.done = 1;
  init.groups_x = groups_x_;
  init.groups_y = groups_y_;
  std::memcpy(state_.mapped, &init, sizeof(init));
  auto a = create_buffer(ctx, sizeof(sh::CgArgs),
                         VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_INDIRECT_BUFFER_BIT,
                         MemoryUse::device, false, "implicit: indirect arguments");
  if (!a)
    return a.error();
  args_ = std::move(*a);
  return {};
}

namespace {

/// implicit.comp's one binding table (implicit_shared.h) and its one build (its reductions' shared
/// arrays are sized with VKCLOTH_WORKGROUP_SIZE).
constexpr BindingTable kImplicitBindings{"implicit", sh::implicit_bindings};
constexpr ShaderSource kImplicit{"implicit.comp", spirv::implicit_comp_spv, {}, &kImplicitBindings, true};

} // namespace

// The Context's layouts and pipelines (one per pass this batch records: implicit.comp
// specialised with its mode, ShaderVariant::stage); this batch's pool and two sets (position parity).
Result<void> ImplicitGpu::create_pipelines() {
  Context::Impl& ctx = *ctx_;
  auto layouts = ctx.pipelines->layouts(kImplicitBindings);
  if (!layouts)
    return layouts.error();
  set_layout_ = layouts->storage;
  layout_ = layouts->layout;
  VKCLOTH_TRY(create_parity_sets(ctx, set_layout_,
                                 static_cast<std::uint32_t>(std::size(sh::implicit_bindings)), pool_, sets_,
                                 "implicit"));
  // FORCE and FINISH come per collider types (ensure_collider_passes).
  const std::uint32_t one_workgroup[] = {VKCLOTH_IMPL_SYSTEM, VKCLOTH_IMPL_SOLVE};
  const std::uint32_t per_iteration[] = {VKCLOTH_IMPL_SYSTEM, VKCLOTH_IMPL_MATVEC, VKCLOTH_IMPL_UPDATE,
                                         VKCLOTH_IMPL_DIRECTION};
  for (std::uint32_t mode : budget_ > 0 ? std::span<const std::uint32_t>(one_workgroup)
                                        : std::span<const std::uint32_t>(per_iteration)) {
    auto pp = ctx.pipelines->pipeline(kImplicit, {}, {BufferAccess::texel_views, 0, mode});
    if (!pp)
      return pp.error();
    passes_[mode] = *pp;
  }
  return {};
}

Result<void> ImplicitGpu::ensure_collider_passes(std::uint32_t types,
                                                 std::span<const std::uint32_t> constants) {
  if (force_passes_[types])
    return {};
  for (auto [mode, pass] : {std::pair{VKCLOTH_IMPL_FORCE, &force_passes_[types]},
                            std::pair{VKCLOTH_IMPL_FINISH, &finish_passes_[types]}}) {
    auto pp = ctx_->pipelines->pipeline(kImplicit, constants, {BufferAccess::texel_views, 0, mode});
    if (!pp)
      return pp.error();
    *pass = *pp;
  }
  return {};
}

// Long (~60 lines) but flat: one switch that maps each binding of the implicit layout
// (implicit_shared.h) to its buffer, a table to scan rather than logic to follow.
Result<void> ImplicitGpu::write_sets(const ImplicitInputs& in) {
  VKCLOTH_TRY(write_parity_sets(*ctx_, sets_, sh::implicit_bindings,
                                [&](std::uint32_t read, std::uint32_t binding) -> VkBuffer {
                                  switch (binding) {
                                  case VKCLOTH_BINDING_POS_IN:
                                    return in.pos[read];
                                  case VKCLOTH_BINDING_POS_OUT:
                                    return in.pos[read ^ 1u];
                                  case VKCLOTH_BINDING_FORCE_OUT:
                                    return in.force;
                                  case VKCLOTH_BINDING_NORMAL:
                                    return in.normal;
                                  case VKCLOTH_BINDING_VEL:
                                    return in.vel;
                                  case VKCLOTH_BINDING_PARTICLE:
                                    return in.particle;
                                  case VKCLOTH_BINDING_OFFSETS:
                                    return in.offsets;
                                  case VKCLOTH_BINDING_EDGES:
                                    return in.edges;
                                  case VKCLOTH_BINDING_COLLIDERS:
                                    return in.colliders;
                                  case VKCLOTH_BINDING_FLAGS:
                                    return in.flags;
                                  case VKCLOTH_BINDING_INSTANCES:
                                    return in.instances;
                                  case VKCLOTH_BINDING_MESH_NODES:
                                    return in.mesh_nodes;
                                  case VKCLOTH_BINDING_MESH_TRIS:
                                    return in.mesh_tris;
                                  case VKCLOTH_BINDING_MESH_CACHE:
                                    return in.mesh_cache;
                                  case VKCLOTH_BINDING_IMPL_VF:
                                    return vf_.buffer;
                                  case VKCLOTH_BINDING_IMPL_KS:
                                    return ks_.buffer;
                                  case VKCLOTH_BINDING_IMPL_BLOCK_INV:
                                    return block_inv_.buffer;
                                  case VKCLOTH_BINDING_IMPL_X:
                                    return x_.buffer;
                                  case VKCLOTH_BINDING_IMPL_R:
                                    return r_.buffer;
                                  case VKCLOTH_BINDING_IMPL_Z:
                                    return z_.buffer;
                                  case VKCLOTH_BINDING_IMPL_D:
                                    return d_.buffer;
                                  case VKCLOTH_BINDING_IMPL_Q:
                                    return q_.buffer;
                                  case VKCLOTH_BINDING_IMPL_PARTIALS:
                                    return partials_.buffer;
                                  case VKCLOTH_BINDING_IMPL_STATE:
                                    return state_.buffer;
                                  case VKCLOTH_BINDING_IMPL_ARGS:
                                    return args_.buffer;
                                  default:
                                    return VK_NULL_HANDLE;
                                  }
                                }));
  return {};
}

std::uint32_t ImplicitGpu::record_substep(VkCommandBuffer c, std::uint32_t read,
                                          const sh::PushConstants& main_pc, const SimParams& params,
                                          std::uint32_t types, bool first) {
  const auto& v = ctx_->vk;
  const float tol = float(params.cg_tolerance);
  auto pc = sh::push_from<sh::ImplicitPush>(main_pc);
  pc.tolerance2 = tol * tol; // as CpuSolver<float>: Real(tol) * Real(tol)
  pc.cg_max_iterations = params.cg_max_iterations;
  pc.solve_budget = budget_;
  v.vkCmdBindDescriptorSets(c, VK_PIPELINE_BIND_POINT_COMPUTE, layout_, 0, 1, &sets_[read], 0, nullptr);
  bool need_barrier = !first;
  std::uint32_t dispatches = 0;
  enum class Groups { all, one, indirect }; // every particle's group; one workgroup; CgArgs
  auto pass = [&](std::uint32_t stage, Groups groups) {
    if (need_barrier)
      barriers::implicit_pass(v, c); // previous pass -> this one (RAW, WAR, indirect args)
    need_barrier = true;
    v.vkCmdBindPipeline(c, VK_PIPELINE_BIND_POINT_COMPUTE,
                        stage == VKCLOTH_IMPL_FORCE    ? force_passes_[types]
                        : stage == VKCLOTH_IMPL_FINISH ? finish_passes_[types]
                                                       : passes_[stage]);
    pc.stage = stage;
    ++dispatches;
    v.vkCmdPushConstants(c, layout_, VK_SHADER_STAGE_COMPUTE_BIT, 0, sizeof(pc), &pc);
    if (groups == Groups::indirect)
      v.vkCmdDispatchIndirect(c, args_.buffer, 0);
    else if (groups == Groups::one)
      v.vkCmdDispatch(c, 1, 1, 1);
    else
      v.vkCmdDispatch(c, groups_x_, groups_y_, 1);
  };
  pass(VKCLOTH_IMPL_FORCE, Groups::all);
  pass(VKCLOTH_IMPL_SYSTEM, Groups::all); // its last workgroup starts the solve (rz, rr, ref2)
  if (budget_ > 0) {
    for (std::uint32_t it = 0; it < params.cg_max_iterations; it += budget_)
      pass(VKCLOTH_IMPL_SOLVE, Groups::one);
  } else {
    for (std::uint32_t it = 0; it < params.cg_max_iterations; ++it) {
      pass(VKCLOTH_IMPL_MATVEC, Groups::indirect); // + alpha (its last workgroup)
      pass(VKCLOTH_IMPL_UPDATE, Groups::indirect); // + beta, convergence
      pass(VKCLOTH_IMPL_DIRECTION, Groups::indirect);
    }
  }
  pass(VKCLOTH_IMPL_FINISH, Groups::all);
  return dispatches;
}

std::uint32_t ImplicitGpu::iteration_budget(std::uint32_t count, std::uint32_t max_degree) {
  // Per CG iteration, an invocation loops ceil(count / 64) times in each of the matvec (plus
  // its springs), update and direction loops, 2 x 6 times in the two tree sums, once outside;
  // `rows` more are left as margin.
  const std::uint64_t rows = (std::uint64_t(count) + VKCLOTH_WORKGROUP_SIZE - 1) / VKCLOTH_WORKGROUP_SIZE;
  const std::uint64_t per_iteration = rows * (3 + std::uint64_t(max_degree)) + 13;
  const std::uint64_t room = rows < 30000 ? 30000 - rows : 0;
  return std::uint32_t(std::min<std::uint64_t>(room / per_iteration, 1024)); // 0: too large
}

SolveStats ImplicitGpu::stats() const {
  sh::CgState s{};
  std::memcpy(&s, state_.mapped, sizeof(s));
  SolveStats r;
  r.iterations = s.iterations;
  r.residual = s.ref2 > 0.0f ? std::sqrt(double(s.rr) / double(s.ref2)) : 0.0;
  r.total_iterations = s.total_iterations;
  r.solves = s.solves;
  return r;
}

} // namespace vkcloth::gpu
