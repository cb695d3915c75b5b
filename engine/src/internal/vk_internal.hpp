// SPDX-License-Identifier: MIT
// Internal to engine/src/vulkan: volk, the Context internals and errors (objects: resources.hpp).
// Include this FIRST in every .cpp here: volk.h must precede any other Vulkan header.
#pragma once

// volk's symbols are renamed vkcloth_* (see engine/src/vulkan/CMakeLists.txt): no clash with a
// host's own volk or Vulkan loader.
#include "vkcloth_volk_prefix.h"
#include <volk.h>

#include <atomic>
#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "vkcloth/gpu/context.hpp"
#include "vkcloth/result.hpp"

namespace vkcloth::gpu {

/// Readable name of a VkResult ("VK_ERROR_DEVICE_LOST").
const char* vk_result_name(VkResult r);

/// An Error for a failed Vulkan call: ErrorCode::out_of_memory for the two OOM results,
/// ErrorCode::vulkan otherwise; the message names the call and the VkResult.
Error vk_error(VkResult r, const std::string& what);

#define VKCLOTH_VK_TRY(call, what)                                                                           \
  do {                                                                                                       \
    if (const VkResult vkcloth_vk_r_ = (call); vkcloth_vk_r_ != VK_SUCCESS)                                  \
      return ::vkcloth::gpu::vk_error(vkcloth_vk_r_, (what));                                                \
  } while (0)

class PipelineRegistry;

namespace detail {
/// The engine's way past the public objects' private members (friend of Context, GpuSolver and
/// ClothWorld), so no Impl accessor appears in a public header.
struct Access {
  static const std::shared_ptr<Context::Impl>& context(const Context& c) { return c.impl_; }
  /// Wraps an Impl in its public object (their constructors are private).
  template <typename T, typename I> static T wrap(std::unique_ptr<I> impl) { return T(std::move(impl)); }
  template <typename T> static auto& impl(T& object) { return *object.impl_; }
};
} // namespace detail

/// The internals of a Context (kept alive by every object created from it).
inline const std::shared_ptr<Context::Impl>& context_impl(const Context& c) {
  return detail::Access::context(c);
}

/// Instance-level functions of one instance (loaded from its own vkGetInstanceProcAddr, so
/// several Contexts on different instances never share function pointers).
struct InstanceFns {
  PFN_vkDestroyInstance vkDestroyInstance = nullptr;
  PFN_vkEnumeratePhysicalDevices vkEnumeratePhysicalDevices = nullptr;
  PFN_vkGetPhysicalDeviceProperties vkGetPhysicalDeviceProperties = nullptr;
  PFN_vkGetPhysicalDeviceQueueFamilyProperties vkGetPhysicalDeviceQueueFamilyProperties = nullptr;
  PFN_vkGetPhysicalDeviceMemoryProperties vkGetPhysicalDeviceMemoryProperties = nullptr;
  PFN_vkCreateDevice vkCreateDevice = nullptr;
  PFN_vkGetDeviceProcAddr vkGetDeviceProcAddr = nullptr;
  PFN_vkCreateDebugUtilsMessengerEXT vkCreateDebugUtilsMessengerEXT = nullptr;
  PFN_vkDestroyDebugUtilsMessengerEXT vkDestroyDebugUtilsMessengerEXT = nullptr;
};

/// The device functions of one device plus the VkAllocationCallbacks (HostHandles::allocator, null:
/// the driver's) that every vkCreate*/vkAllocateMemory/vkDestroy*/vkFreeMemory of vkcloth passes.
struct DeviceFns : VolkDeviceTable {
  const VkAllocationCallbacks* allocator = nullptr;
};

struct Context::Impl {
  VkInstance instance = VK_NULL_HANDLE;
  VkPhysicalDevice physical_device = VK_NULL_HANDLE;
  VkDevice device = VK_NULL_HANDLE;
  std::uint32_t queue_family = 0;
  VkQueue queue = VK_NULL_HANDLE;
  PFN_vkGetInstanceProcAddr get_instance_proc_addr = nullptr;
  std::uint32_t api_version = 0;

  InstanceFns fi;
  DeviceFns vk{}; ///< device functions of `device`, and the host's allocation callbacks

  VkPhysicalDeviceProperties properties{};
  VkPhysicalDeviceMemoryProperties memory{};
  std::uint32_t timestamp_valid_bits = 0;
  std::string name;

  bool owns = false;
  bool validation = false;
  bool print_messages = true;
  VkDebugUtilsMessengerEXT messenger = VK_NULL_HANDLE;
  std::atomic<std::uint64_t> messages{0};
  std::atomic<std::int64_t> live_allocations{0}; ///< allocate_memory() allocations not yet freed
  /// Test hook (testing::set_allocation_failure_hook): true fails the allocation. Empty: no cost
  /// beyond one branch per allocation.
  std::function<bool()> fail_allocation;
  /// Shader modules, layouts, the pipeline cache and the compute pipelines, shared by every
  /// batch on this Context (pipelines.hpp); made in load(), destroyed first in ~Impl().
  std::unique_ptr<PipelineRegistry> pipelines;

  Impl() = default;
  Impl(const Impl&) = delete;
  Impl& operator=(const Impl&) = delete;
  ~Impl();

  /// Loads `fi` from instance, the properties of physical_device and `vk` from device.
  Result<void> load(std::uint32_t required_api);
  /// Index of a memory type allowed by `type_bits` having all of `required` (and, when possible,
  /// all of `preferred`); -1 if none.
  int find_memory_type(std::uint32_t type_bits, VkMemoryPropertyFlags required,
                       VkMemoryPropertyFlags preferred) const;
};

} // namespace vkcloth::gpu
