// SPDX-License-Identifier: MIT
#include "vk_internal.hpp"

#include "pipelines.hpp"

#include <algorithm>
#include <cctype>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <mutex>
#include <vector>

#include <fmt/format.h>
#include <fmt/ranges.h>

#if defined(__SANITIZE_ADDRESS__)
#include <dlfcn.h>
#include <link.h>
#endif

namespace vkcloth::gpu {
namespace {

/// Under AddressSanitizer only: keeps every library loaded so far (the Vulkan loader, the driver,
/// the layers) loaded until exit. The loader unloads the driver at vkDestroyInstance, and
/// LeakSanitizer's end-of-process report then cannot name the driver's one-time allocations, nor
/// match them against tests/lsan.supp, which lists these libraries by name.
void keep_vulkan_libraries_loaded_for_lsan() {
#if defined(__SANITIZE_ADDRESS__)
  dl_iterate_phdr(
      [](dl_phdr_info* info, std::size_t, void*) -> int {
        if (info->dlpi_name && *info->dlpi_name)
          dlopen(info->dlpi_name, RTLD_NOW | RTLD_NOLOAD | RTLD_NODELETE);
        return 0;
      },
      nullptr);
#endif
}

// volk's function pointers are process globals: every use of them goes through this mutex, and
// each Context keeps its own vkGetInstanceProcAddr and tables so they never depend on the globals.
std::mutex& volk_mutex() {
  static std::mutex m;
  return m;
}
PFN_vkGetInstanceProcAddr g_loader_gipa = nullptr; // the system loader's, once found

/// Points volk at `gipa` (the loader's when null); `used` receives the one in use.
Result<void> init_volk_locked(PFN_vkGetInstanceProcAddr gipa, PFN_vkGetInstanceProcAddr* used = nullptr) {
  if (gipa) {
    volkInitializeCustom(gipa);
    if (used)
      *used = gipa;
    return {};
  }
  if (!g_loader_gipa) {
    if (volkInitialize() != VK_SUCCESS)
      return make_error(
          ErrorCode::no_device,
          "no Vulkan loader (libvulkan.so.1) could be loaded: install a Vulkan driver and loader "
          "(e.g. libvulkan1 + mesa-vulkan-drivers for the lavapipe CPU device)");
    g_loader_gipa = vkGetInstanceProcAddr;
  } else {
    volkInitializeCustom(g_loader_gipa);
  }
  if (used)
    *used = g_loader_gipa;
  return {};
}

bool env_flag(const char* name) {
  const char* v = std::getenv(name);
  return v && *v && std::strcmp(v, "0") != 0 && std::strcmp(v, "false") != 0;
}

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

std::string version_string(std::uint32_t v) {
  return fmt::format("{}.{}.{}", VK_API_VERSION_MAJOR(v), VK_API_VERSION_MINOR(v), VK_API_VERSION_PATCH(v));
}

/// Validation messages of every Context of the process, including those reported while a Context
/// is destroyed (leaked objects).
std::atomic<std::uint64_t> g_process_messages{0};

VKAPI_ATTR VkBool32 VKAPI_CALL debug_callback(VkDebugUtilsMessageSeverityFlagBitsEXT severity,
                                              VkDebugUtilsMessageTypeFlagsEXT,
                                              const VkDebugUtilsMessengerCallbackDataEXT* data, void* user) {
  auto* ctx = static_cast<Context::Impl*>(user);
  if (severity < VK_DEBUG_UTILS_MESSAGE_SEVERITY_WARNING_BIT_EXT)
    return VK_FALSE;
  ctx->messages.fetch_add(1, std::memory_order_relaxed);
  g_process_messages.fetch_add(1, std::memory_order_relaxed);
  if (ctx->print_messages)
    std::fprintf(stderr, "vkcloth: Vulkan validation %s: %s\n",
                 severity >= VK_DEBUG_UTILS_MESSAGE_SEVERITY_ERROR_BIT_EXT ? "error" : "warning",
                 data && data->pMessage ? data->pMessage : "(no message)");
  return VK_FALSE;
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

Result<InstanceFns> load_instance_fns(PFN_vkGetInstanceProcAddr gipa, VkInstance instance) {
  InstanceFns f;
#define VKCLOTH_LOAD(name) f.name = reinterpret_cast<PFN_##name>(gipa(instance, #name))
  VKCLOTH_LOAD(vkDestroyInstance);
  VKCLOTH_LOAD(vkEnumeratePhysicalDevices);
  VKCLOTH_LOAD(vkGetPhysicalDeviceProperties);
  VKCLOTH_LOAD(vkGetPhysicalDeviceQueueFamilyProperties);
  VKCLOTH_LOAD(vkGetPhysicalDeviceMemoryProperties);
  VKCLOTH_LOAD(vkCreateDevice);
  VKCLOTH_LOAD(vkGetDeviceProcAddr);
  VKCLOTH_LOAD(vkCreateDebugUtilsMessengerEXT);
  VKCLOTH_LOAD(vkDestroyDebugUtilsMessengerEXT);
#undef VKCLOTH_LOAD
  if (!f.vkEnumeratePhysicalDevices || !f.vkGetPhysicalDeviceProperties || !f.vkGetDeviceProcAddr)
    return make_error(ErrorCode::vulkan, "vkGetInstanceProcAddr returned no core instance functions");
  return f;
}

struct OwnedInstance {
  VkInstance instance = VK_NULL_HANDLE;
  std::uint32_t api_version = 0;
  PFN_vkGetInstanceProcAddr gipa = nullptr;
};

/// The validation layer and the two instance extensions validation needs (volk mutex held).
Result<void> check_validation_support(const char* layer) {
  std::uint32_t n = 0;
  vkEnumerateInstanceLayerProperties(&n, nullptr);
  std::vector<VkLayerProperties> lp(n);
  vkEnumerateInstanceLayerProperties(&n, lp.data());
  if (std::none_of(lp.begin(), lp.end(),
                   [&](const VkLayerProperties& p) { return std::strcmp(p.layerName, layer) == 0; }))
    return make_error(ErrorCode::unsupported,
                      "validation was requested (VKCLOTH_VALIDATION=1 or ContextOptions::validation) but "
                      "VK_LAYER_KHRONOS_validation is not installed (package vulkan-validationlayers)");
  std::uint32_t ne = 0;
  vkEnumerateInstanceExtensionProperties(layer, &ne, nullptr);
  std::vector<VkExtensionProperties> le(ne);
  vkEnumerateInstanceExtensionProperties(layer, &ne, le.data());
  std::uint32_t ng = 0;
  vkEnumerateInstanceExtensionProperties(nullptr, &ng, nullptr);
  le.resize(ne + ng);
  vkEnumerateInstanceExtensionProperties(nullptr, &ng, le.data() + ne);
  auto has = [&](const char* e) {
    return std::any_of(le.begin(), le.end(),
                       [&](const VkExtensionProperties& p) { return std::strcmp(p.extensionName, e) == 0; });
  };
  if (!has(VK_EXT_DEBUG_UTILS_EXTENSION_NAME) || !has(VK_EXT_VALIDATION_FEATURES_EXTENSION_NAME))
    return make_error(ErrorCode::unsupported,
                      "validation needs VK_EXT_debug_utils and VK_EXT_validation_features, "
                      "which this Vulkan installation does not offer");
  return {};
}

/// What the debug messenger reports (warnings and errors), to `impl`'s counter.
VkDebugUtilsMessengerCreateInfoEXT messenger_info(Context::Impl* impl) {
  VkDebugUtilsMessengerCreateInfoEXT mi{};
  mi.sType = VK_STRUCTURE_TYPE_DEBUG_UTILS_MESSENGER_CREATE_INFO_EXT;
  mi.messageSeverity =
      VK_DEBUG_UTILS_MESSAGE_SEVERITY_WARNING_BIT_EXT | VK_DEBUG_UTILS_MESSAGE_SEVERITY_ERROR_BIT_EXT;
  mi.messageType = VK_DEBUG_UTILS_MESSAGE_TYPE_GENERAL_BIT_EXT |
                   VK_DEBUG_UTILS_MESSAGE_TYPE_VALIDATION_BIT_EXT |
                   VK_DEBUG_UTILS_MESSAGE_TYPE_PERFORMANCE_BIT_EXT;
  mi.pfnUserCallback = debug_callback;
  mi.pUserData = impl;
  return mi;
}

/// Creates an instance (validation optional; `impl` receives messages from creation on).
Result<OwnedInstance> create_instance(Context::Impl* impl, bool validation,
                                      const std::vector<const char*>& extra_extensions = {}) {
  std::lock_guard lock(volk_mutex());
  PFN_vkGetInstanceProcAddr gipa = nullptr;
  VKCLOTH_TRY(init_volk_locked(nullptr, &gipa));
  const std::uint32_t loader = volkGetInstanceVersion();
  if (loader < VK_API_VERSION_1_2)
    return make_error(ErrorCode::no_device,
                      fmt::format("the Vulkan loader supports Vulkan {}, vkcloth needs 1.2 or newer",
                                  version_string(loader)));
  const std::uint32_t api = std::min<std::uint32_t>(loader, VK_API_VERSION_1_3);

  std::vector<const char*> layers, extensions;
  VkValidationFeaturesEXT features{};
  features.sType = VK_STRUCTURE_TYPE_VALIDATION_FEATURES_EXT;
  const VkValidationFeatureEnableEXT enables[] = {
      VK_VALIDATION_FEATURE_ENABLE_SYNCHRONIZATION_VALIDATION_EXT};
  VkDebugUtilsMessengerCreateInfoEXT messenger = messenger_info(impl);
  const void* next = nullptr;
  if (validation) {
    const char* layer = "VK_LAYER_KHRONOS_validation";
    VKCLOTH_TRY(check_validation_support(layer));
    layers.push_back(layer);
    extensions.push_back(VK_EXT_DEBUG_UTILS_EXTENSION_NAME);
    extensions.push_back(VK_EXT_VALIDATION_FEATURES_EXTENSION_NAME);
    features.enabledValidationFeatureCount = 1;
    features.pEnabledValidationFeatures = enables;
    features.pNext = &messenger; // also reports messages of vkCreateInstance / vkDestroyInstance
    next = &features;
  }

  for (const char* e : extra_extensions)
    if (std::none_of(extensions.begin(), extensions.end(),
                     [&](const char* x) { return std::strcmp(x, e) == 0; }))
      extensions.push_back(e);

  VkApplicationInfo app{};
  app.sType = VK_STRUCTURE_TYPE_APPLICATION_INFO;
  app.pApplicationName = "vkcloth";
  app.pEngineName = "vkcloth";
  app.apiVersion = api;
  VkInstanceCreateInfo ci{};
  ci.sType = VK_STRUCTURE_TYPE_INSTANCE_CREATE_INFO;
  ci.pNext = next;
  ci.pApplicationInfo = &app;
  ci.enabledLayerCount = static_cast<std::uint32_t>(layers.size());
  ci.ppEnabledLayerNames = layers.data();
  ci.enabledExtensionCount = static_cast<std::uint32_t>(extensions.size());
  ci.ppEnabledExtensionNames = extensions.data();
  VkInstance instance = VK_NULL_HANDLE;
  const VkResult r = vkCreateInstance(&ci, nullptr, &instance);
  if (r == VK_ERROR_EXTENSION_NOT_PRESENT && !extra_extensions.empty())
    return make_error(ErrorCode::unsupported,
                      fmt::format("vkCreateInstance: an instance extension is missing (asked for: {})",
                                  fmt::join(extra_extensions, ", ")));
  if (r == VK_ERROR_INCOMPATIBLE_DRIVER)
    return make_error(ErrorCode::no_device,
                      "vkCreateInstance: VK_ERROR_INCOMPATIBLE_DRIVER: no Vulkan driver is installed "
                      "(install one, e.g. mesa-vulkan-drivers for the lavapipe CPU device)");
  if (r != VK_SUCCESS)
    return vk_error(r, "vkCreateInstance");
  return OwnedInstance{instance, api, gipa};
}

} // namespace

const char* vk_result_name(VkResult r) {
  switch (r) {
#define VKCLOTH_CASE(x)                                                                                      \
  case x:                                                                                                    \
    return #x
    VKCLOTH_CASE(VK_SUCCESS);
    VKCLOTH_CASE(VK_NOT_READY);
    VKCLOTH_CASE(VK_TIMEOUT);
    VKCLOTH_CASE(VK_INCOMPLETE);
    VKCLOTH_CASE(VK_ERROR_OUT_OF_HOST_MEMORY);
    VKCLOTH_CASE(VK_ERROR_OUT_OF_DEVICE_MEMORY);
    VKCLOTH_CASE(VK_ERROR_INITIALIZATION_FAILED);
    VKCLOTH_CASE(VK_ERROR_DEVICE_LOST);
    VKCLOTH_CASE(VK_ERROR_MEMORY_MAP_FAILED);
    VKCLOTH_CASE(VK_ERROR_LAYER_NOT_PRESENT);
    VKCLOTH_CASE(VK_ERROR_EXTENSION_NOT_PRESENT);
    VKCLOTH_CASE(VK_ERROR_FEATURE_NOT_PRESENT);
    VKCLOTH_CASE(VK_ERROR_INCOMPATIBLE_DRIVER);
    VKCLOTH_CASE(VK_ERROR_TOO_MANY_OBJECTS);
    VKCLOTH_CASE(VK_ERROR_FORMAT_NOT_SUPPORTED);
    VKCLOTH_CASE(VK_ERROR_FRAGMENTED_POOL);
    VKCLOTH_CASE(VK_ERROR_OUT_OF_POOL_MEMORY);
    VKCLOTH_CASE(VK_ERROR_UNKNOWN);
#undef VKCLOTH_CASE
  default:
    return "VkResult(unknown)";
  }
}

Error vk_error(VkResult r, const std::string& what) {
  const bool oom = r == VK_ERROR_OUT_OF_HOST_MEMORY || r == VK_ERROR_OUT_OF_DEVICE_MEMORY;
  Error e{oom ? ErrorCode::out_of_memory : ErrorCode::vulkan,
          fmt::format("{} failed: {} ({})", what, vk_result_name(r), static_cast<int>(r)),
          static_cast<std::int32_t>(r)};
  if (r == VK_ERROR_DEVICE_LOST)
    e.message += "; the device was lost (driver reset or a GPU hang)";
  if (oom)
    e.message += "; try a smaller system or free GPU memory";
  return e;
}

Context::Impl::~Impl() {
  pipelines.reset(); // before the device goes, whoever owns it
  if (!owns)
    return;
  if (device) {
    if (vk.vkDeviceWaitIdle)
      vk.vkDeviceWaitIdle(device);
    auto destroy =
        vk.vkDestroyDevice
            ? vk.vkDestroyDevice
            : reinterpret_cast<PFN_vkDestroyDevice>(fi.vkGetDeviceProcAddr(device, "vkDestroyDevice"));
    if (destroy)
      destroy(device, nullptr);
  }
  if (messenger && fi.vkDestroyDebugUtilsMessengerEXT)
    fi.vkDestroyDebugUtilsMessengerEXT(instance, messenger, nullptr);
  if (instance && fi.vkDestroyInstance)
    fi.vkDestroyInstance(instance, nullptr);
}

Result<void> Context::Impl::load(std::uint32_t required_api) {
  fi.vkGetPhysicalDeviceProperties(physical_device, &properties);
  fi.vkGetPhysicalDeviceMemoryProperties(physical_device, &memory);
  name = properties.deviceName;
  if (std::min(properties.apiVersion, api_version) < required_api)
    return make_error(ErrorCode::unsupported,
                      fmt::format("device '{}' is used at Vulkan {} (device {}), vkcloth's shaders need 1.2",
                                  name, version_string(api_version), version_string(properties.apiVersion)));
  std::uint32_t n = 0;
  fi.vkGetPhysicalDeviceQueueFamilyProperties(physical_device, &n, nullptr);
  std::vector<VkQueueFamilyProperties> qf(n);
  fi.vkGetPhysicalDeviceQueueFamilyProperties(physical_device, &n, qf.data());
  if (queue_family >= n || !(qf[queue_family].queueFlags & VK_QUEUE_COMPUTE_BIT))
    return make_error(ErrorCode::unsupported,
                      fmt::format("queue family {} of '{}' has no compute support", queue_family, name));
  timestamp_valid_bits = qf[queue_family].timestampValidBits;
  {
    // volkLoadDeviceTable goes through volk's global vkGetDeviceProcAddr: point it at ours first.
    std::lock_guard lock(volk_mutex());
    VKCLOTH_TRY(init_volk_locked(get_instance_proc_addr));
    volkLoadInstanceOnly(instance);
    volkLoadDeviceTable(&vk, device);
  }
  if (!vk.vkCmdDispatch || !vk.vkQueueSubmit)
    return make_error(ErrorCode::vulkan, "vkGetDeviceProcAddr returned no core device functions");
  pipelines = std::make_unique<PipelineRegistry>(*this); // creates nothing yet
  return {};
}

int Context::Impl::find_memory_type(std::uint32_t bits, VkMemoryPropertyFlags required,
                                    VkMemoryPropertyFlags preferred) const {
  int fallback = -1;
  for (std::uint32_t i = 0; i < memory.memoryTypeCount; ++i) {
    if (!(bits & (1u << i)))
      continue;
    const VkMemoryPropertyFlags f = memory.memoryTypes[i].propertyFlags;
    if ((f & required) != required)
      continue;
    if ((f & preferred) == preferred)
      return static_cast<int>(i);
    if (fallback < 0)
      fallback = static_cast<int>(i);
  }
  return fallback;
}

Context::Context(std::shared_ptr<Impl> impl) : impl_(std::move(impl)) {}
Context::Context(Context&&) noexcept = default;
Context& Context::operator=(Context&&) noexcept = default;
Context::~Context() = default;

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

namespace {

/// The debug messenger that counts (and prints) validation warnings and errors.
Result<void> create_messenger(Context::Impl& impl) {
  const VkDebugUtilsMessengerCreateInfoEXT mi = messenger_info(&impl);
  if (!impl.fi.vkCreateDebugUtilsMessengerEXT)
    return make_error(ErrorCode::unsupported,
                      "vkCreateDebugUtilsMessengerEXT is missing although VK_EXT_debug_utils is enabled");
  VKCLOTH_VK_TRY(impl.fi.vkCreateDebugUtilsMessengerEXT(impl.instance, &mi, nullptr, &impl.messenger),
                 "vkCreateDebugUtilsMessengerEXT");
  return {};
}

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

} // namespace

Result<Context> Context::create(const ContextOptions& options) {
  const bool validation = options.validation ? *options.validation : env_flag("VKCLOTH_VALIDATION");
  std::string filter = options.device_filter;
  if (filter.empty())
    if (const char* e = std::getenv("VKCLOTH_DEVICE"))
      filter = e;

  auto impl = std::make_shared<Impl>();
  impl->owns = true;
  impl->validation = validation;
  impl->print_messages = options.print_validation_messages;
  auto inst = create_instance(impl.get(), validation, options.instance_extensions);
  if (!inst)
    return inst.error();
  impl->instance = inst->instance;
  impl->api_version = inst->api_version;
  impl->get_instance_proc_addr = inst->gipa;
  auto fi = load_instance_fns(inst->gipa, inst->instance);
  if (!fi)
    return fi.error();
  impl->fi = *fi;
  if (validation)
    VKCLOTH_TRY(create_messenger(*impl));

  auto candidates = list_candidates(*impl, inst->gipa, options);
  if (!candidates)
    return candidates.error();
  auto picked = choose_device(*candidates, filter);
  if (!picked)
    return picked.error();
  const Candidate* chosen = *picked;
  impl->physical_device = candidates->devices[chosen->index];
  impl->queue_family = chosen->family;
  const float priority = 1.0f;
  VkDeviceQueueCreateInfo qi{};
  qi.sType = VK_STRUCTURE_TYPE_DEVICE_QUEUE_CREATE_INFO;
  qi.queueFamilyIndex = impl->queue_family;
  qi.queueCount = 1;
  qi.pQueuePriorities = &priority;
  VkDeviceCreateInfo di{};
  di.sType = VK_STRUCTURE_TYPE_DEVICE_CREATE_INFO;
  di.queueCreateInfoCount = 1;
  di.pQueueCreateInfos = &qi;
  di.enabledExtensionCount = static_cast<std::uint32_t>(options.device_extensions.size());
  di.ppEnabledExtensionNames = options.device_extensions.data();
  VKCLOTH_VK_TRY(impl->fi.vkCreateDevice(impl->physical_device, &di, nullptr, &impl->device),
                 fmt::format("vkCreateDevice on '{}'", chosen->props.deviceName));
  VKCLOTH_TRY(impl->load(VK_API_VERSION_1_2));
  impl->vk.vkGetDeviceQueue(impl->device, impl->queue_family, 0, &impl->queue);
  return Context(std::move(impl));
}

Result<Context> Context::adopt(const HostHandles& h) {
  if (!h.instance || !h.physical_device || !h.device || !h.queue || !h.get_instance_proc_addr)
    return make_error(
        ErrorCode::invalid_argument,
        "HostHandles needs instance, physical_device, device, queue and get_instance_proc_addr");
  auto impl = std::make_shared<Impl>();
  impl->owns = false;
  impl->instance = h.instance;
  impl->physical_device = h.physical_device;
  impl->device = h.device;
  impl->queue_family = h.queue_family;
  impl->queue = h.queue;
  impl->get_instance_proc_addr = h.get_instance_proc_addr;
  impl->api_version = h.api_version;
  auto fi = load_instance_fns(h.get_instance_proc_addr, h.instance);
  if (!fi)
    return fi.error();
  impl->fi = *fi;
  VKCLOTH_TRY(impl->load(VK_API_VERSION_1_2));
  impl->vk.allocator = h.allocator;
  keep_vulkan_libraries_loaded_for_lsan(); // the host's driver, for the same reason
  return Context(std::move(impl));
}

HostHandles Context::handles() const {
  return HostHandles{impl_->instance, impl_->physical_device,        impl_->device,      impl_->queue_family,
                     impl_->queue,    impl_->get_instance_proc_addr, impl_->api_version, impl_->vk.allocator};
}
PFN_vkGetDeviceProcAddr Context::device_proc_addr() const {
  return impl_->fi.vkGetDeviceProcAddr;
}
const std::string& Context::device_name() const {
  return impl_->name;
}
VkPhysicalDeviceType Context::device_type() const {
  return impl_->properties.deviceType;
}
const VkPhysicalDeviceLimits& Context::limits() const {
  return impl_->properties.limits;
}
bool Context::owns_device() const {
  return impl_->owns;
}
bool Context::validation_enabled() const {
  return impl_->validation;
}
std::uint64_t Context::validation_message_count() const {
  return impl_->messages.load(std::memory_order_relaxed);
}
std::uint64_t Context::process_validation_message_count() {
  return g_process_messages.load(std::memory_order_relaxed);
}
std::int64_t Context::live_allocation_count() const {
  return impl_->live_allocations.load(std::memory_order_relaxed);
}
Result<void> Context::wait_idle() const {
  VKCLOTH_VK_TRY(impl_->vk.vkDeviceWaitIdle(impl_->device), "vkDeviceWaitIdle");
  return {};
}

} // namespace vkcloth::gpu
