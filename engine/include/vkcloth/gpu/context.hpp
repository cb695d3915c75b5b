// SPDX-License-Identifier: MIT
// Vulkan context for the compute solver: either a headless instance + device of its own (tools,
// samples, tests) or a host's existing handles (an engine embedding vkcloth). The solver only
// ever borrows a Context; a Context destroys only the handles it created.
//
// Thread safety: a Context may be shared by several solvers, but submissions to its queue must be
// externally synchronised (Vulkan's rule for VkQueue): do not call GpuSolver::simulate() or the
// readbacks of solvers sharing a Context from several threads at once.
#pragma once

#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <vulkan/vulkan_core.h>

#include "vkcloth/result.hpp"

namespace vkcloth::gpu {

namespace detail {
struct Access; // engine internals: reach the Impl of a Context, GpuSolver or ClothWorld
} // namespace detail

/// Options for a Context that creates its own instance and device.
struct ContextOptions {
  /// Device choice: a decimal index into the device list, or a case-insensitive substring of the
  /// device name. Empty: the environment variable VKCLOTH_DEVICE, else the first discrete GPU,
  /// else integrated, virtual, other, CPU (lavapipe), in that order.
  std::string device_filter;
  /// Enables VK_LAYER_KHRONOS_validation with synchronization validation and a debug messenger
  /// that counts (and prints) warnings and errors. Unset: VKCLOTH_VALIDATION=1 in the environment.
  std::optional<bool> validation;
  /// Print each validation message to stderr (they are counted either way).
  bool print_validation_messages = true;
  /// Extra instance extensions (e.g. glfwGetRequiredInstanceExtensions() for a window surface).
  std::vector<const char*> instance_extensions;
  /// Extra device extensions (e.g. VK_KHR_SWAPCHAIN_EXTENSION_NAME); a device lacking one is skipped.
  std::vector<const char*> device_extensions;
  /// The queue must also support graphics (for the renderer); compute is always required.
  bool require_graphics = false;
  /// Optional further test of a queue family, called after the instance exists (e.g. present
  /// support to a surface created from that instance); families for which it returns false are skipped.
  std::function<bool(VkInstance, VkPhysicalDevice, std::uint32_t queue_family)> queue_family_filter;
};

/// A host's Vulkan handles, adopted as they are (nothing is created or destroyed but the
/// solver's own objects: the host's instance, device and queue stay valid and usable after every
/// vkcloth object is gone). The device needs one queue of `queue_family` with compute support;
/// no extension or feature beyond Vulkan 1.2 core is required.
struct HostHandles {
  VkInstance instance = VK_NULL_HANDLE;
  VkPhysicalDevice physical_device = VK_NULL_HANDLE;
  VkDevice device = VK_NULL_HANDLE;
  std::uint32_t queue_family = 0;
  VkQueue queue = VK_NULL_HANDLE;
  PFN_vkGetInstanceProcAddr get_instance_proc_addr = nullptr;
  /// The API version the instance and device were created for; the shaders need 1.2.
  std::uint32_t api_version = VK_API_VERSION_1_2;
  /// The host's allocation callbacks, passed to EVERY vkCreate* / vkAllocateMemory / vkDestroy* /
  /// vkFreeMemory that vkcloth makes on `device` (solvers, worlds, renderer, offscreen targets).
  /// Null: the driver's allocator. Must outlive every vkcloth object created on this Context.
  const VkAllocationCallbacks* allocator = nullptr;
};

/// One physical device as listed by Context::list_devices().
struct DeviceInfo {
  std::uint32_t index = 0;
  std::string name;
  VkPhysicalDeviceType type = VK_PHYSICAL_DEVICE_TYPE_OTHER;
  std::uint32_t api_version = 0;
  bool usable = false; ///< Vulkan >= 1.2 and a compute queue
};

/// A Vulkan instance, physical device, device and compute queue. Movable, not copyable; solvers
/// created from it keep its internals alive, so it may be destroyed before them.
class Context {
public:
  /// Creates a headless instance and device. ErrorCode::no_device when no Vulkan driver or
  /// device is found or nothing matches the filter; ErrorCode::unsupported when validation was
  /// requested and the layer is missing; ErrorCode::vulkan for other failures.
  static Result<Context> create(const ContextOptions& options = {});
  /// Adopts a host's handles; destroys none of them.
  static Result<Context> adopt(const HostHandles& handles);
  /// The devices the Vulkan loader reports (for `--list-devices`); no device is created.
  static Result<std::vector<DeviceInfo>> list_devices();

  Context(Context&&) noexcept;
  Context& operator=(Context&&) noexcept;
  Context(const Context&) = delete;
  Context& operator=(const Context&) = delete;
  ~Context();

  /// The handles in use (adoptable by another Context or by a renderer).
  HostHandles handles() const;
  /// vkGetDeviceProcAddr for this device, to load further device functions.
  PFN_vkGetDeviceProcAddr device_proc_addr() const;
  const std::string& device_name() const;
  VkPhysicalDeviceType device_type() const;
  const VkPhysicalDeviceLimits& limits() const;
  /// True when this Context created (and will destroy) the instance and device.
  bool owns_device() const;

  bool validation_enabled() const;
  /// Validation warnings and errors reported so far (0 when validation is off).
  std::uint64_t validation_message_count() const;
  /// Validation warnings and errors of every Context of this process so far, including those
  /// reported while a Context was destroyed (e.g. leaked objects). The CLI's --validate uses it.
  static std::uint64_t process_validation_message_count();
  /// Device memory allocations vkcloth's solvers hold on this Context right now (0 once every
  /// solver is destroyed, or after a failed GpuSolver::create: tests use it to check for leaks).
  std::int64_t live_allocation_count() const;

  /// vkDeviceWaitIdle.
  Result<void> wait_idle() const;

  struct Impl; ///< internal (engine/src/vulkan)

private:
  friend struct detail::Access;
  explicit Context(std::shared_ptr<Impl> impl);
  std::shared_ptr<Impl> impl_;
};

} // namespace vkcloth::gpu
