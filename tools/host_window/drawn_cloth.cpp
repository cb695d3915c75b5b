// SPDX-License-Identifier: MIT
#include "vkcloth_host_window/drawn_cloth.hpp"

#include <fmt/format.h>

#include "vkcloth/render/interaction.hpp"

namespace vkcloth::host {

Result<std::optional<gpu::Backend>> parse_backend(std::string_view name) {
  if (name == "auto")
    return std::optional<gpu::Backend>{};
  if (name == "cpu")
    return std::optional<gpu::Backend>{gpu::Backend::cpu};
  if (name == "vulkan")
    return std::optional<gpu::Backend>{gpu::Backend::vulkan};
  return make_error(ErrorCode::invalid_argument,
                    fmt::format("--backend {}: expected auto, cpu or vulkan", name));
}

gpu::BackendChoice resolve_backend(std::optional<gpu::Backend> requested, const gpu::Context& context) {
  if (!requested)
    return gpu::choose_backend(context);
  return {*requested, fmt::format("--backend {} on {}", gpu::to_string(*requested), context.device_name())};
}

Result<DrawnCloth> DrawnCloth::create(gpu::Backend backend, gpu::Context& context,
                                      const ParticleSystem& system, const SimParams& params) {
  DrawnCloth d;
  d.context_ = &context;
  if (backend == gpu::Backend::vulkan) {
    auto s = gpu::GpuSolver::create(context, system, params);
    if (!s)
      return s.error();
    d.gpu_.emplace(std::move(*s));
    return d;
  }
  // Validated before the topology is made, then again by add(): as CpuSolver::create(system, ...).
  SimParams checked = params;
  VKCLOTH_TRY(checked.validate());
  auto topology = ClothTopology::create(system);
  if (!topology)
    return topology.error();
  auto world = CpuWorld::create();
  if (!world)
    return world.error();
  auto id = world->add(*topology, std::move(checked));
  if (!id)
    return id.error();
  auto b = render::HostClothBuffers::create(context, **topology, 2);
  if (!b)
    return b.error();
  d.cpu_.emplace(std::move(*world));
  d.cpu_id_ = *id;
  d.host_.emplace(std::move(*b));
  return d;
}

Result<gpu::InstanceBuffers> DrawnCloth::record_frame(VkCommandBuffer cmd, std::uint32_t steps,
                                                      std::uint32_t slot,
                                                      const std::optional<HeldParticle>& held) {
  if (gpu_) {
    if (held)
      render::record_hold_particle(*context_, cmd, *gpu_, held->index, held->position);
    if (steps)
      gpu_->record_steps(cmd, steps);
    // THE compute -> graphics barrier: this frame's compute writes of positions and normals become
    // visible to the vertex fetch of the draws (VERTEX_INPUT / VERTEX_ATTRIBUTE_READ).
    gpu_->record_barrier_to(cmd, VK_PIPELINE_STAGE_VERTEX_INPUT_BIT, VK_ACCESS_VERTEX_ATTRIBUTE_READ_BIT);
    return gpu_->buffers();
  }
  if (held && held->index < cpu_solver().positions().size())
    if (auto r = cpu_->set_particle(cpu_id_, held->index, held->position, glm::vec3(0.0f)); !r)
      return cpu_error(r.error());
  if (auto r = cpu_->simulate(steps); !r)
    return cpu_error(r.error());
  // Host-coherent writes before the frame's vkQueueSubmit: visible to its draws, no barrier.
  return host_->upload(slot, cpu_solver().positions(), cpu_solver().normals());
}

Result<render::Image> DrawnCloth::render(render::OffscreenTarget& target, render::ClothRenderer& renderer,
                                         const render::Camera& camera, std::uint32_t steps) {
  if (gpu_)
    return target.render(*gpu_, renderer, camera, steps); // draws the solver's colliders as they are
  if (auto r = cpu_->simulate(steps); !r)
    return cpu_error(r.error());
  VKCLOTH_TRY(renderer.set_colliders(cpu_solver().params().colliders)); // where the steps left them
  // Slot 0 every time: render() waits for its submission, so nothing still reads it.
  auto buffers = host_->upload(0, cpu_solver().positions(), cpu_solver().normals());
  if (!buffers)
    return buffers.error();
  return target.render(*buffers, renderer, camera);
}

Result<void> DrawnCloth::simulate(std::uint64_t steps) {
  if (gpu_)
    return gpu_->simulate(steps);
  if (auto r = cpu_->simulate(steps); !r)
    return cpu_error(r.error());
  return {};
}

Result<std::vector<glm::vec3>> DrawnCloth::positions() {
  return gpu_ ? gpu_->positions() : cpu_->positions(cpu_id_);
}

Result<void> DrawnCloth::check_divergence() {
  if (gpu_)
    return gpu_->check_divergence();
  return {}; // the CPU steps returned it
}

Result<void> DrawnCloth::set_params(const SimParams& params) {
  return gpu_ ? gpu_->set_params(params) : cpu_->set_params(cpu_id_, params);
}

const SimParams& DrawnCloth::params() const {
  return gpu_ ? gpu_->params() : cpu_solver().params();
}

const std::shared_ptr<const ClothTopology>& DrawnCloth::topology() const {
  return gpu_ ? gpu_->topology() : cpu_solver().topology();
}

std::uint64_t DrawnCloth::step_index() const {
  return gpu_ ? gpu_->step_index() : cpu_solver().step_index();
}

double DrawnCloth::time() const {
  return gpu_ ? gpu_->time() : cpu_solver().time();
}

Error DrawnCloth::cpu_error(const Error& e) const {
  Error out = e;
  const std::string prefix = fmt::format("cloth instance {}: ", cpu_id_);
  if (out.message.starts_with(prefix))
    out.message.erase(0, prefix.size());
  return out;
}

} // namespace vkcloth::host
