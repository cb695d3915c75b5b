#include "vk_internal.hpp"

#include <algorithm>
#include <map>

#include <fmt/format.h>

#include "barriers.hpp"
#include "vkcloth/gpu/world.hpp"

namespace vkcloth::gpu {

std::vector<std::uint32_t> grid_triangle_indices(std::uint32_t nx, std::uint32_t ny) {
  std::vector<std::uint32_t> idx;
  if (nx < 2 || ny < 2) return idx;
  idx.reserve(std::size_t(nx - 1) * (ny - 1) * 6);
  for (std::uint32_t j = 0; j + 1 < ny; ++j)
    for (std::uint32_t i = 0; i + 1 < nx; ++i) {
      const std::uint32_t a = j * nx + i, b = a + 1, c = a + nx, d = c + 1;
      idx.insert(idx.end(), {a, b, d, a, d, c});
    }
  return idx;
}

struct ClothWorld::Impl {
  struct Instance {
    std::shared_ptr<const ParticleSystem> topology;
    GpuSolver solver;
  };
  std::shared_ptr<Context::Impl> ctx;
  Context* context = nullptr; // for GpuSolver::create (borrowed; the Impl above keeps the device)
  WorldOptions options;
  std::map<InstanceId, Instance> instances; // ordered: the recording order
  InstanceId next = 1;
  VkCommandPool cmd_pool = VK_NULL_HANDLE;
  VkCommandBuffer cmd = VK_NULL_HANDLE;
  VkFence fence = VK_NULL_HANDLE;

  Impl() = default;
  Impl(const Impl&) = delete;
  Impl& operator=(const Impl&) = delete;
  ~Impl() {
    instances.clear();
    if (!ctx || !ctx->device) return;
    const auto& v = ctx->vk;
    if (fence) {
      v.vkWaitForFences(ctx->device, 1, &fence, VK_TRUE, UINT64_MAX);
      v.vkDestroyFence(ctx->device, fence, v.allocator);
    }
    if (cmd_pool) v.vkDestroyCommandPool(ctx->device, cmd_pool, v.allocator);
  }

  Result<Instance*> find(InstanceId id) {
    const auto it = instances.find(id);
    if (it == instances.end()) return make_error(ErrorCode::invalid_argument, fmt::format("no cloth instance with id {}", id));
    return &it->second;
  }
};

Result<ClothWorld> ClothWorld::create(Context& context, WorldOptions options) {
  auto impl = std::make_unique<Impl>();
  impl->ctx = context.impl();
  impl->context = &context;
  impl->options = std::move(options);
  const auto& v = impl->ctx->vk;
  const VkDevice d = impl->ctx->device;
  VkCommandPoolCreateInfo cp{};
  cp.sType = VK_STRUCTURE_TYPE_COMMAND_POOL_CREATE_INFO;
  cp.flags = VK_COMMAND_POOL_CREATE_RESET_COMMAND_BUFFER_BIT;
  cp.queueFamilyIndex = impl->ctx->queue_family;
  VKCLOTH_VK_TRY(v.vkCreateCommandPool(d, &cp, v.allocator, &impl->cmd_pool), "vkCreateCommandPool (world)");
  VkCommandBufferAllocateInfo ca{};
  ca.sType = VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO;
  ca.commandPool = impl->cmd_pool;
  ca.level = VK_COMMAND_BUFFER_LEVEL_PRIMARY;
  ca.commandBufferCount = 1;
  VKCLOTH_VK_TRY(v.vkAllocateCommandBuffers(d, &ca, &impl->cmd), "vkAllocateCommandBuffers (world)");
  VkFenceCreateInfo fi{};
  fi.sType = VK_STRUCTURE_TYPE_FENCE_CREATE_INFO;
  fi.flags = VK_FENCE_CREATE_SIGNALED_BIT;
  VKCLOTH_VK_TRY(v.vkCreateFence(d, &fi, v.allocator, &impl->fence), "vkCreateFence (world)");
  return ClothWorld(std::move(impl));
}

ClothWorld::ClothWorld(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
ClothWorld::ClothWorld(ClothWorld&&) noexcept = default;
ClothWorld& ClothWorld::operator=(ClothWorld&&) noexcept = default;
ClothWorld::~ClothWorld() = default;

Result<InstanceId> ClothWorld::add(std::shared_ptr<const ParticleSystem> topology, SimParams params,
                                   const InitialState& initial) {
  if (!topology) return make_error(ErrorCode::invalid_argument, "ClothWorld::add: the topology is null");
  const std::size_t n = topology->size();
  if (!initial.positions.empty() && initial.positions.size() != n)
    return make_error(ErrorCode::invalid_argument,
                      fmt::format("ClothWorld::add: initial positions has {} entries, the topology {} particles",
                                  initial.positions.size(), n));
  if (!initial.velocities.empty() && initial.velocities.size() != n)
    return make_error(ErrorCode::invalid_argument,
                      fmt::format("ClothWorld::add: initial velocities has {} entries, the topology {} particles",
                                  initial.velocities.size(), n));
  Result<GpuSolver> solver = [&]() -> Result<GpuSolver> {
    if (initial.positions.empty() && initial.velocities.empty())
      return GpuSolver::create(*impl_->context, *topology, std::move(params), impl_->options.solver);
    ParticleSystem state = *topology; // the state only: the GPU solver copies what it uploads
    for (std::size_t p = 0; p < n; ++p) {
      if (!initial.positions.empty()) state.particles[p].position = initial.positions[p];
      if (!initial.velocities.empty()) state.particles[p].velocity = initial.velocities[p];
    }
    return GpuSolver::create(*impl_->context, state, std::move(params), impl_->options.solver);
  }();
  if (!solver) return solver.error();
  const InstanceId id = impl_->next++;
  impl_->instances.emplace(id, Impl::Instance{std::move(topology), std::move(solver.value())});
  return id;
}

Result<void> ClothWorld::remove(InstanceId id) {
  VKCLOTH_TRY(impl_->find(id));
  impl_->instances.erase(id);
  return {};
}

Result<void> ClothWorld::set_params(InstanceId id, SimParams params) {
  auto inst = impl_->find(id);
  if (!inst) return inst.error();
  return (*inst)->solver.set_params(std::move(params));
}

Result<SimParams> ClothWorld::params(InstanceId id) const {
  auto inst = impl_->find(id);
  if (!inst) return inst.error();
  return (*inst)->solver.params();
}

void ClothWorld::record_step(VkCommandBuffer cmd) { record_steps(cmd, 1); }

void ClothWorld::record_steps(VkCommandBuffer cmd, std::uint32_t steps) {
  for (auto& [id, inst] : impl_->instances) inst.solver.record_steps(cmd, steps);
}

void ClothWorld::record_barrier_to(VkCommandBuffer cmd, VkPipelineStageFlags dst_stage, VkAccessFlags dst_access) const {
  barriers::after_steps(impl_->ctx->vk, cmd, dst_stage, dst_access);
}

Result<void> ClothWorld::simulate(std::uint64_t steps, std::uint32_t steps_per_submit) {
  if (steps_per_submit == 0) return make_error(ErrorCode::invalid_argument, "steps_per_submit must be > 0");
  Impl& s = *impl_;
  const auto& v = s.ctx->vk;
  for (std::uint64_t done = 0; done < steps;) {
    const auto k = static_cast<std::uint32_t>(std::min<std::uint64_t>(steps - done, steps_per_submit));
    VKCLOTH_VK_TRY(v.vkResetFences(s.ctx->device, 1, &s.fence), "vkResetFences (world)");
    VKCLOTH_VK_TRY(v.vkResetCommandBuffer(s.cmd, 0), "vkResetCommandBuffer (world)");
    VkCommandBufferBeginInfo bi{};
    bi.sType = VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO;
    bi.flags = VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT;
    VKCLOTH_VK_TRY(v.vkBeginCommandBuffer(s.cmd, &bi), "vkBeginCommandBuffer (world)");
    record_steps(s.cmd, k);
    barriers::after_steps(v, s.cmd, VK_PIPELINE_STAGE_HOST_BIT, VK_ACCESS_HOST_READ_BIT); // flags read by the host
    VKCLOTH_VK_TRY(v.vkEndCommandBuffer(s.cmd), "vkEndCommandBuffer (world)");
    VkSubmitInfo si{};
    si.sType = VK_STRUCTURE_TYPE_SUBMIT_INFO;
    si.commandBufferCount = 1;
    si.pCommandBuffers = &s.cmd;
    VKCLOTH_VK_TRY(v.vkQueueSubmit(s.ctx->queue, 1, &si, s.fence), "vkQueueSubmit (world)");
    VKCLOTH_VK_TRY(v.vkWaitForFences(s.ctx->device, 1, &s.fence, VK_TRUE, UINT64_MAX), "vkWaitForFences (world)");
    done += k;
    VKCLOTH_TRY(check_divergence());
  }
  return {};
}

Result<void> ClothWorld::check_divergence() {
  for (auto& [id, inst] : impl_->instances)
    if (auto r = inst.solver.check_divergence(); !r) {
      Error e = r.error();
      e.message = fmt::format("cloth instance {}: {}", id, e.message);
      return e;
    }
  return {};
}

Result<std::vector<glm::vec3>> ClothWorld::positions(InstanceId id) {
  auto inst = impl_->find(id);
  if (!inst) return inst.error();
  return (*inst)->solver.positions();
}
Result<std::vector<glm::vec3>> ClothWorld::velocities(InstanceId id) {
  auto inst = impl_->find(id);
  if (!inst) return inst.error();
  return (*inst)->solver.velocities();
}
Result<std::vector<glm::vec3>> ClothWorld::normals(InstanceId id) {
  auto inst = impl_->find(id);
  if (!inst) return inst.error();
  return (*inst)->solver.normals();
}

Result<InstanceBuffers> ClothWorld::buffers(InstanceId id) const {
  auto inst = impl_->find(id);
  if (!inst) return inst.error();
  const GpuSolver& g = (*inst)->solver;
  InstanceBuffers b;
  b.positions = g.current_position_buffer();
  b.normals = g.normal_buffer();
  b.uvs = g.uv_buffer();
  b.count = g.particle_count();
  if ((*inst)->topology->grid) {
    b.nx = (*inst)->topology->grid->nx;
    b.ny = (*inst)->topology->grid->ny;
  }
  return b;
}

GpuSolver* ClothWorld::solver(InstanceId id) {
  auto inst = impl_->find(id);
  return inst ? &(*inst)->solver : nullptr;
}
const GpuSolver* ClothWorld::solver(InstanceId id) const {
  auto inst = impl_->find(id);
  return inst ? &(*inst)->solver : nullptr;
}
std::shared_ptr<const ParticleSystem> ClothWorld::topology(InstanceId id) const {
  auto inst = impl_->find(id);
  return inst ? (*inst)->topology : nullptr;
}

std::vector<InstanceId> ClothWorld::instances() const {
  std::vector<InstanceId> ids;
  for (const auto& [id, inst] : impl_->instances) ids.push_back(id);
  return ids;
}
std::size_t ClothWorld::size() const { return impl_->instances.size(); }

} // namespace vkcloth::gpu
