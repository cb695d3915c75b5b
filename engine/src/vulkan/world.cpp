// SPDX-License-Identifier: MIT
#include "internal/resources.hpp"

#include <algorithm>
#include <map>
#include <set>
#include <utility>
#include <vector>

#include <fmt/format.h>

#include "internal/barriers.hpp"
#include "world_impl.hpp"
#include "internal/argument_checks.hpp"
#include "internal/stretch_topology.hpp"

namespace vkcloth::gpu {

std::vector<std::uint32_t> grid_triangle_indices(std::uint32_t nx, std::uint32_t ny) {
  std::vector<std::uint32_t> idx;
  if (nx < 2 || ny < 2)
    return idx;
  idx.reserve(std::size_t(nx - 1) * (ny - 1) * 6);
  for (std::uint32_t j = 0; j + 1 < ny; ++j)
    for (std::uint32_t i = 0; i + 1 < nx; ++i) {
      const std::uint32_t a = j * nx + i, b = a + 1, c = a + nx, d = c + 1;
      idx.insert(idx.end(), {a, b, d, a, d, c});
    }
  return idx;
}

std::vector<std::uint32_t> grid_triangle_strip_indices(std::uint32_t nx, std::uint32_t ny) {
  std::vector<std::uint32_t> idx;
  if (nx < 2 || ny < 2)
    return idx;
  idx.reserve(std::size_t(ny - 1) * (2 * nx + 1));
  for (std::uint32_t j = 0; j + 1 < ny; ++j) {
    if (j > 0)
      idx.push_back(strip_restart_index);
    // Upper point first: the strip's first triangle (c0, a0, c1) is the list's (a, d, c), the
    // second (a0, a1, c1) its (a, b, d): same triangles, same counter-clockwise winding.
    for (std::uint32_t i = 0; i < nx; ++i)
      idx.insert(idx.end(), {(j + 1) * nx + i, j * nx + i});
  }
  return idx;
}

Result<std::unique_ptr<ClothWorld::Impl>> ClothWorld::Impl::create(const std::shared_ptr<Context::Impl>& ctx,
                                                                   WorldOptions options,
                                                                   const testing::SolverKnobs& knobs) {
  auto impl = std::make_unique<Impl>();
  impl->ctx = ctx;
  impl->options = std::move(options);
  impl->knobs = knobs;
  auto commands = CommandContext::create(*ctx, "world");
  if (!commands)
    return commands.error();
  impl->commands = std::move(*commands);
  if (ctx->timestamp_valid_bits > 0) {
    VkQueryPoolCreateInfo qi{};
    qi.sType = VK_STRUCTURE_TYPE_QUERY_POOL_CREATE_INFO;
    qi.queryType = VK_QUERY_TYPE_TIMESTAMP;
    qi.queryCount = 2;
    VKCLOTH_VK_TRY(ctx->vk.vkCreateQueryPool(ctx->device, &qi, ctx->vk.allocator, impl->queries.init(*ctx)),
                   "vkCreateQueryPool (world)");
  }
  return impl;
}

ClothWorld::Impl::BatchKey ClothWorld::Impl::key_of(const Instance& inst, InstanceId id) {
  BatchKey k;
  k.topology = inst.topology.get();
  k.family = inst.params.integrator == Integrator::rk4              ? 1
             : inst.params.integrator == Integrator::implicit_euler ? 2
             : inst.params.integrator == Integrator::vbd            ? 3
                                                                    : 0;
  k.substeps = inst.params.substeps;
  k.iterations = k.family == 3 ? inst.params.vbd_iterations : 0;
  k.only = k.family == 2 ? id : 0;
  return k;
}

Result<ClothWorld::Impl::Instance*> ClothWorld::Impl::find(InstanceId id) {
  const auto it = instances.find(id);
  if (it == instances.end())
    return make_error(ErrorCode::invalid_argument, fmt::format("no cloth instance with id {}", id));
  return &it->second;
}

Result<void> ClothWorld::Impl::rebuild(const BatchKey& key, const std::vector<InstanceId>& members,
                                       const std::map<InstanceId, const InitialState*>& fresh) {
  if (members.empty()) {
    VKCLOTH_TRY(commands.wait_for_earlier_work()); // recorded steps may still use its buffers
    batches.erase(key);
    return {};
  }
  std::vector<SimParams> params;
  std::vector<SlotState> states;
  for (InstanceId id : members) {
    params.push_back(instances.at(id).params);
    const auto f = fresh.find(id);
    states.push_back(f == fresh.end() ? SlotState{}
                                      : SlotState{&f->second->positions, &f->second->velocities});
  }
  auto made = Batch::create(ctx, commands, *instances.at(members.front()).topology, std::move(params),
                            options.solver, knobs, states);
  if (!made)
    return made.error();
  std::unique_ptr<Batch> batch = std::move(*made);
  std::set<Batch*> sources; // the batches the surviving members come from
  for (InstanceId id : members)
    if (!fresh.count(id))
      sources.insert(instances.at(id).batch);
  // The copy's leading barrier (ALL_COMMANDS) and its fence also mean that every earlier
  // submission on the queue (the host's recorded steps) has completed: the old batches are idle.
  if (!sources.empty())
    VKCLOTH_TRY(commands.submit_and_wait([&](VkCommandBuffer c) {
      barriers::before_batch_copy(ctx->vk, c);
      for (std::uint32_t k = 0; k < members.size(); ++k)
        if (!fresh.count(members[k])) {
          const Instance& inst = instances.at(members[k]);
          batch->record_copy_slot(c, *inst.batch, inst.slot, k);
        }
      barriers::after_batch_copy(ctx->vk, c);
    }));
  // Their flags are current (the copy waited for their work): read each batch's once.
  for (Batch* source : sources)
    source->refresh_flags();
  for (std::uint32_t k = 0; k < members.size(); ++k) {
    const Instance& inst = instances.at(members[k]);
    if (!fresh.count(members[k])) // step count, divergence, the host's targets
      VKCLOTH_TRY(batch->carry_over(k, inst.batch->slot(inst.slot)));
  }
  for (std::uint32_t k = 0; k < members.size(); ++k) {
    Instance& inst = instances.at(members[k]);
    inst.batch = batch.get();
    inst.slot = k;
  }
  batches[key] = BatchEntry{std::move(batch), members};
  return {};
}

void ClothWorld::Impl::record_steps(VkCommandBuffer cmd, std::uint32_t steps) {
  for (auto& [key, entry] : batches) {
    const std::uint64_t before = entry.solver->dispatches();
    entry.solver->record(cmd, steps);
    dispatches += entry.solver->dispatches() - before;
    // Moving colliders and host frames advanced in the batch: params(id) (and a later rebuild)
    // start from there.
    if (entry.solver->any_moving_colliders())
      for (std::uint32_t k = 0; k < entry.members.size(); ++k)
        instances.at(entry.members[k]).params.colliders = entry.solver->slot(k).params.colliders;
    for (std::uint32_t k = 0; k < entry.members.size(); ++k)
      if (entry.solver->slot(k).params.inertia.frame)
        instances.at(entry.members[k]).params.inertia.frame = entry.solver->slot(k).params.inertia.frame;
  }
}

Result<void> ClothWorld::Impl::simulate(std::uint64_t steps, std::uint32_t steps_per_submit) {
  if (steps_per_submit == 0)
    return make_error(ErrorCode::invalid_argument, "steps_per_submit must be > 0");
  const auto& v = ctx->vk;
  last_ms = queries ? 0.0 : -1.0;
  for (std::uint64_t done = 0; done < steps;) {
    const auto k = static_cast<std::uint32_t>(std::min<std::uint64_t>(steps - done, steps_per_submit));
    VKCLOTH_TRY(commands.submit_and_wait([&](VkCommandBuffer c) {
      if (queries) {
        v.vkCmdResetQueryPool(c, queries, 0, 2);
        v.vkCmdWriteTimestamp(c, VK_PIPELINE_STAGE_TOP_OF_PIPE_BIT, queries, 0);
      }
      record_steps(c, k);
      if (queries)
        v.vkCmdWriteTimestamp(c, VK_PIPELINE_STAGE_BOTTOM_OF_PIPE_BIT, queries, 1);
      barriers::after_steps(v, c, VK_PIPELINE_STAGE_HOST_BIT,
                            VK_ACCESS_HOST_READ_BIT); // flags read by the host
    }));
    if (queries) {
      std::uint64_t ts[2] = {};
      VKCLOTH_VK_TRY(v.vkGetQueryPoolResults(ctx->device, queries, 0, 2, sizeof(ts), ts,
                                             sizeof(std::uint64_t),
                                             VK_QUERY_RESULT_64_BIT | VK_QUERY_RESULT_WAIT_BIT),
                     "vkGetQueryPoolResults");
      const std::uint32_t bits = ctx->timestamp_valid_bits;
      const std::uint64_t mask = bits >= 64 ? ~0ull : ((1ull << bits) - 1);
      const std::uint64_t ticks = ((ts[1] & mask) - (ts[0] & mask)) & mask;
      last_ms += double(ticks) * double(ctx->properties.limits.timestampPeriod) * 1e-6;
    }
    done += k;
    VKCLOTH_TRY(divergence());
  }
  return {};
}

Result<void> ClothWorld::Impl::check_divergence() {
  VKCLOTH_TRY(commands.submit_and_wait([&](VkCommandBuffer c) { barriers::before_readback(ctx->vk, c); }));
  return divergence();
}

Result<void> ClothWorld::Impl::divergence() {
  for (auto& [key, entry] : batches)
    entry.solver->refresh_flags();
  for (auto& [id, inst] : instances)
    if (const auto& d = inst.batch->slot(inst.slot).diverged) {
      Error e = *d;
      e.message = fmt::format("cloth instance {}: {}", id, e.message);
      return e;
    }
  return {};
}

Result<ClothWorld> ClothWorld::create(Context& context, WorldOptions options) {
  return testing::create_world(context, std::move(options), {});
}

Result<ClothWorld> testing::create_world(Context& context, WorldOptions options, const SolverKnobs& knobs) {
  auto impl = ClothWorld::Impl::create(context_impl(context), std::move(options), knobs);
  if (!impl)
    return impl.error();
  return detail::Access::wrap<ClothWorld>(std::move(*impl));
}

ClothWorld::ClothWorld(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
ClothWorld::ClothWorld(ClothWorld&&) noexcept = default;
ClothWorld& ClothWorld::operator=(ClothWorld&&) noexcept = default;
ClothWorld::~ClothWorld() = default;

Result<InstanceId> ClothWorld::add(std::shared_ptr<const ClothTopology> topology, SimParams params,
                                   const InitialState& initial) {
  if (!topology)
    return make_error(ErrorCode::invalid_argument, "ClothWorld::add: the topology is null");
  const std::size_t n = topology->size();
  if (!initial.positions.empty() && initial.positions.size() != n)
    return make_error(
        ErrorCode::invalid_argument,
        fmt::format("ClothWorld::add: initial positions has {} entries, the topology {} particles",
                    initial.positions.size(), n));
  if (!initial.velocities.empty() && initial.velocities.size() != n)
    return make_error(
        ErrorCode::invalid_argument,
        fmt::format("ClothWorld::add: initial velocities has {} entries, the topology {} particles",
                    initial.velocities.size(), n));
  VKCLOTH_TRY(params.validate());
  VKCLOTH_TRY(vkcloth::detail::PinTargets::check(params, {}, n));
  VKCLOTH_TRY(vkcloth::detail::check_sweep_order(params.stretch_limit, *topology));
  VKCLOTH_TRY(vkcloth::detail::check_float_masses(topology->system()));
  Impl& s = *impl_;
  const InstanceId id = s.next;
  s.instances.emplace(id, Impl::Instance{std::move(topology), std::move(params)});
  const Impl::BatchKey key = Impl::key_of(s.instances.at(id), id);
  std::vector<InstanceId> members;
  if (auto it = s.batches.find(key); it != s.batches.end())
    members = it->second.members;
  members.push_back(id);
  if (auto r = s.rebuild(key, members, {{id, &initial}}); !r) {
    s.instances.erase(id);
    return r.error();
  }
  ++s.next;
  return id;
}

Result<void> ClothWorld::remove(InstanceId id) {
  auto inst = impl_->find(id);
  if (!inst)
    return inst.error();
  Impl& s = *impl_;
  const Impl::BatchKey key = Impl::key_of(**inst, id);
  std::vector<InstanceId> members = s.batches.at(key).members;
  std::erase(members, id);
  VKCLOTH_TRY(s.rebuild(key, members, {}));
  s.instances.erase(id);
  return {};
}

Result<void> ClothWorld::set_params(InstanceId id, SimParams params) {
  auto found = impl_->find(id);
  if (!found)
    return found.error();
  VKCLOTH_TRY(params.validate());
  Impl& s = *impl_;
  Impl::Instance& inst = **found;
  VKCLOTH_TRY(inst.batch->slot(inst.slot).targets.check_params(params, inst.batch->particle_count()));
  VKCLOTH_TRY(vkcloth::detail::check_sweep_order(params.stretch_limit, *inst.topology));
  const Impl::BatchKey old_key = Impl::key_of(inst, id);
  SimParams previous = std::move(inst.params);
  inst.params = std::move(params);
  const Impl::BatchKey new_key = Impl::key_of(inst, id);
  if (new_key == old_key) {
    // Same batch: new per-instance parameters and colliders, no pipeline re-created.
    if (auto r = inst.batch->set_params(inst.slot, inst.params); !r) {
      inst.params = std::move(previous);
      return r.error();
    }
    return {};
  }
  // Another integrator family or substep count: the instance moves to that batch.
  std::vector<InstanceId> joined;
  if (auto it = s.batches.find(new_key); it != s.batches.end())
    joined = it->second.members;
  joined.push_back(id);
  if (auto r = s.rebuild(new_key, joined, {}); !r) {
    inst.params = std::move(previous);
    return r.error();
  }
  std::vector<InstanceId> left = s.batches.at(old_key).members;
  std::erase(left, id);
  return s.rebuild(old_key, left, {});
}

Result<void> ClothWorld::set_step_params(InstanceId id, const StepParams& step) {
  auto found = impl_->find(id);
  if (!found)
    return found.error();
  return set_params(id, step.applied_to((*found)->params));
}

Result<void> ClothWorld::set_collider_pose(InstanceId id, std::size_t collider, const ColliderPose& pose) {
  auto found = impl_->find(id);
  if (!found)
    return found.error();
  auto posed = with_collider_pose((*found)->params, collider, pose);
  if (!posed)
    return posed.error();
  return set_params(id, std::move(*posed));
}

Result<void> ClothWorld::set_pin_targets(InstanceId id, std::span<const PinTarget> targets) {
  auto found = impl_->find(id);
  if (!found)
    return found.error();
  return (*found)->batch->set_pin_targets((*found)->slot, targets);
}

Result<void> ClothWorld::teleport(InstanceId id, const RigidJump& jump) {
  auto found = impl_->find(id);
  if (!found)
    return found.error();
  return (*found)->batch->teleport((*found)->slot, jump);
}

Result<SimParams> ClothWorld::params(InstanceId id) const {
  auto inst = impl_->find(id);
  if (!inst)
    return inst.error();
  return (*inst)->params;
}

void ClothWorld::record_step(VkCommandBuffer cmd) {
  record_steps(cmd, 1);
}

void ClothWorld::record_steps(VkCommandBuffer cmd, std::uint32_t steps) {
  impl_->record_steps(cmd, steps);
}

void ClothWorld::record_barrier_to(VkCommandBuffer cmd, VkPipelineStageFlags dst_stage,
                                   VkAccessFlags dst_access) const {
  barriers::after_steps(impl_->ctx->vk, cmd, dst_stage, dst_access);
}

void ClothWorld::Impl::record_queue_transfer(VkCommandBuffer cmd, const QueueTransfer& t,
                                             bool release) const {
  std::vector<VkBuffer> drawn;
  for (const auto& [key, entry] : batches)
    for (VkBuffer b : entry.solver->drawn_buffers())
      drawn.push_back(b);
  barriers::queue_transfer(ctx->vk, cmd, drawn, release, t.src_family, t.dst_family, t.stage, t.access);
}

void ClothWorld::record_release(VkCommandBuffer cmd, const QueueTransfer& transfer) const {
  impl_->record_queue_transfer(cmd, transfer, true);
}

void ClothWorld::record_acquire(VkCommandBuffer cmd, const QueueTransfer& transfer) const {
  impl_->record_queue_transfer(cmd, transfer, false);
}

Result<void> ClothWorld::simulate(std::uint64_t steps, std::uint32_t steps_per_submit) {
  return impl_->simulate(steps, steps_per_submit);
}

Result<void> ClothWorld::check_divergence() {
  return impl_->check_divergence();
}

namespace {

Result<std::vector<glm::vec3>> read(ClothWorld::Impl& w, InstanceId id, SolverBatch::Field field) {
  auto inst = w.find(id);
  if (!inst)
    return inst.error();
  return (*inst)->batch->read(field, (*inst)->slot);
}

} // namespace

Result<std::vector<glm::vec3>> ClothWorld::positions(InstanceId id) {
  return read(*impl_, id, SolverBatch::Field::positions);
}
Result<std::vector<glm::vec3>> ClothWorld::velocities(InstanceId id) {
  return read(*impl_, id, SolverBatch::Field::velocities);
}
Result<std::vector<glm::vec3>> ClothWorld::normals(InstanceId id) {
  return read(*impl_, id, SolverBatch::Field::normals);
}

Result<InstanceBuffers> ClothWorld::buffers(InstanceId id) const {
  auto inst = impl_->find(id);
  if (!inst)
    return inst.error();
  return (*inst)->batch->buffers((*inst)->slot);
}

std::uint64_t ClothWorld::step_index(InstanceId id) const {
  auto inst = impl_->find(id);
  return inst ? (*inst)->batch->slot((*inst)->slot).step : 0;
}

std::size_t ClothWorld::batch_count() const {
  return impl_->batches.size();
}

std::uint64_t ClothWorld::dispatches_recorded() const {
  return impl_->dispatches;
}

std::shared_ptr<const ClothTopology> ClothWorld::topology(InstanceId id) const {
  auto inst = impl_->find(id);
  return inst ? (*inst)->topology : nullptr;
}

std::vector<InstanceId> ClothWorld::instances() const {
  std::vector<InstanceId> ids;
  for (const auto& [id, inst] : impl_->instances)
    ids.push_back(id);
  return ids;
}
std::size_t ClothWorld::size() const {
  return impl_->instances.size();
}

} // namespace vkcloth::gpu
