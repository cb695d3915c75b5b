// SPDX-License-Identifier: MIT
// Physical devices for the Context: Context::list_devices(), the queue family a device offers
// (compute, with graphics or presentation when asked, timestamps preferred), the devices usable
// with the ContextOptions (Vulkan 1.2, a fitting queue family, the device extensions asked for),
// and the choice among them: the one VKCLOTH_DEVICE / device_filter names (an index or a name
// substring), else the best type, discrete GPUs first.
#include "context_setup.hpp"

#include "internal/pipelines.hpp" // PipelineRegistry, for the Impl that list_devices() makes

#include <algorithm>
#include <cctype>
#include <cstring>

#include <fmt/format.h>

namespace vkcloth::gpu {
namespace {

std::string lower(std::string s) {
  std::transform(s.begin(), s.end(), s.begin(), [](unsigned char c) { return char(std::tolower(c)); });
  return s;
}

int type_rank(VkPhysicalDeviceType t) {
  switch (t) {
  case VK_PHYSICAL_DEVICE_TYPE_DISCRETE_GPU:
    return 0;
  case VK_PHYSICAL_DEVICE_TYPE_INTEGRATED_GPU:
    return 1;
  case VK_PHYSICAL_DEVICE_TYPE_VIRTUAL_GPU:
    return 2;
  case VK_PHYSICAL_DEVICE_TYPE_OTHER:
    return 3;
  case VK_PHYSICAL_DEVICE_TYPE_CPU:
    return 4;
  default:
    return 5;
  }
}

const char* type_name(VkPhysicalDeviceType t) {
  switch (t) {
  case VK_PHYSICAL_DEVICE_TYPE_DISCRETE_GPU:
    return "discrete GPU";
  case VK_PHYSICAL_DEVICE_TYPE_INTEGRATED_GPU:
    return "integrated GPU";
  case VK_PHYSICAL_DEVICE_TYPE_VIRTUAL_GPU:
    return "virtual GPU";
  case VK_PHYSICAL_DEVICE_TYPE_CPU:
    return "CPU";
  default:
    return "other";
  }
}

/// Compute-capable queue family (also graphics-capable and accepted by `filter` when asked),
/// preferring one with timestamps; UINT32_MAX if none.
std::uint32_t pick_queue_family(const InstanceFns& fi, VkPhysicalDevice pd,
                                const ContextOptions* options = nullptr,
                                VkInstance instance = VK_NULL_HANDLE) {
  std::uint32_t n = 0;
  fi.vkGetPhysicalDeviceQueueFamilyProperties(pd, &n, nullptr);
  std::vector<VkQueueFamilyProperties> qf(n);
  fi.vkGetPhysicalDeviceQueueFamilyProperties(pd, &n, qf.data());
  std::uint32_t best = UINT32_MAX;
  for (std::uint32_t i = 0; i < n; ++i) {
    if (!(qf[i].queueFlags & VK_QUEUE_COMPUTE_BIT) || qf[i].queueCount == 0)
      continue;
    if (options && options->require_graphics && !(qf[i].queueFlags & VK_QUEUE_GRAPHICS_BIT))
      continue;
    if (options && options->queue_family_filter && !options->queue_family_filter(instance, pd, i))
      continue;
    if (best == UINT32_MAX || (qf[best].timestampValidBits == 0 && qf[i].timestampValidBits > 0))
      best = i;
  }
  return best;
}

} // namespace

Result<std::vector<DeviceInfo>> Context::list_devices() {
  auto impl = std::make_shared<Impl>();
  auto inst = create_instance(impl.get(), false);
  if (!inst)
    return inst.error();
  impl->instance = inst->instance;
  impl->owns = true;
  auto fi = load_instance_fns(inst->gipa, inst->instance);
  if (!fi)
    return fi.error();
  impl->fi = *fi;
  std::uint32_t n = 0;
  VKCLOTH_VK_TRY(impl->fi.vkEnumeratePhysicalDevices(impl->instance, &n, nullptr),
                 "vkEnumeratePhysicalDevices");
  std::vector<VkPhysicalDevice> pds(n);
  VKCLOTH_VK_TRY(impl->fi.vkEnumeratePhysicalDevices(impl->instance, &n, pds.data()),
                 "vkEnumeratePhysicalDevices");
  keep_vulkan_libraries_loaded_for_lsan(); // the drivers are loaded now
  std::vector<DeviceInfo> out;
  for (std::uint32_t i = 0; i < n; ++i) {
    VkPhysicalDeviceProperties p;
    impl->fi.vkGetPhysicalDeviceProperties(pds[i], &p);
    out.push_back(
        DeviceInfo{i, p.deviceName, p.deviceType, p.apiVersion,
                   p.apiVersion >= VK_API_VERSION_1_2 && pick_queue_family(impl->fi, pds[i]) != UINT32_MAX});
  }
  return out;
}

/// Every physical device of the instance, and those usable with `options`.
Result<Candidates> list_candidates(Context::Impl& impl, PFN_vkGetInstanceProcAddr gipa,
                                   const ContextOptions& options) {
  Candidates out;
  std::uint32_t n = 0;
  VKCLOTH_VK_TRY(impl.fi.vkEnumeratePhysicalDevices(impl.instance, &n, nullptr),
                 "vkEnumeratePhysicalDevices");
  if (n == 0)
    return make_error(ErrorCode::no_device,
                      "the Vulkan loader found no physical device (install a driver, e.g. "
                      "mesa-vulkan-drivers for the lavapipe CPU device)");
  out.devices.resize(n);
  VKCLOTH_VK_TRY(impl.fi.vkEnumeratePhysicalDevices(impl.instance, &n, out.devices.data()),
                 "vkEnumeratePhysicalDevices");
  keep_vulkan_libraries_loaded_for_lsan(); // the drivers are loaded now

  for (std::uint32_t i = 0; i < n; ++i) {
    Candidate c{i, {}, pick_queue_family(impl.fi, out.devices[i], &options, impl.instance)};
    if (c.family != UINT32_MAX && !options.device_extensions.empty()) {
      auto enumerate = reinterpret_cast<PFN_vkEnumerateDeviceExtensionProperties>(
          gipa(impl.instance, "vkEnumerateDeviceExtensionProperties"));
      std::uint32_t ne = 0;
      enumerate(out.devices[i], nullptr, &ne, nullptr);
      std::vector<VkExtensionProperties> de(ne);
      enumerate(out.devices[i], nullptr, &ne, de.data());
      for (const char* e : options.device_extensions)
        if (std::none_of(de.begin(), de.end(), [&](const VkExtensionProperties& p) {
              return std::strcmp(p.extensionName, e) == 0;
            }))
          c.family = UINT32_MAX;
    }
    impl.fi.vkGetPhysicalDeviceProperties(out.devices[i], &c.props);
    out.listing += fmt::format("{}[{}] {} ({}, Vulkan {})", i ? ", " : "", i, c.props.deviceName,
                               type_name(c.props.deviceType), version_string(c.props.apiVersion));
    if (c.family != UINT32_MAX && c.props.apiVersion >= VK_API_VERSION_1_2)
      out.usable.push_back(c);
  }
  if (out.usable.empty())
    return make_error(ErrorCode::no_device,
                      fmt::format("no device offers Vulkan 1.2 and a compute queue{}{}; devices: {}",
                                  options.require_graphics ? " with graphics" : "",
                                  options.queue_family_filter ? " (and presentation)" : "", out.listing));

  return out;
}

/// The device `filter` names (an index or a name substring), else the best type (discrete first).
Result<const Candidate*> choose_device(const Candidates& c, const std::string& filter) {
  const Candidate* chosen = nullptr;
  if (!filter.empty()) {
    const bool numeric =
        std::all_of(filter.begin(), filter.end(), [](unsigned char ch) { return std::isdigit(ch); });
    for (const Candidate& d : c.usable) {
      const bool match = numeric ? std::to_string(d.index) == filter
                                 : lower(d.props.deviceName).find(lower(filter)) != std::string::npos;
      if (match) {
        chosen = &d;
        break;
      }
    }
    if (!chosen)
      return make_error(
          ErrorCode::no_device,
          fmt::format("no usable Vulkan device matches '{}' (VKCLOTH_DEVICE or the device option: an index "
                      "or a name substring); devices: {}",
                      filter, c.listing));
  } else {
    chosen = &*std::min_element(c.usable.begin(), c.usable.end(), [](const Candidate& a, const Candidate& b) {
      return type_rank(a.props.deviceType) < type_rank(b.props.deviceType);
    });
  }

  return chosen;
}

} // namespace vkcloth::gpu
