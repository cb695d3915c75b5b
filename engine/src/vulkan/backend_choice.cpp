// SPDX-License-Identifier: MIT
#include "vkcloth/gpu/backend_choice.hpp"

#include <fmt/format.h>

namespace vkcloth::gpu {

const char* to_string(Backend backend) {
  return backend == Backend::cpu ? "cpu" : "vulkan";
}

BackendChoice choose_backend(VkPhysicalDeviceType type, std::string_view device_name) {
  // The ratio is `vkcloth bench` on lavapipe (docs/performance.md "Backend auto"): the CPU solver's SIMD
  // rows against the same kernel compiled by llvmpipe, on the same cores.
  if (type == VK_PHYSICAL_DEVICE_TYPE_CPU)
    return {Backend::cpu,
            fmt::format("{} is a CPU implementation of Vulkan (lavapipe): its compute shaders run on the "
                        "same cores as the CPU solver, which steps the cloth 8-18x faster there, so auto "
                        "simulates on the CPU and uploads positions and normals for each frame",
                        device_name)};
  const char* kind = type == VK_PHYSICAL_DEVICE_TYPE_DISCRETE_GPU     ? "a discrete GPU"
                     : type == VK_PHYSICAL_DEVICE_TYPE_INTEGRATED_GPU ? "an integrated GPU"
                     : type == VK_PHYSICAL_DEVICE_TYPE_VIRTUAL_GPU    ? "a virtual GPU"
                                                                      : "not a CPU device";
  return {Backend::vulkan, fmt::format("{} is {}: the simulation runs on it and is drawn from its own "
                                       "buffers, nothing crosses the bus",
                                       device_name, kind)};
}

BackendChoice choose_backend(const Context& context) {
  return choose_backend(context.device_type(), context.device_name());
}

} // namespace vkcloth::gpu
