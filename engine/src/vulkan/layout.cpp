// SPDX-License-Identifier: MIT
// The per-device layout (vkcloth/gpu/layout.hpp): the one place that decides how the solver's
// shaders read their buffers and how large their workgroups are.
#include "internal/vk_internal.hpp"

#include <algorithm>

#include <fmt/format.h>

#include "internal/pipelines.hpp"
#include "vkcloth/gpu/layout.hpp"
#include "kernel/layout/vkcloth_shared.h"

namespace vkcloth::gpu {

const char* to_string(BufferAccess access) {
  switch (access) {
  case BufferAccess::automatic:
    return "auto";
  case BufferAccess::texel_views:
    return "texel";
  case BufferAccess::storage_buffers:
    return "storage";
  }
  return "?";
}

std::optional<BufferAccess> parse_buffer_access(std::string_view text) {
  for (BufferAccess a : {BufferAccess::automatic, BufferAccess::texel_views, BufferAccess::storage_buffers})
    if (text == to_string(a))
      return a;
  return std::nullopt;
}

DeviceLayout choose_layout(const VkPhysicalDeviceProperties& properties, std::uint32_t subgroup_size) {
  const VkPhysicalDeviceLimits& lim = properties.limits;
  const std::uint32_t max_size = std::min(lim.maxComputeWorkGroupSize[0], lim.maxComputeWorkGroupInvocations);
  DeviceLayout out;
  out.subgroup_size = subgroup_size;
  if (properties.deviceType == VK_PHYSICAL_DEVICE_TYPE_CPU) {
    // Texel views: docs/performance.md "lavapipe (llvmpipe) notes".
    out.access = BufferAccess::texel_views;
    out.workgroup_size = std::min<std::uint32_t>(VKCLOTH_WORKGROUP_SIZE, max_size);
    out.reason = fmt::format("CPU device: texel views (llvmpipe vectorises texel fetches, not storage-buffer "
                             "loads), the compiled workgroup of {}",
                             out.workgroup_size);
    return out;
  }
  // A GPU: storage buffers (its ordinary memory path; no texel-unit detour, no texel-count limit),
  // workgroups of whole subgroups, at least VKCLOTH_WORKGROUP_SIZE invocations (enough warps or
  // waves per group to hide latency; every common subgroup size, 8 to 64, divides 64).
  const std::uint32_t sub = subgroup_size ? subgroup_size : 32;
  std::uint32_t size = ((VKCLOTH_WORKGROUP_SIZE + sub - 1) / sub) * sub;
  if (size > max_size) // a subgroup larger than the device's workgroup limit: whole subgroups only
    size = std::max<std::uint32_t>(sub <= max_size ? max_size / sub * sub : max_size, 1);
  out.access = BufferAccess::storage_buffers;
  out.workgroup_size = size;
  out.reason = fmt::format("{} device, subgroups of {}{}: storage buffers, workgroups of {} (a multiple of "
                           "the subgroup, at most {} invocations)",
                           properties.deviceType == VK_PHYSICAL_DEVICE_TYPE_DISCRETE_GPU     ? "discrete"
                           : properties.deviceType == VK_PHYSICAL_DEVICE_TYPE_INTEGRATED_GPU ? "integrated"
                           : properties.deviceType == VK_PHYSICAL_DEVICE_TYPE_VIRTUAL_GPU    ? "virtual"
                                                                                             : "other",
                           sub, subgroup_size ? "" : " (unknown, taken as 32)", size, max_size);
  return out;
}

DeviceLayout device_layout(const Context::Impl& ctx) {
  VkPhysicalDeviceSubgroupProperties subgroup{};
  subgroup.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_SUBGROUP_PROPERTIES;
  // Core in Vulkan 1.1 (the Context requires 1.2); loaded here, as the Context loads only what
  // every path needs.
  const auto get2 = reinterpret_cast<PFN_vkGetPhysicalDeviceProperties2>(
      ctx.get_instance_proc_addr(ctx.instance, "vkGetPhysicalDeviceProperties2"));
  if (get2) {
    VkPhysicalDeviceProperties2 p2{};
    p2.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_PROPERTIES_2;
    p2.pNext = &subgroup;
    get2(ctx.physical_device, &p2);
  }
  return choose_layout(ctx.properties, subgroup.subgroupSize);
}

DeviceLayout device_layout(const Context& context) {
  return device_layout(*context_impl(context));
}

} // namespace vkcloth::gpu
