// SPDX-License-Identifier: MIT
#include "render_internal.hpp"

#include <glm/vec4.hpp>

#include "internal/barriers.hpp"
#include "vkcloth/render/interaction.hpp"

namespace vkcloth::render {

void record_hold_particle(const gpu::Context& context, VkCommandBuffer cmd, const gpu::GpuSolver& solver,
                          std::uint32_t particle, glm::vec3 position) {
  if (particle >= solver.particle_count())
    return;
  const auto& v = gpu::context_impl(context)->vk;
  gpu::barriers::before_host_edit(v, cmd);
  const glm::vec4 p(position, 1.0f), zero(0.0f);
  const VkDeviceSize at = VkDeviceSize(particle) * gpu::GpuSolver::stride;
  v.vkCmdUpdateBuffer(cmd, solver.current_position_buffer(), at, sizeof(p), &p);
  v.vkCmdUpdateBuffer(cmd, solver.velocity_buffer(), at, sizeof(zero), &zero);
  gpu::barriers::after_host_edit(v, cmd);
}

} // namespace vkcloth::render
