#include "implicit_gpu.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>

#include <fmt/format.h>

#include "barriers.hpp"
#include "implicit_shared.h"
#include "vkcloth/shaders/implicit_comp_spv.hpp"
#include "vkcloth/shaders/implicit_reduce_comp_spv.hpp"

namespace vkcloth::gpu {

namespace sh = shared;

namespace {

constexpr std::uint32_t kBindings[] = {
    VKCLOTH_BINDING_POS_IN,         VKCLOTH_BINDING_FORCE_OUT,     VKCLOTH_BINDING_NORMAL,    VKCLOTH_BINDING_POS_OUT,
    VKCLOTH_BINDING_VEL,            VKCLOTH_BINDING_PARTICLE,      VKCLOTH_BINDING_OFFSETS,   VKCLOTH_BINDING_EDGES,
    VKCLOTH_BINDING_COLLIDERS,      VKCLOTH_BINDING_FLAGS,         VKCLOTH_BINDING_INSTANCES, VKCLOTH_BINDING_IMPL_VF,   VKCLOTH_BINDING_IMPL_KS,
    VKCLOTH_BINDING_IMPL_DIAG_INV,  VKCLOTH_BINDING_IMPL_X,        VKCLOTH_BINDING_IMPL_R,    VKCLOTH_BINDING_IMPL_Z,
    VKCLOTH_BINDING_IMPL_D,         VKCLOTH_BINDING_IMPL_Q,        VKCLOTH_BINDING_IMPL_PARTIALS,
    VKCLOTH_BINDING_IMPL_STATE,     VKCLOTH_BINDING_IMPL_ARGS};
constexpr std::uint32_t kBindingCount = sizeof(kBindings) / sizeof(kBindings[0]);

template <std::size_t N>
Result<VkShaderModule> module(const DeviceFns& vk, VkDevice d, const std::uint32_t (&code)[N], const char* name) {
  VkShaderModuleCreateInfo ci{};
  ci.sType = VK_STRUCTURE_TYPE_SHADER_MODULE_CREATE_INFO;
  ci.codeSize = N * sizeof(std::uint32_t);
  ci.pCode = code;
  VkShaderModule m = VK_NULL_HANDLE;
  VKCLOTH_VK_TRY(vk.vkCreateShaderModule(d, &ci, vk.allocator, &m), fmt::format("vkCreateShaderModule ({})", name));
  return m;
}

} // namespace

ImplicitGpu::~ImplicitGpu() {
  if (!ctx_ || !ctx_->device) return;
  const auto& v = ctx_->vk;
  const VkDevice d = ctx_->device;
  if (pass_) v.vkDestroyPipeline(d, pass_, v.allocator);
  if (reduce_) v.vkDestroyPipeline(d, reduce_, v.allocator);
  if (layout_) v.vkDestroyPipelineLayout(d, layout_, v.allocator);
  if (pool_) v.vkDestroyDescriptorPool(d, pool_, v.allocator);
  if (set_layout_) v.vkDestroyDescriptorSetLayout(d, set_layout_, v.allocator);
  for (Buffer* b : {&vf_, &ks_, &diag_inv_, &x_, &r_, &z_, &d_, &q_, &partials_, &state_, &args_}) destroy_buffer(*ctx_, *b);
}

Result<std::unique_ptr<ImplicitGpu>> ImplicitGpu::create(const std::shared_ptr<Context::Impl>& ctx, std::uint32_t count,
                                                         std::uint64_t entries, std::uint32_t groups_x,
                                                         std::uint32_t groups_y, bool allow_map) {
  std::unique_ptr<ImplicitGpu> s(new ImplicitGpu());
  s->ctx_ = ctx;
  s->count_ = count;
  s->groups_x_ = groups_x;
  s->groups_y_ = groups_y;
  const auto& v = ctx->vk;
  const VkDevice d = ctx->device;
  const VkBufferUsageFlags usage = VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_TRANSFER_DST_BIT;
  const VkDeviceSize vec4_bytes = std::max<VkDeviceSize>(VkDeviceSize(count) * 16, 16);
  const std::pair<Buffer*, const char*> vec4s[] = {{&s->vf_, "implicit: filtered velocities"},
                                                   {&s->diag_inv_, "implicit: Jacobi diagonal"},
                                                   {&s->x_, "implicit: CG x"},
                                                   {&s->r_, "implicit: CG r"},
                                                   {&s->z_, "implicit: CG z"},
                                                   {&s->d_, "implicit: CG d"},
                                                   {&s->q_, "implicit: CG q"}};
  for (auto [b, what] : vec4s) {
    auto r = create_buffer(*ctx, vec4_bytes, usage, MemoryUse::device, allow_map, what);
    if (!r) return r.error();
    *b = *r;
  }
  {
    auto r = create_buffer(*ctx, std::max<VkDeviceSize>(entries * 32, 32), usage, MemoryUse::device, allow_map,
                           "implicit: spring blocks");
    if (!r) return r.error();
    s->ks_ = *r;
    const std::uint64_t groups = std::uint64_t(groups_x) * groups_y;
    auto p = create_buffer(*ctx, std::max<VkDeviceSize>(groups * 8, 16), usage, MemoryUse::device, allow_map,
                           "implicit: partial sums");
    if (!p) return p.error();
    s->partials_ = *p;
    auto st = create_buffer(*ctx, sizeof(sh::CgState), VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, MemoryUse::host_readback, true,
                            "implicit: CG state");
    if (!st) return st.error();
    s->state_ = *st;
    sh::CgState init{};
    init.done = 1;
    init.groups_x = groups_x;
    init.groups_y = groups_y;
    std::memcpy(s->state_.mapped, &init, sizeof(init));
    auto a = create_buffer(*ctx, sizeof(sh::CgArgs), VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_INDIRECT_BUFFER_BIT,
                           MemoryUse::device, false, "implicit: indirect arguments");
    if (!a) return a.error();
    s->args_ = *a;
  }

  std::array<VkDescriptorSetLayoutBinding, kBindingCount> bindings{};
  for (std::uint32_t i = 0; i < kBindingCount; ++i)
    bindings[i] = {kBindings[i], VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, 1, VK_SHADER_STAGE_COMPUTE_BIT, nullptr};
  VkDescriptorSetLayoutCreateInfo li{};
  li.sType = VK_STRUCTURE_TYPE_DESCRIPTOR_SET_LAYOUT_CREATE_INFO;
  li.bindingCount = kBindingCount;
  li.pBindings = bindings.data();
  VKCLOTH_VK_TRY(v.vkCreateDescriptorSetLayout(d, &li, v.allocator, &s->set_layout_), "vkCreateDescriptorSetLayout (implicit)");
  const VkPushConstantRange range{VK_SHADER_STAGE_COMPUTE_BIT, 0, sizeof(sh::PushConstants)};
  VkPipelineLayoutCreateInfo pi{};
  pi.sType = VK_STRUCTURE_TYPE_PIPELINE_LAYOUT_CREATE_INFO;
  pi.setLayoutCount = 1;
  pi.pSetLayouts = &s->set_layout_;
  pi.pushConstantRangeCount = 1;
  pi.pPushConstantRanges = &range;
  VKCLOTH_VK_TRY(v.vkCreatePipelineLayout(d, &pi, v.allocator, &s->layout_), "vkCreatePipelineLayout (implicit)");
  const VkDescriptorPoolSize size{VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, 2 * kBindingCount};
  VkDescriptorPoolCreateInfo dp{};
  dp.sType = VK_STRUCTURE_TYPE_DESCRIPTOR_POOL_CREATE_INFO;
  dp.maxSets = 2;
  dp.poolSizeCount = 1;
  dp.pPoolSizes = &size;
  VKCLOTH_VK_TRY(v.vkCreateDescriptorPool(d, &dp, v.allocator, &s->pool_), "vkCreateDescriptorPool (implicit)");
  const VkDescriptorSetLayout layouts[2] = {s->set_layout_, s->set_layout_};
  VkDescriptorSetAllocateInfo ai{};
  ai.sType = VK_STRUCTURE_TYPE_DESCRIPTOR_SET_ALLOCATE_INFO;
  ai.descriptorPool = s->pool_;
  ai.descriptorSetCount = 2;
  ai.pSetLayouts = layouts;
  VKCLOTH_VK_TRY(v.vkAllocateDescriptorSets(d, &ai, s->sets_), "vkAllocateDescriptorSets (implicit)");

  auto pm = module(v, d, spirv::implicit_comp_spv, "implicit.comp");
  if (!pm) return pm.error();
  auto rm = module(v, d, spirv::implicit_reduce_comp_spv, "implicit_reduce.comp");
  if (!rm) {
    v.vkDestroyShaderModule(d, *pm, v.allocator);
    return rm.error();
  }
  VkComputePipelineCreateInfo ci[2]{};
  const VkShaderModule mods[2] = {*pm, *rm};
  for (int k = 0; k < 2; ++k) {
    ci[k].sType = VK_STRUCTURE_TYPE_COMPUTE_PIPELINE_CREATE_INFO;
    ci[k].stage = VkPipelineShaderStageCreateInfo{VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO, nullptr, 0,
                                                  VK_SHADER_STAGE_COMPUTE_BIT, mods[k], "main", nullptr};
    ci[k].layout = s->layout_;
  }
  VkPipeline pipes[2] = {};
  const VkResult res = v.vkCreateComputePipelines(d, VK_NULL_HANDLE, 2, ci, v.allocator, pipes);
  v.vkDestroyShaderModule(d, *pm, v.allocator);
  v.vkDestroyShaderModule(d, *rm, v.allocator);
  if (res != VK_SUCCESS) return vk_error(res, "vkCreateComputePipelines (implicit.comp, implicit_reduce.comp)");
  s->pass_ = pipes[0];
  s->reduce_ = pipes[1];
  return s;
}

Result<void> ImplicitGpu::write_sets(const ImplicitInputs& in) {
  std::array<VkDescriptorBufferInfo, 2 * kBindingCount> infos{};
  std::array<VkWriteDescriptorSet, 2 * kBindingCount> writes{};
  std::size_t k = 0;
  for (std::uint32_t read = 0; read < 2; ++read)
    for (std::uint32_t binding : kBindings) {
      VkBuffer b = VK_NULL_HANDLE;
      switch (binding) {
      case VKCLOTH_BINDING_POS_IN: b = in.pos[read]; break;
      case VKCLOTH_BINDING_POS_OUT: b = in.pos[read ^ 1u]; break;
      case VKCLOTH_BINDING_FORCE_OUT: b = in.force; break;
      case VKCLOTH_BINDING_NORMAL: b = in.normal; break;
      case VKCLOTH_BINDING_VEL: b = in.vel; break;
      case VKCLOTH_BINDING_PARTICLE: b = in.particle; break;
      case VKCLOTH_BINDING_OFFSETS: b = in.offsets; break;
      case VKCLOTH_BINDING_EDGES: b = in.edges; break;
      case VKCLOTH_BINDING_COLLIDERS: b = in.colliders; break;
      case VKCLOTH_BINDING_FLAGS: b = in.flags; break;
      case VKCLOTH_BINDING_INSTANCES: b = in.instances; break;
      case VKCLOTH_BINDING_IMPL_VF: b = vf_.buffer; break;
      case VKCLOTH_BINDING_IMPL_KS: b = ks_.buffer; break;
      case VKCLOTH_BINDING_IMPL_DIAG_INV: b = diag_inv_.buffer; break;
      case VKCLOTH_BINDING_IMPL_X: b = x_.buffer; break;
      case VKCLOTH_BINDING_IMPL_R: b = r_.buffer; break;
      case VKCLOTH_BINDING_IMPL_Z: b = z_.buffer; break;
      case VKCLOTH_BINDING_IMPL_D: b = d_.buffer; break;
      case VKCLOTH_BINDING_IMPL_Q: b = q_.buffer; break;
      case VKCLOTH_BINDING_IMPL_PARTIALS: b = partials_.buffer; break;
      case VKCLOTH_BINDING_IMPL_STATE: b = state_.buffer; break;
      case VKCLOTH_BINDING_IMPL_ARGS: b = args_.buffer; break;
      default: break;
      }
      infos[k] = {b, 0, VK_WHOLE_SIZE};
      writes[k] = VkWriteDescriptorSet{VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET, nullptr, sets_[read], binding, 0, 1,
                                       VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, nullptr, &infos[k], nullptr};
      ++k;
    }
  ctx_->vk.vkUpdateDescriptorSets(ctx_->device, static_cast<std::uint32_t>(k), writes.data(), 0, nullptr);
  return {};
}

std::uint32_t ImplicitGpu::record_substep(VkCommandBuffer c, std::uint32_t read, sh::PushConstants pc,
                                          const SimParams& params, bool first) {
  const auto& v = ctx_->vk;
  const float tol = float(params.cg_tolerance);
  pc.c_next = tol * tol; // as CpuSolver<float>: Real(tol) * Real(tol)
  pc.pad0 = params.cg_max_iterations;
  pc.pad1 = groups_x_ * groups_y_;
  v.vkCmdBindDescriptorSets(c, VK_PIPELINE_BIND_POINT_COMPUTE, layout_, 0, 1, &sets_[read], 0, nullptr);
  bool need_barrier = !first;
  std::uint32_t dispatches = 0;
  VkPipeline bound = VK_NULL_HANDLE;
  auto pass = [&](VkPipeline pipe, std::uint32_t stage, int indirect_offset) {
    if (need_barrier) barriers::implicit_pass(v, c); // previous pass -> this one (RAW, WAR, indirect args)
    need_barrier = true;
    if (pipe != bound) {
      v.vkCmdBindPipeline(c, VK_PIPELINE_BIND_POINT_COMPUTE, pipe);
      bound = pipe;
    }
    pc.stage = stage;
    ++dispatches;
    v.vkCmdPushConstants(c, layout_, VK_SHADER_STAGE_COMPUTE_BIT, 0, sizeof(pc), &pc);
    if (indirect_offset >= 0)
      v.vkCmdDispatchIndirect(c, args_.buffer, VkDeviceSize(indirect_offset));
    else if (pipe == reduce_)
      v.vkCmdDispatch(c, 1, 1, 1);
    else
      v.vkCmdDispatch(c, groups_x_, groups_y_, 1);
  };
  constexpr int direct = -1, particles = offsetof(sh::CgArgs, particle_x), reduce = offsetof(sh::CgArgs, reduce_x);
  pass(pass_, VKCLOTH_IMPL_FORCE, direct);
  pass(pass_, VKCLOTH_IMPL_SYSTEM, direct);
  pass(reduce_, VKCLOTH_REDUCE_INIT, direct);
  for (std::uint32_t it = 0; it < params.cg_max_iterations; ++it) {
    pass(pass_, VKCLOTH_IMPL_MATVEC, particles);
    pass(reduce_, VKCLOTH_REDUCE_ALPHA, reduce);
    pass(pass_, VKCLOTH_IMPL_UPDATE, particles);
    pass(reduce_, VKCLOTH_REDUCE_BETA, reduce);
    pass(pass_, VKCLOTH_IMPL_DIRECTION, particles);
  }
  pass(pass_, VKCLOTH_IMPL_FINISH, direct);
  return dispatches;
}

SolveStats ImplicitGpu::stats() const {
  sh::CgState s{};
  std::memcpy(&s, state_.mapped, sizeof(s));
  SolveStats r;
  r.iterations = s.iterations;
  r.residual = s.rr0 > 0.0f ? std::sqrt(double(s.rr) / double(s.rr0)) : 0.0;
  return r;
}

} // namespace vkcloth::gpu
