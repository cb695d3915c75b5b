// SPDX-License-Identifier: MIT
// Vulkan loading and instance creation for the Context: volk (its globals behind one mutex, the
// system loader's vkGetInstanceProcAddr found once), the instance function table, the instance
// itself with the validation layer and synchronization validation when asked, the debug messenger
// that counts (and prints) validation messages per Context and per process, and the LSan keep-alive
// of the loaded Vulkan libraries.
#include "context_setup.hpp"

#include <algorithm>
#include <cstdio>
#include <cstring>

#include <fmt/format.h>
#include <fmt/ranges.h>

#if defined(__SANITIZE_ADDRESS__)
#include <dlfcn.h>
#include <link.h>
#endif

namespace vkcloth::gpu {

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

namespace {
PFN_vkGetInstanceProcAddr g_loader_gipa = nullptr; // the system loader's, once found
} // namespace

/// Points volk at `gipa` (the loader's when null); `used` receives the one in use.
Result<void> init_volk_locked(PFN_vkGetInstanceProcAddr gipa, PFN_vkGetInstanceProcAddr* used) {
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

std::string version_string(std::uint32_t v) {
  return fmt::format("{}.{}.{}", VK_API_VERSION_MAJOR(v), VK_API_VERSION_MINOR(v), VK_API_VERSION_PATCH(v));
}

namespace {

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

} // namespace

std::uint64_t Context::process_validation_message_count() {
  return g_process_messages.load(std::memory_order_relaxed);
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

namespace {

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

} // namespace

/// Creates an instance (validation optional; `impl` receives messages from creation on).
Result<OwnedInstance> create_instance(Context::Impl* impl, bool validation,
                                      const std::vector<const char*>& extra_extensions) {
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

} // namespace vkcloth::gpu
