// SPDX-License-Identifier: MIT
// Self-collision after a substep's update and stretch control: SelfCollisionGpu (the spatial
// hash and the Jacobi passes of self_collision.comp, its own buffers, sets and parameters), made
// when an instance first turns it on.
#include <algorithm>
#include <cstring>
#include <limits>
#include <memory>
#include <vector>

#include "internal/kernel.hpp"
#include "../batch_limits.hpp"
#include "self_collision_gpu.hpp"
#include "../solver_batch.hpp"
#include "pass.hpp"

namespace vkcloth::gpu {

namespace {

class SelfCollisionPass final : public Pass {
public:
  const char* name() const override { return "self-collision"; }
  bool active(const SolverBatch& b) const override { return b.self_iterations() > 0 || b.any_self_energy(); }

  // Its buffers (the rest positions uploaded, the counts zeroed) and descriptor sets, which nothing
  // recorded so far uses; its parameters straight into the mapped buffer (no recorded work reads it).
  Result<void> prepare(SolverBatch& b) override {
    if (gpu_ || !active(b))
      return {};
    const std::uint32_t count = b.particle_count();
    // Its largest buffer holds two vec4 per particle of every instance (a move and a velocity change).
    VKCLOTH_TRY(check_buffer(b.context(), storage_limit(b.context(), b.solver_knobs()),
                             "self-collision moves", std::uint64_t(b.size()) * count, 32));
    auto r = SelfCollisionGpu::create(b.shared_context(), count, b.size(),
                                      b.context().properties.limits.maxComputeWorkGroupCount[0],
                                      !b.solver_knobs().force_staging, b.buffer_access());
    if (!r)
      return r.error();
    std::vector<shared::vec4> rest(count);
    for (std::uint32_t p = 0; p < count; ++p) { // as CpuSolver<float>::self_collide makes them
      const Particle& q = b.topology().system().particles[p];
      rest[p] = {float(q.position.x), float(q.position.y), float(q.position.z),
                 kernel::inverse_mass(float(q.mass), q.pinned)};
    }
    const float nan = std::numeric_limits<float>::quiet_NaN(); // no list built yet
    const std::vector<shared::vec4> never(std::size_t(count) * b.size(), shared::vec4{nan, nan, nan, nan});
    const SolverBatch::Upload up[] = {
        {&(*r)->rest_positions(), rest.data(), rest.size() * sizeof(shared::vec4)},
        {&(*r)->counts(), nullptr, 0},
        {&(*r)->built(), never.data(), never.size() * sizeof(shared::vec4)},
        {&(*r)->stale(), nullptr, 0}};
    VKCLOTH_TRY(b.upload(up));
    gpu_ = std::move(*r);
    b.set_self_collision(gpu_.get());
    write_params(b, VK_NULL_HANDLE);
    // Only its own new sets: the state sets may be in use by recorded work (set_params).
    return gpu_->write_sets(b.one_set_inputs());
  }

  Result<void> write_sets(const SolverBatch& b) override {
    return gpu_ ? gpu_->write_sets(b.one_set_inputs()) : Result<void>{};
  }

  void write_params(const SolverBatch& b, VkCommandBuffer cmd) override {
    if (!gpu_)
      return;
    std::vector<const SimParams*> params;
    for (const SolverBatch::Slot& s : b.instance_slots())
      params.push_back(&s.params);
    const auto packed = SelfCollisionGpu::packed(params);
    gpu_->set_lists(std::any_of(packed.begin(), packed.end(), [](const shared::SelfParams& p) {
      return p.iterations > 0 && p.half_skin2 > 0.0f && !(p.stiffness > 0.0f); // after the step
    }));
    const std::size_t bytes = packed.size() * sizeof(shared::SelfParams);
    if (cmd)
      b.record_buffer_update(cmd, gpu_->params(), packed.data(), bytes);
    else
      std::memcpy(gpu_->params().mapped, packed.data(), bytes);
  }

  std::uint32_t record(const SolverBatch& b, PassFrame& f) override {
    const std::uint32_t iterations = b.self_iterations(); // 0: every instance's acted in vbd's sweeps
    return iterations ? gpu_->record_substep(f.cmd, f.read, *f.pc, iterations) : 0;
  }

private:
  std::unique_ptr<SelfCollisionGpu> gpu_;
};

} // namespace

std::unique_ptr<Pass> make_self_collision() {
  return std::make_unique<SelfCollisionPass>();
}

} // namespace vkcloth::gpu
