// SPDX-License-Identifier: MIT
#include "implicit_update.hpp"

#include <algorithm>

#include <fmt/format.h>

#include "../solver_batch.hpp"
#include "vkcloth/gpu/gpu_solver.hpp"

namespace vkcloth::gpu {

bool ImplicitUpdate::active(const SolverBatch& b) const {
  return b.family().integrator == Integrator::implicit_euler;
}

Result<void> ImplicitUpdate::prepare(SolverBatch& b) {
  if (!active(b))
    return {};
  if (!gpu_) {
    using D = GpuSolverOptions::CgDispatch;
    const GpuSolverOptions& options = b.solver_options();
    const std::uint32_t count = b.particle_count();
    std::uint32_t max_degree = 0;
    const auto gather = b.topology().edge_offsets();
    for (std::size_t p = 0; p + 1 < gather.size(); ++p)
      max_degree = std::max(max_degree, gather[p + 1] - gather[p]);
    const std::uint32_t budget = ImplicitGpu::iteration_budget(count, max_degree);
    if (options.cg_dispatch == D::one_workgroup && budget == 0)
      return make_error(
          ErrorCode::unsupported,
          fmt::format("GpuSolverOptions::cg_dispatch = one_workgroup: {} particles with up to {} springs "
                      "each are too many for one workgroup; use automatic or per_iteration",
                      count, max_degree));
    // automatic: one workgroup only where it was measured to win (lavapipe, docs/performance.md);
    // a GPU runs a single workgroup on one of its many compute units.
    const bool cpu_device = b.context().properties.deviceType == VK_PHYSICAL_DEVICE_TYPE_CPU;
    const bool one_workgroup = options.cg_dispatch == D::one_workgroup ||
                               (options.cg_dispatch == D::automatic && cpu_device && budget > 0 &&
                                count <= implicit_one_workgroup_max_particles);
    auto r = ImplicitGpu::create(b.shared_context(), count, b.edge_count(), b.dispatch_x(), b.dispatch_y(),
                                 one_workgroup ? budget : 0, !b.solver_knobs().force_staging);
    if (!r)
      return r.error();
    gpu_ = std::move(*r);
    VKCLOTH_TRY(gpu_->write_sets(b.implicit_inputs()));
  }
  // Its FORCE and FINISH passes: CSR gather (no stencil), every normal path as the flags say.
  const std::uint32_t types = b.collider_types();
  return gpu_->ensure_collider_passes(types, b.state_constants(true, types, true));
}

Result<void> ImplicitUpdate::write_sets(const SolverBatch& b) {
  return gpu_ ? gpu_->write_sets(b.implicit_inputs()) : Result<void>{};
}

std::uint32_t ImplicitUpdate::record(const SolverBatch& b, PassFrame& f) {
  return gpu_->record_substep(f.cmd, f.read, *f.pc, b.family(), b.collider_types(), f.first);
}

} // namespace vkcloth::gpu
