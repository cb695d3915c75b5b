// SPDX-License-Identifier: MIT
// The interleaved vertices at the end of a recording (GpuSolverOptions::interleaved_vertices):
// vertices.comp packs the current positions, the normals and the uvs into one Vertex per particle,
// reading POS_IN of the state set whose read index is the current one.
#include <memory>

#include "internal/barriers.hpp"
#include "../solver_batch.hpp"
#include "pass.hpp"
#include "state_set.hpp"
#include "vkcloth/shaders/vertices_comp_spv.hpp"

namespace vkcloth::gpu {

namespace {

constexpr ShaderSource kVertices{"vertices.comp", spirv::vertices_comp_spv, {}, &kStateBindings};

class Vertices final : public Pass {
public:
  const char* name() const override { return "interleaved vertices"; }
  When when() const override { return When::recording_end; }
  bool active(const SolverBatch& b) const override { return b.solver_options().interleaved_vertices; }

  Result<void> prepare(SolverBatch& b) override {
    return active(b) ? b.ensure_pipeline(pipeline_, kVertices) : Result<void>{};
  }

  std::uint32_t record(const SolverBatch& b, PassFrame& f) override {
    const auto& v = b.vk();
    barriers::dispatch_to_dispatch(v, f.cmd); // the last pass's positions and normals -> this pass
    v.vkCmdBindPipeline(f.cmd, VK_PIPELINE_BIND_POINT_COMPUTE, pipeline_);
    b.bind_state(f.cmd, f.read, false, SolverBatch::no_texel_set); // vertices.comp has one (storage) build
    b.push_state(f.cmd, f.pc);
    b.dispatch_particles(f.cmd);
    return 1;
  }

private:
  VkPipeline pipeline_ = VK_NULL_HANDLE;
};

} // namespace

std::unique_ptr<Pass> make_vertices() {
  return std::make_unique<Vertices>();
}

} // namespace vkcloth::gpu
