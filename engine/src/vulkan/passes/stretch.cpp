// SPDX-License-Identifier: MIT
// Stretch control after a substep's update (the tethers before these: finish.cpp). Provot's
// sweeps: strain_links.comp, one dispatch per colour of the strain links (a colour's links share
// no particle), the most sweeps any instance asks for. The fast projection: StrainProjectionGpu
// (strain_project.comp, its own buffers and sets), made when an instance first asks for it.
#include <algorithm>
#include <memory>
#include <tuple>

#include "internal/barriers.hpp"
#include "../batch_limits.hpp"
#include "../solver_batch.hpp"
#include "strain_projection_gpu.hpp"
#include "pass.hpp"
#include "state_set.hpp"
#include "vkcloth/shaders/strain_links_storage_comp_spv.hpp"
#include "vkcloth/shaders/strain_links_texel_comp_spv.hpp"

namespace vkcloth::gpu {

namespace {

constexpr ShaderSource kStrainLinks{"strain_links.comp", spirv::strain_links_texel_comp_spv,
                                    spirv::strain_links_storage_comp_spv, &kStateBindings};

/// The most Provot sweeps an instance asks for (0: none uses them).
std::uint32_t provot_sweeps(const SolverBatch& b) {
  std::uint32_t sweeps = 0;
  for (const SolverBatch::Slot& s : b.instance_slots())
    if (s.params.stretch_limit.provot())
      sweeps = std::max(sweeps, s.params.stretch_limit.iterations);
  return sweeps;
}

/// Whether an instance sweeps in `chains` order (else: in colours).
bool any_order(const SolverBatch& b, bool chains) {
  const auto& slots = b.instance_slots();
  return std::any_of(slots.begin(), slots.end(), [&](const SolverBatch::Slot& s) {
    return s.params.stretch_limit.provot() && s.params.stretch_limit.chains() == chains;
  });
}

class StrainLinks final : public Pass {
public:
  const char* name() const override { return "Provot's sweeps"; }
  bool active(const SolverBatch& b) const override {
    return provot_sweeps(b) > 0 && b.strain_link_count() > 0;
  }

  Result<void> prepare(SolverBatch& b) override {
    return active(b) ? b.ensure_pipeline(pipeline_, kStrainLinks) : Result<void>{};
  }

  std::uint32_t record(const SolverBatch& b, PassFrame& f) override {
    const auto& v = b.vk();
    // Set 1 of the positions being written: the sweeps read positions[write] through its texel view.
    b.bind_state(f.cmd, f.read, false, f.read ^ 1u);
    v.vkCmdBindPipeline(f.cmd, VK_PIPELINE_BIND_POINT_COMPUTE, pipeline_);
    auto pc = shared::push_from<shared::StrainLinksPush>(*f.pc);
    const auto colours = b.strain_colour_offsets();
    const std::uint32_t sweeps = provot_sweeps(b);
    std::uint32_t dispatches = 0;
    auto dispatch = [&](std::uint32_t first, std::uint32_t count, std::uint32_t chain_links) {
      pc.link_first = first;
      pc.link_count = count;
      pc.chain_links = chain_links;
      b.push_state(f.cmd, &pc);
      barriers::dispatch_to_dispatch(v, f.cmd); // the previous pass, colour or chains' pass -> this one
      b.dispatch_items(f.cmd, count);
      ++dispatches;
    };
    // Chain order: the rows, then the columns (SolverBatch::ensure_strain_chains put their links
    // after the coloured ones), each forward, then back in a dispatch of its own: the pass back
    // reads through the texel views what the pass forward wrote.
    const StrainChainShape chains = b.topology().strain_chain_shape();
    const bool by_colour = any_order(b, false), by_chain = any_order(b, true);
    const std::uint32_t row_first = std::uint32_t(b.strain_link_count());
    const std::uint32_t column_first = row_first + chains.rows * chains.row_links;
    for (std::uint32_t sweep = 0; sweep < sweeps; ++sweep) {
      pc.stage = sweep;
      for (std::size_t k = 0; by_colour && k + 1 < colours.size(); ++k)
        dispatch(colours[k], colours[k + 1] - colours[k], 0u);
      for (const auto& [first, count, links] :
           {std::tuple{row_first, chains.rows, chains.row_links},
            std::tuple{column_first, chains.columns, chains.column_links}})
        for (const std::uint32_t direction : {0u, VKCLOTH_CHAIN_BACKWARD})
          if (by_chain && count > 0)
            dispatch(first, count, links | direction);
    }
    return dispatches;
  }

private:
  VkPipeline pipeline_ = VK_NULL_HANDLE;
};

class StrainProjection final : public Pass {
public:
  const char* name() const override { return "fast projection"; }
  bool active(const SolverBatch& b) const override { return b.projection_iterations() > 0; }

  // Made when an instance first asks for the fast projection: its buffers (each particle's links
  // uploaded) and its own descriptor sets, which nothing recorded so far uses.
  Result<void> prepare(SolverBatch& b) override {
    if (gpu_ || !active(b))
      return {};
    // Its largest buffer holds two vec4 per strain link of every instance.
    VKCLOTH_TRY(check_buffer(b.context(), storage_limit(b.context(), b.solver_knobs()),
                             "strain projection links", std::uint64_t(b.size()) * b.strain_link_count(), 32));
    auto r = StrainProjectionGpu::create(b.shared_context(), b.topology(), b.size(),
                                         !b.solver_knobs().force_staging);
    if (!r)
      return r.error();
    const std::vector<std::uint32_t> incidence = StrainProjectionGpu::incidence_data(b.topology());
    const SolverBatch::Upload up[] = {{&(*r)->incidence(), incidence.data(), incidence.size() * 4}};
    VKCLOTH_TRY(b.upload(up));
    VKCLOTH_TRY((*r)->write_sets(b.one_set_inputs()));
    gpu_ = std::move(*r);
    return {};
  }
  Result<void> write_sets(const SolverBatch& b) override {
    return gpu_ ? gpu_->write_sets(b.one_set_inputs()) : Result<void>{};
  }
  std::uint32_t record(const SolverBatch& b, PassFrame& f) override {
    return gpu_->record_substep(f.cmd, f.read, *f.pc, b.projection_iterations());
  }

private:
  std::unique_ptr<StrainProjectionGpu> gpu_;
};

} // namespace

std::unique_ptr<Pass> make_strain_links() {
  return std::make_unique<StrainLinks>();
}
std::unique_ptr<Pass> make_strain_projection() {
  return std::make_unique<StrainProjection>();
}

} // namespace vkcloth::gpu
