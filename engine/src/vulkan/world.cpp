#include "resources.hpp"

#include <algorithm>
#include <map>
#include <set>
#include <utility>
#include <vector>

#include <fmt/format.h>

#include "barriers.hpp"
#include "solver_batch.hpp"
#include "vkcloth/gpu/testing.hpp"
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

// Instances are grouped into batches (GpuSolver::Impl, solver_batch.hpp) by topology, integrator
// family and substep count; each batch steps all its instances with one dispatch per pass.
// Adding, removing or moving an instance rebuilds its batch: new buffers, the surviving
// instances' state copied over on the GPU (positions, velocities, normals, forces).
struct ClothWorld::Impl {
  using Batch = GpuSolver::Impl;
  struct Instance {
    std::shared_ptr<const ParticleSystem> topology;
    SimParams params;
    Batch* batch = nullptr;
    std::uint32_t slot = 0;
  };
  /// What instances must agree on to share a batch (and so its dispatches).
  struct BatchKey {
    const ParticleSystem* topology = nullptr;
    int family = 0; // 0: explicit / semi-implicit Euler, 1: RK4, 2: implicit Euler (one instance per batch)
    std::uint32_t substeps = 1;
    InstanceId only = 0; // implicit Euler: the instance (its CG reductions are per batch)
    auto operator<=>(const BatchKey&) const = default;
  };
  struct BatchEntry {
    std::unique_ptr<Batch> solver;
    std::vector<InstanceId> members; // slot order
  };

  std::shared_ptr<Context::Impl> ctx;
  WorldOptions options;
  testing::SolverKnobs knobs;
  std::map<InstanceId, Instance> instances; // ordered by id
  std::map<BatchKey, BatchEntry> batches;
  InstanceId next = 1;
  std::uint64_t dispatches = 0; // recorded by record_steps(), all batches
  CommandContext commands;      // batch rebuilds (copies), simulate(), check_divergence()

  Impl() = default;
  Impl(const Impl&) = delete;
  Impl& operator=(const Impl&) = delete;

  static BatchKey key_of(const Instance& inst, InstanceId id) {
    BatchKey k;
    k.topology = inst.topology.get();
    k.family = inst.params.integrator == Integrator::rk4 ? 1 : inst.params.integrator == Integrator::implicit_euler ? 2 : 0;
    k.substeps = inst.params.substeps;
    k.only = k.family == 2 ? id : 0;
    return k;
  }

  Result<Instance*> find(InstanceId id) {
    const auto it = instances.find(id);
    if (it == instances.end()) return make_error(ErrorCode::invalid_argument, fmt::format("no cloth instance with id {}", id));
    return &it->second;
  }

  template <typename F> Result<void> submit_and_wait(F&& record_fn) {
    return commands.submit_and_wait(std::forward<F>(record_fn));
  }

  /// Rebuilds the batch `key` with `members` (slot order; may be empty: the batch goes away).
  /// Members already in a batch keep their state (copied on the GPU); `fresh` ones start from
  /// their InitialState. On failure nothing changes.
  Result<void> rebuild(const BatchKey& key, const std::vector<InstanceId>& members,
                       const std::map<InstanceId, const InitialState*>& fresh) {
    if (members.empty()) {
      batches.erase(key);
      return {};
    }
    std::vector<SimParams> params;
    std::vector<SlotState> states;
    for (InstanceId id : members) {
      params.push_back(instances.at(id).params);
      const auto f = fresh.find(id);
      states.push_back(f == fresh.end() ? SlotState{} : SlotState{&f->second->positions, &f->second->velocities});
    }
    auto made = Batch::create(ctx, *instances.at(members.front()).topology, std::move(params), options.solver, knobs, states);
    if (!made) return made.error();
    std::unique_ptr<Batch> batch = std::move(*made);
    std::set<Batch*> sources; // the batches the surviving members come from
    for (InstanceId id : members)
      if (!fresh.count(id)) sources.insert(instances.at(id).batch);
    if (!sources.empty())
      VKCLOTH_TRY(submit_and_wait([&](VkCommandBuffer c) {
        barriers::before_batch_copy(ctx->vk, c);
        for (std::uint32_t k = 0; k < members.size(); ++k)
          if (!fresh.count(members[k])) {
            const Instance& inst = instances.at(members[k]);
            batch->record_copy_slot(c, *inst.batch, inst.slot, k);
          }
        barriers::after_batch_copy(ctx->vk, c);
      }));
    // Their flags are current (the copy waited for their work): read each batch's once.
    for (Batch* source : sources) source->refresh_flags();
    for (std::uint32_t k = 0; k < members.size(); ++k) {
      Instance& inst = instances.at(members[k]);
      if (!fresh.count(members[k])) { // carry its step count and divergence over
        const Batch::Slot& old = inst.batch->slots[inst.slot];
        Batch::Slot& now = batch->slots[k];
        now.step = now.epoch_step = old.step;
        now.diverged = old.diverged;
        if (now.diverged) batch->freeze_slot(k);
      }
      inst.batch = batch.get();
      inst.slot = k;
    }
    batches[key] = BatchEntry{std::move(batch), members};
    return {};
  }

  /// Reads every batch's flags (their work must be complete and visible to the host).
  Result<void> divergence() {
    for (auto& [key, entry] : batches) entry.solver->refresh_flags();
    for (auto& [id, inst] : instances)
      if (const auto& d = inst.batch->slots[inst.slot].diverged) {
        Error e = *d;
        e.message = fmt::format("cloth instance {}: {}", id, e.message);
        return e;
      }
    return {};
  }
};

Result<ClothWorld> ClothWorld::create(Context& context, WorldOptions options) {
  return testing::create_world(context, std::move(options), {});
}

Result<ClothWorld> testing::create_world(Context& context, WorldOptions options, const SolverKnobs& knobs) {
  auto impl = std::make_unique<ClothWorld::Impl>();
  impl->ctx = context_impl(context);
  impl->options = std::move(options);
  impl->knobs = knobs;
  auto commands = CommandContext::create(*impl->ctx, "world");
  if (!commands) return commands.error();
  impl->commands = std::move(*commands);
  return detail::Access::wrap<ClothWorld>(std::move(impl));
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
  VKCLOTH_TRY(params.validate());
  Impl& s = *impl_;
  const InstanceId id = s.next;
  s.instances.emplace(id, Impl::Instance{std::move(topology), std::move(params)});
  const Impl::BatchKey key = Impl::key_of(s.instances.at(id), id);
  std::vector<InstanceId> members;
  if (auto it = s.batches.find(key); it != s.batches.end()) members = it->second.members;
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
  if (!inst) return inst.error();
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
  if (!found) return found.error();
  VKCLOTH_TRY(params.validate());
  Impl& s = *impl_;
  Impl::Instance& inst = **found;
  const Impl::BatchKey old_key = Impl::key_of(inst, id);
  SimParams previous = std::move(inst.params);
  inst.params = std::move(params);
  const Impl::BatchKey new_key = Impl::key_of(inst, id);
  if (new_key == old_key) {
    // Same batch: new per-instance parameters and colliders, no pipeline re-created.
    if (auto r = inst.batch->set_slot_params(inst.slot, inst.params); !r) {
      inst.params = std::move(previous);
      return r.error();
    }
    return {};
  }
  // Another integrator family or substep count: the instance moves to that batch.
  std::vector<InstanceId> joined;
  if (auto it = s.batches.find(new_key); it != s.batches.end()) joined = it->second.members;
  joined.push_back(id);
  if (auto r = s.rebuild(new_key, joined, {}); !r) {
    inst.params = std::move(previous);
    return r.error();
  }
  std::vector<InstanceId> left = s.batches.at(old_key).members;
  std::erase(left, id);
  return s.rebuild(old_key, left, {});
}

Result<SimParams> ClothWorld::params(InstanceId id) const {
  auto inst = impl_->find(id);
  if (!inst) return inst.error();
  return (*inst)->params;
}

void ClothWorld::record_step(VkCommandBuffer cmd) { record_steps(cmd, 1); }

void ClothWorld::record_steps(VkCommandBuffer cmd, std::uint32_t steps) {
  for (auto& [key, entry] : impl_->batches) {
    const std::uint64_t before = entry.solver->dispatches;
    entry.solver->record(cmd, steps);
    impl_->dispatches += entry.solver->dispatches - before;
  }
}

void ClothWorld::record_barrier_to(VkCommandBuffer cmd, VkPipelineStageFlags dst_stage, VkAccessFlags dst_access) const {
  barriers::after_steps(impl_->ctx->vk, cmd, dst_stage, dst_access);
}

Result<void> ClothWorld::simulate(std::uint64_t steps, std::uint32_t steps_per_submit) {
  if (steps_per_submit == 0) return make_error(ErrorCode::invalid_argument, "steps_per_submit must be > 0");
  Impl& s = *impl_;
  for (std::uint64_t done = 0; done < steps;) {
    const auto k = static_cast<std::uint32_t>(std::min<std::uint64_t>(steps - done, steps_per_submit));
    VKCLOTH_TRY(s.submit_and_wait([&](VkCommandBuffer c) {
      record_steps(c, k);
      barriers::after_steps(s.ctx->vk, c, VK_PIPELINE_STAGE_HOST_BIT, VK_ACCESS_HOST_READ_BIT); // flags read by the host
    }));
    done += k;
    VKCLOTH_TRY(s.divergence());
  }
  return {};
}

Result<void> ClothWorld::check_divergence() {
  Impl& s = *impl_;
  VKCLOTH_TRY(s.submit_and_wait([&](VkCommandBuffer c) { barriers::before_readback(s.ctx->vk, c); }));
  return s.divergence();
}

Result<std::vector<glm::vec3>> ClothWorld::positions(InstanceId id) {
  auto inst = impl_->find(id);
  if (!inst) return inst.error();
  Impl::Batch& b = *(*inst)->batch;
  return b.read_vec3(b.pos[b.current()], (*inst)->slot);
}
Result<std::vector<glm::vec3>> ClothWorld::velocities(InstanceId id) {
  auto inst = impl_->find(id);
  if (!inst) return inst.error();
  return (*inst)->batch->read_vec3((*inst)->batch->vel, (*inst)->slot);
}
Result<std::vector<glm::vec3>> ClothWorld::normals(InstanceId id) {
  auto inst = impl_->find(id);
  if (!inst) return inst.error();
  return (*inst)->batch->read_vec3((*inst)->batch->normal, (*inst)->slot);
}

Result<InstanceBuffers> ClothWorld::buffers(InstanceId id) const {
  auto inst = impl_->find(id);
  if (!inst) return inst.error();
  const Impl::Batch& b = *(*inst)->batch;
  InstanceBuffers out;
  out.positions = b.pos[b.current()].buffer;
  out.normals = b.normal.buffer;
  out.uvs = b.uv.buffer;
  out.indices = b.indices.buffer;
  out.index_count = b.index_count;
  out.offset = b.slot_offset((*inst)->slot);
  out.count = b.count;
  out.nx = b.nx;
  out.ny = b.ny;
  return out;
}

std::uint64_t ClothWorld::step_index(InstanceId id) const {
  auto inst = impl_->find(id);
  return inst ? (*inst)->batch->slots[(*inst)->slot].step : 0;
}

std::size_t ClothWorld::batch_count() const { return impl_->batches.size(); }

std::uint64_t ClothWorld::dispatches_recorded() const { return impl_->dispatches; }

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
