// SPDX-License-Identifier: MIT
// GpuSolver: a ClothWorld of one instance (world_impl.hpp). Every step, readback and rebuild is
// the world's and its batch's (solver_batch.cpp); this file only maps the single-cloth API onto
// them: the instance's own divergence error (without the world's "cloth instance N" prefix),
// its buffers by index, the forces and timings the world does not expose.
#include "internal/resources.hpp"

#include <memory>
#include <utility>

#include "internal/barriers.hpp"
#include "passes/implicit_gpu.hpp"
#include "vkcloth/gpu/gpu_solver.hpp"
#include "vkcloth/gpu/testing.hpp"
#include "world_impl.hpp"

namespace vkcloth::gpu {

struct GpuSolver::Impl {
  ClothWorld world;
  InstanceId id = 0;
  // The world's entry of the one instance: std::map nodes never move, and the instance is never
  // removed, so no lookup per call (record_draw, hold, readbacks query it every frame).
  const ClothWorld::Impl::Instance* inst = nullptr;

  ClothWorld::Impl& w() const { return detail::Access::impl(world); }
  const ClothWorld::Impl::Instance& instance() const { return *inst; }
  SolverBatch& batch() const { return *instance().batch; }
  std::uint32_t slot() const { return instance().slot; }
  const std::optional<Error>& diverged() const { return batch().slot(slot()).diverged; }
  /// `r`, or the instance's own divergence error when it diverged.
  Result<void> own_error(Result<void> r) const {
    if (const auto& d = diverged())
      return *d;
    return r;
  }
};

Result<GpuSolver> GpuSolver::create(Context& context, std::shared_ptr<const ClothTopology> topology,
                                    SimParams params, const GpuSolverOptions& options) {
  return testing::create_solver(context, std::move(topology), std::move(params), options);
}

Result<GpuSolver> GpuSolver::create(Context& context, const ParticleSystem& system, SimParams params,
                                    const GpuSolverOptions& options) {
  return testing::create_solver(context, system, std::move(params), options);
}

Result<GpuSolver> testing::create_solver(Context& context, const ParticleSystem& system, SimParams params,
                                         const GpuSolverOptions& options, const SolverKnobs& knobs) {
  // Parameters first, as before topologies: their errors take precedence over the system's.
  VKCLOTH_TRY(params.validate());
  auto topology = ClothTopology::create(system);
  if (!topology)
    return topology.error();
  return create_solver(context, std::move(*topology), std::move(params), options, knobs);
}

Result<GpuSolver> testing::create_solver(Context& context, std::shared_ptr<const ClothTopology> topology,
                                         SimParams params, const GpuSolverOptions& options,
                                         const SolverKnobs& knobs) {
  WorldOptions wo;
  wo.solver = options;
  auto world = create_world(context, std::move(wo), knobs);
  if (!world)
    return world.error();
  // The world keeps the topology (for rebuilds when the integrator changes).
  auto id = world->add(std::move(topology), std::move(params));
  if (!id)
    return id.error();
  auto impl = std::make_unique<GpuSolver::Impl>(GpuSolver::Impl{std::move(*world), *id, nullptr});
  impl->inst = &impl->w().instances.at(*id);
  return detail::Access::wrap<GpuSolver>(std::move(impl));
}

GpuSolver::GpuSolver(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
GpuSolver::GpuSolver(GpuSolver&&) noexcept = default;
GpuSolver& GpuSolver::operator=(GpuSolver&&) noexcept = default;
GpuSolver::~GpuSolver() = default;

Result<void> GpuSolver::set_params(SimParams params) {
  return impl_->world.set_params(impl_->id, std::move(params));
}
Result<void> GpuSolver::set_pin_targets(std::span<const PinTarget> targets) {
  return impl_->world.set_pin_targets(impl_->id, targets);
}
Result<void> GpuSolver::teleport(const RigidJump& jump) {
  return impl_->world.teleport(impl_->id, jump);
}
const SimParams& GpuSolver::params() const {
  return impl_->instance().params;
}

void GpuSolver::record_steps(VkCommandBuffer cmd, std::uint32_t steps) {
  impl_->world.record_steps(cmd, steps);
}
void GpuSolver::record_release(VkCommandBuffer cmd, const QueueTransfer& transfer) const {
  impl_->world.record_release(cmd, transfer);
}
void GpuSolver::record_acquire(VkCommandBuffer cmd, const QueueTransfer& transfer) const {
  impl_->world.record_acquire(cmd, transfer);
}
Result<void> GpuSolver::record_steps(VkCommandBuffer cmd, std::uint32_t steps, const StepParams& step) {
  VKCLOTH_TRY(impl_->world.set_step_params(impl_->id, step));
  impl_->world.record_steps(cmd, steps);
  return {};
}
void GpuSolver::record_step(VkCommandBuffer cmd) {
  impl_->world.record_steps(cmd, 1);
}

void GpuSolver::record_barrier_to(VkCommandBuffer cmd, VkPipelineStageFlags dst_stage,
                                  VkAccessFlags dst_access) const {
  impl_->world.record_barrier_to(cmd, dst_stage, dst_access);
}

Result<void> GpuSolver::simulate(std::uint64_t steps, std::uint32_t steps_per_submit) {
  if (const auto& d = impl_->diverged())
    return *d;
  return impl_->own_error(impl_->w().simulate(steps, steps_per_submit));
}

Result<void> GpuSolver::check_divergence() {
  if (const auto& d = impl_->diverged())
    return *d;
  return impl_->own_error(impl_->w().check_divergence());
}

Result<std::vector<glm::vec3>> GpuSolver::positions() {
  return impl_->world.positions(impl_->id);
}
Result<std::vector<glm::vec3>> GpuSolver::velocities() {
  return impl_->world.velocities(impl_->id);
}
Result<std::vector<glm::vec3>> GpuSolver::normals() {
  return impl_->world.normals(impl_->id);
}
Result<std::vector<glm::vec3>> GpuSolver::forces() {
  return impl_->batch().read(SolverBatch::Field::forces, impl_->slot());
}
const std::vector<glm::vec2>& GpuSolver::uvs() const {
  return impl_->batch().uvs();
}
const std::shared_ptr<const ClothTopology>& GpuSolver::topology() const {
  return impl_->instance().topology;
}

std::uint64_t GpuSolver::step_index() const {
  return impl_->batch().slot(impl_->slot()).step;
}
double GpuSolver::time() const {
  return impl_->batch().slot(impl_->slot()).time;
}
std::uint32_t GpuSolver::particle_count() const {
  return impl_->batch().particle_count();
}
std::uint32_t GpuSolver::current_position_index() const {
  return impl_->batch().current_position_index();
}
VkBuffer GpuSolver::position_buffer(std::uint32_t index) const {
  return impl_->batch().position_buffer(index);
}
VkBuffer GpuSolver::current_position_buffer() const {
  return buffers().positions;
}
VkBuffer GpuSolver::velocity_buffer() const {
  return impl_->batch().velocity_buffer();
}
VkBuffer GpuSolver::normal_buffer() const {
  return buffers().normals;
}
VkBuffer GpuSolver::uv_buffer() const {
  return buffers().uvs;
}
SolveStats GpuSolver::last_solve() const {
  return impl_->batch().last_solve();
}
bool GpuSolver::implicit_one_workgroup() const {
  return impl_->batch().implicit_one_workgroup();
}
double GpuSolver::last_gpu_ms() const {
  return impl_->w().last_ms;
}
bool GpuSolver::uses_staging() const {
  return impl_->batch().uses_staging();
}
InstanceBuffers GpuSolver::buffers() const {
  return impl_->batch().buffers(impl_->slot());
}

} // namespace vkcloth::gpu

namespace vkcloth::gpu::testing {

Result<std::vector<float>> read_vertices(GpuSolver& solver) {
  const GpuSolver::Impl& s = detail::Access::impl(solver);
  return s.batch().read_vertices(s.slot());
}

} // namespace vkcloth::gpu::testing
