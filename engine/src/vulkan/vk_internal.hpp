// Internal to engine/src/vulkan: volk, the Context internals, errors and buffers.
// Include this FIRST in every .cpp here: volk.h must precede any other Vulkan header.
#pragma once

// volk's symbols are renamed vkcloth_* (see engine/src/vulkan/CMakeLists.txt): no clash with a
// host's own volk or Vulkan loader.
#include "vkcloth_volk_prefix.h"
#include <volk.h>

#include <atomic>
#include <cstdint>
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

#define VKCLOTH_VK_TRY(call, what)                                                                      \
  do {                                                                                                  \
    if (const VkResult vkcloth_vk_r_ = (call); vkcloth_vk_r_ != VK_SUCCESS)                             \
      return ::vkcloth::gpu::vk_error(vkcloth_vk_r_, (what));                                           \
  } while (0)

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
  std::atomic<std::int64_t> live_allocations{0}; ///< create_buffer() allocations not yet freed

  Impl() = default;
  Impl(const Impl&) = delete;
  Impl& operator=(const Impl&) = delete;
  ~Impl();

  /// Loads `fi` from instance, the properties of physical_device and `vk` from device.
  Result<void> load(std::uint32_t required_api);
  /// Index of a memory type allowed by `type_bits` having all of `required` (and, when possible,
  /// all of `preferred`); -1 if none.
  int find_memory_type(std::uint32_t type_bits, VkMemoryPropertyFlags required, VkMemoryPropertyFlags preferred) const;
};

/// A buffer with its own memory allocation; `mapped` is set when the memory is host-visible and
/// mapped persistently (always host-coherent).
struct Buffer {
  VkBuffer buffer = VK_NULL_HANDLE;
  VkDeviceMemory memory = VK_NULL_HANDLE;
  VkDeviceSize size = 0;
  void* mapped = nullptr;
};

enum class MemoryUse {
  device,         ///< device-local; mapped only if also host-visible+coherent and `allow_map`
  host_upload,    ///< host-visible+coherent staging for uploads
  host_readback,  ///< host-visible+coherent, cached if possible, for readbacks and flags
};

/// `sharing_families`: queue families that use the buffer without ownership transfers; two or more
/// distinct ones make it VK_SHARING_MODE_CONCURRENT, otherwise it is EXCLUSIVE.
Result<Buffer> create_buffer(Context::Impl& ctx, VkDeviceSize size, VkBufferUsageFlags usage, MemoryUse use,
                             bool allow_map, const char* what, const std::vector<std::uint32_t>& sharing_families = {});
void destroy_buffer(Context::Impl& ctx, Buffer& b);

/// The convenience path of solvers and worlds: resets `cmd`, records `record_fn(cmd)` into it
/// (one-time submit), submits it on the Context's queue signalling `fence` and waits for it.
template <typename F>
Result<void> submit_and_wait(const Context::Impl& ctx, VkCommandBuffer cmd, VkFence fence, F&& record_fn) {
  const auto& v = ctx.vk;
  VKCLOTH_VK_TRY(v.vkResetCommandBuffer(cmd, 0), "vkResetCommandBuffer");
  VkCommandBufferBeginInfo bi{};
  bi.sType = VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO;
  bi.flags = VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT;
  VKCLOTH_VK_TRY(v.vkBeginCommandBuffer(cmd, &bi), "vkBeginCommandBuffer");
  record_fn(cmd);
  VKCLOTH_VK_TRY(v.vkEndCommandBuffer(cmd), "vkEndCommandBuffer");
  VkSubmitInfo si{};
  si.sType = VK_STRUCTURE_TYPE_SUBMIT_INFO;
  si.commandBufferCount = 1;
  si.pCommandBuffers = &cmd;
  VKCLOTH_VK_TRY(v.vkResetFences(ctx.device, 1, &fence), "vkResetFences");
  VKCLOTH_VK_TRY(v.vkQueueSubmit(ctx.queue, 1, &si, fence), "vkQueueSubmit");
  VKCLOTH_VK_TRY(v.vkWaitForFences(ctx.device, 1, &fence, VK_TRUE, UINT64_MAX), "vkWaitForFences");
  return {};
}

} // namespace vkcloth::gpu
