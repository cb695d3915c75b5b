// SPDX-License-Identifier: MIT
// What a host names whichever world steps its cloths (vkcloth::CpuWorld, cpu_world.hpp, or
// vkcloth::gpu::ClothWorld, gpu/world.hpp): an instance's handle and its optional initial state.
// No Vulkan here: a CPU-only host includes this and cpu_world.hpp.
#pragma once

#include <cstdint>
#include <vector>

#include <glm/vec3.hpp>

#include "vkcloth/glm_abi.hpp"

namespace vkcloth {

/// An instance's handle; never reused within one world.
using InstanceId = std::uint64_t;

/// Optional initial state of an instance (instead of the topology's particle positions and
/// velocities); each vector is empty (topology's value) or has one entry per particle. Pinned
/// particles start with zero velocity whatever `velocities` says, as from the topology.
struct InitialState {
  std::vector<glm::dvec3> positions;
  std::vector<glm::dvec3> velocities;
};

} // namespace vkcloth
