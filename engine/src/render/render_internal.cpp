// SPDX-License-Identifier: MIT
#include "render_internal.hpp"

#include <vector>

namespace vkcloth::render::detail {

bool queue_has_graphics(gpu::Context::Impl& ctx) {
  std::uint32_t n = 0;
  ctx.fi.vkGetPhysicalDeviceQueueFamilyProperties(ctx.physical_device, &n, nullptr);
  std::vector<VkQueueFamilyProperties> qf(n);
  ctx.fi.vkGetPhysicalDeviceQueueFamilyProperties(ctx.physical_device, &n, qf.data());
  return ctx.queue_family < n && (qf[ctx.queue_family].queueFlags & VK_QUEUE_GRAPHICS_BIT);
}

} // namespace vkcloth::render::detail
