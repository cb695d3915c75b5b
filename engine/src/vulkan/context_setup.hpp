// SPDX-License-Identifier: MIT
// Internal to the Context: what its three parts share. context_instance.cpp loads Vulkan (volk and
// its process-wide mutex) and creates the instance, with the validation layer and the debug
// messenger that counts its messages; context_devices.cpp lists the physical devices and picks one
// (VKCLOTH_DEVICE, ContextOptions); context.cpp creates or adopts the device and holds the
// Context's members.
#pragma once

#include "internal/vk_internal.hpp"

#include <cstdint>
#include <mutex>
#include <string>
#include <vector>

namespace vkcloth::gpu {

// ---- loader and instance (context_instance.cpp) ---------------------------------------------------

/// Under AddressSanitizer only: keeps every library loaded so far (the Vulkan loader, the driver,
/// the layers) loaded until exit, so LeakSanitizer can name their one-time allocations.
void keep_vulkan_libraries_loaded_for_lsan();

/// volk's function pointers are process globals: every use of them goes through this mutex.
std::mutex& volk_mutex();
/// Points volk at `gipa` (the loader's when null); `used` receives the one in use. Needs volk_mutex().
Result<void> init_volk_locked(PFN_vkGetInstanceProcAddr gipa, PFN_vkGetInstanceProcAddr* used = nullptr);

/// "1.3.250"
std::string version_string(std::uint32_t v);

/// The instance functions of `instance`, from its own vkGetInstanceProcAddr.
Result<InstanceFns> load_instance_fns(PFN_vkGetInstanceProcAddr gipa, VkInstance instance);

struct OwnedInstance {
  VkInstance instance = VK_NULL_HANDLE;
  std::uint32_t api_version = 0;
  PFN_vkGetInstanceProcAddr gipa = nullptr;
};

/// Creates an instance (validation optional; `impl` receives messages from creation on).
Result<OwnedInstance> create_instance(Context::Impl* impl, bool validation,
                                      const std::vector<const char*>& extra_extensions = {});

/// The debug messenger that counts (and prints) validation warnings and errors.
Result<void> create_messenger(Context::Impl& impl);

// ---- physical devices (context_devices.cpp) -------------------------------------------------------

/// A physical device that offers what the options need: `family` is its queue family, or
/// UINT32_MAX when none fits (or a requested device extension is missing).
struct Candidate {
  std::uint32_t index;
  VkPhysicalDeviceProperties props;
  std::uint32_t family;
};

struct Candidates {
  std::vector<VkPhysicalDevice> devices;
  std::vector<Candidate> usable; // Vulkan 1.2 and a fitting queue family
  std::string listing;           // every device, for error messages
};

/// Every physical device of the instance, and those usable with `options`.
Result<Candidates> list_candidates(Context::Impl& impl, PFN_vkGetInstanceProcAddr gipa,
                                   const ContextOptions& options);

/// The device `filter` names (an index or a name substring), else the best type (discrete first).
Result<const Candidate*> choose_device(const Candidates& c, const std::string& filter);

} // namespace vkcloth::gpu
