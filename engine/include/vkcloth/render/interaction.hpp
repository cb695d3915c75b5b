// SPDX-License-Identifier: MIT
// Interaction with a running GpuSolver from a viewer: holding one particle where the mouse is
// (the report's "hand lifting the cloth"), without a CPU round trip of the state.
#pragma once

#include <cstdint>

#include <glm/vec3.hpp>
#include <vulkan/vulkan_core.h>

#include "vkcloth/gpu/context.hpp"
#include "vkcloth/gpu/gpu_solver.hpp"

namespace vkcloth::render {

/// Records, into the caller's command buffer: a barrier after every earlier access of the
/// solver's buffers, vkCmdUpdateBuffer of `particle`'s entry in the CURRENT positions buffer to
/// `position` and of its velocity to zero, then a barrier making those writes visible to the
/// next record_steps() and to vertex reads. Record it before the frame's steps; the particle
/// then moves freely during those steps and is put back by the next call. Out-of-range indices
/// are ignored.
void record_hold_particle(const gpu::Context& context, VkCommandBuffer cmd, const gpu::GpuSolver& solver,
                          std::uint32_t particle, glm::vec3 position);

} // namespace vkcloth::render
