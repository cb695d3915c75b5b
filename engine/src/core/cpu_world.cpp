// SPDX-License-Identifier: MIT
#include "vkcloth/cpu_world.hpp"

#include <map>
#include <optional>
#include <utility>

#include <fmt/format.h>

namespace vkcloth {

struct CpuWorld::Impl {
  struct Instance {
    CpuSolver<float> solver;
    std::optional<Error> diverged; // its first blow-up; it is not stepped again
  };

  CpuWorldOptions options;
  std::map<InstanceId, Instance> instances; // id order = stepping order
  InstanceId next = 1;

  Result<Instance*> find(InstanceId id) {
    const auto it = instances.find(id);
    if (it == instances.end())
      return make_error(ErrorCode::invalid_argument, fmt::format("no cloth instance with id {}", id));
    return &it->second;
  }
  Result<const Instance*> find(InstanceId id) const {
    const auto it = instances.find(id);
    if (it == instances.end())
      return make_error(ErrorCode::invalid_argument, fmt::format("no cloth instance with id {}", id));
    return &it->second;
  }

  /// The first diverged instance's error, naming it (as ClothWorld's).
  Result<void> divergence() const;
};

namespace {

/// `e` with its message prefixed by the instance (ClothWorld's wording).
Error naming(InstanceId id, Error e) {
  e.message = fmt::format("cloth instance {}: {}", id, e.message);
  return e;
}

using Field = std::span<const glm::vec3> (CpuSolver<float>::*)() const;

Result<std::vector<glm::vec3>> copy_of(const CpuWorld::Impl& world, InstanceId id, Field field) {
  auto inst = world.find(id);
  if (!inst)
    return inst.error();
  const std::span<const glm::vec3> v = ((*inst)->solver.*field)();
  return std::vector<glm::vec3>(v.begin(), v.end());
}

/// Starts `solver` from `initial` (sizes already checked): one set_particle per particle, which
/// converts to float as CpuSolver::create converts the topology's state, and zeroes the velocity
/// of pinned particles.
Result<void> apply_initial_state(CpuSolver<float>& solver, const InitialState& initial) {
  if (initial.positions.empty() && initial.velocities.empty())
    return {};
  const auto n = static_cast<std::uint32_t>(solver.positions().size());
  for (std::uint32_t p = 0; p < n; ++p) {
    const glm::vec3 x = initial.positions.empty() ? solver.positions()[p] : glm::vec3(initial.positions[p]);
    const glm::vec3 v =
        initial.velocities.empty() ? solver.velocities()[p] : glm::vec3(initial.velocities[p]);
    if (auto r = solver.set_particle(p, x, v); !r) {
      Error e = r.error();
      e.message = "CpuWorld::add: initial state: " + e.message;
      return e;
    }
  }
  return {};
}

} // namespace

Result<void> CpuWorld::Impl::divergence() const {
  for (const auto& [id, inst] : instances)
    if (inst.diverged)
      return naming(id, *inst.diverged);
  return {};
}

Result<CpuWorld> CpuWorld::create(CpuWorldOptions options) {
  if (options.solver.threads > 256)
    return make_error(ErrorCode::invalid_argument,
                      fmt::format("threads must be at most 256, got {}", options.solver.threads));
  auto impl = std::make_unique<Impl>();
  impl->options = options;
  return CpuWorld(std::move(impl));
}

CpuWorld::CpuWorld(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
CpuWorld::CpuWorld(CpuWorld&&) noexcept = default;
CpuWorld& CpuWorld::operator=(CpuWorld&&) noexcept = default;
CpuWorld::~CpuWorld() = default;

Result<InstanceId> CpuWorld::add(std::shared_ptr<const ClothTopology> topology, SimParams params,
                                 const InitialState& initial) {
  if (!topology)
    return make_error(ErrorCode::invalid_argument, "CpuWorld::add: the topology is null");
  const std::size_t n = topology->size();
  if (!initial.positions.empty() && initial.positions.size() != n)
    return make_error(
        ErrorCode::invalid_argument,
        fmt::format("CpuWorld::add: initial positions has {} entries, the topology {} particles",
                    initial.positions.size(), n));
  if (!initial.velocities.empty() && initial.velocities.size() != n)
    return make_error(
        ErrorCode::invalid_argument,
        fmt::format("CpuWorld::add: initial velocities has {} entries, the topology {} particles",
                    initial.velocities.size(), n));
  auto solver = CpuSolver<float>::create(std::move(topology), std::move(params), impl_->options.solver);
  if (!solver)
    return solver.error();
  VKCLOTH_TRY(apply_initial_state(*solver, initial));
  const InstanceId id = impl_->next++;
  impl_->instances.emplace(id, Impl::Instance{std::move(*solver), std::nullopt});
  return id;
}

Result<void> CpuWorld::remove(InstanceId id) {
  VKCLOTH_TRY(impl_->find(id));
  impl_->instances.erase(id);
  return {};
}

Result<void> CpuWorld::set_params(InstanceId id, SimParams params) {
  auto inst = impl_->find(id);
  if (!inst)
    return inst.error();
  return (*inst)->solver.set_params(std::move(params));
}

Result<void> CpuWorld::set_step_params(InstanceId id, const StepParams& step) {
  auto inst = impl_->find(id);
  if (!inst)
    return inst.error();
  return (*inst)->solver.set_params(step.applied_to((*inst)->solver.params()));
}

Result<void> CpuWorld::set_collider_pose(InstanceId id, std::size_t collider, const ColliderPose& pose) {
  auto inst = impl_->find(id);
  if (!inst)
    return inst.error();
  auto posed = with_collider_pose((*inst)->solver.params(), collider, pose);
  if (!posed)
    return posed.error();
  return (*inst)->solver.set_params(std::move(*posed));
}

Result<void> CpuWorld::set_pin_targets(InstanceId id, std::span<const PinTarget> targets) {
  auto inst = impl_->find(id);
  if (!inst)
    return inst.error();
  return (*inst)->solver.set_pin_targets(targets);
}

Result<void> CpuWorld::teleport(InstanceId id, const RigidJump& jump) {
  auto inst = impl_->find(id);
  if (!inst)
    return inst.error();
  return (*inst)->solver.teleport(jump);
}

Result<SimParams> CpuWorld::params(InstanceId id) const {
  auto inst = impl_->find(id);
  if (!inst)
    return inst.error();
  return (*inst)->solver.params();
}

Result<void> CpuWorld::simulate(std::uint64_t steps, std::uint32_t /*steps_per_submit*/) {
  // A step fails only on a blow-up (CpuSolver::step), which leaves the state after the bad step:
  // the instance stays there, the others go on.
  for (auto& [id, inst] : impl_->instances)
    if (!inst.diverged)
      if (auto r = inst.solver.run(steps); !r)
        inst.diverged = r.error();
  return impl_->divergence();
}

Result<void> CpuWorld::check_divergence() {
  return impl_->divergence();
}

Result<std::vector<glm::vec3>> CpuWorld::positions(InstanceId id) {
  return copy_of(*impl_, id, &CpuSolver<float>::positions);
}
Result<std::vector<glm::vec3>> CpuWorld::velocities(InstanceId id) {
  return copy_of(*impl_, id, &CpuSolver<float>::velocities);
}
Result<std::vector<glm::vec3>> CpuWorld::normals(InstanceId id) {
  return copy_of(*impl_, id, &CpuSolver<float>::normals);
}

std::uint64_t CpuWorld::step_index(InstanceId id) const {
  const CpuSolver<float>* s = solver(id);
  return s ? s->step_index() : 0;
}

std::shared_ptr<const ClothTopology> CpuWorld::topology(InstanceId id) const {
  const CpuSolver<float>* s = solver(id);
  return s ? s->topology() : nullptr;
}

std::vector<InstanceId> CpuWorld::instances() const {
  std::vector<InstanceId> ids;
  for (const auto& [id, inst] : impl_->instances)
    ids.push_back(id);
  return ids;
}

std::size_t CpuWorld::size() const {
  return impl_->instances.size();
}

const CpuSolver<float>* CpuWorld::solver(InstanceId id) const {
  const auto it = impl_->instances.find(id);
  return it == impl_->instances.end() ? nullptr : &it->second.solver;
}

Result<void> CpuWorld::set_particle(InstanceId id, std::uint32_t index, glm::vec3 position,
                                    glm::vec3 velocity) {
  auto inst = impl_->find(id);
  if (!inst)
    return inst.error();
  if (auto r = (*inst)->solver.set_particle(index, position, velocity); !r)
    return naming(id, r.error());
  return {};
}

} // namespace vkcloth
