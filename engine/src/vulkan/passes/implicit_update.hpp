// SPDX-License-Identifier: MIT
// Implicit Euler's update of a substep (batches of one instance): ImplicitGpu, the linearised
// backward Euler system and its CG on the GPU (implicit_gpu.hpp), made with the batch. Declared
// here, unlike the other passes, because the batch reports its last solve (GpuSolver::last_solve).
#pragma once

#include <memory>

#include "implicit_gpu.hpp"
#include "pass.hpp"

namespace vkcloth::gpu {

class ImplicitUpdate final : public Pass {
public:
  const char* name() const override { return "implicit update"; }
  bool active(const SolverBatch& b) const override;
  Result<void> prepare(SolverBatch& b) override;
  Result<void> write_sets(const SolverBatch& b) override;
  std::uint32_t record(const SolverBatch& b, PassFrame& f) override;
  /// The last completed solve (valid once the recorded work finished); empty before the first.
  SolveStats stats() const { return gpu_ ? gpu_->stats() : SolveStats{}; }
  bool one_workgroup() const { return gpu_ && gpu_->one_workgroup(); }

private:
  std::unique_ptr<ImplicitGpu> gpu_;
};

} // namespace vkcloth::gpu
