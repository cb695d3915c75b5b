// SPDX-License-Identifier: MIT
// Which solver to draw from where the user does not choose (`--backend auto` of `vkcloth render`,
// `view` and the samples): the Vulkan solver on a GPU, the CPU reference solver on a CPU
// implementation of Vulkan (lavapipe), where compute shaders run on the same cores as the CPU
// solver, only slower. The reason is a sentence for a person (`vkcloth devices` prints it).
#pragma once

#include <string>
#include <string_view>

#include <vulkan/vulkan_core.h>

#include "vkcloth/gpu/context.hpp"

namespace vkcloth::gpu {

/// Where the simulation runs.
enum class Backend {
  cpu, ///< CpuSolver<float> (a CpuWorld of one cloth in DrawnCloth); its positions and normals are uploaded
       ///< for drawing each frame
  vulkan, ///< GpuSolver; drawn straight from its buffers, nothing crosses the bus
};

/// "cpu" | "vulkan" (the `--backend` names).
const char* to_string(Backend backend);

/// A backend and why it was chosen.
struct BackendChoice {
  Backend backend = Backend::vulkan;
  std::string reason;
};

/// cpu for VK_PHYSICAL_DEVICE_TYPE_CPU, vulkan for every other type (discrete, integrated,
/// virtual, other); `device_name` goes into the reason.
BackendChoice choose_backend(VkPhysicalDeviceType type, std::string_view device_name);
/// choose_backend(context.device_type(), context.device_name()).
BackendChoice choose_backend(const Context& context);

} // namespace vkcloth::gpu
