// SPDX-License-Identifier: MIT
// The Context: Context::create() (an instance, the chosen device, its queue) and Context::adopt()
// (a host's handles), the Impl that holds them (device function table, memory types, destruction
// in order) and the Context's accessors; also vk_result_name() and vk_error() for every Vulkan
// error of the engine. Loading and the instance are in context_instance.cpp, the device choice in
// context_devices.cpp.
#include "context_setup.hpp"

#include "internal/pipelines.hpp"

#include <algorithm>
#include <cstdlib>
#include <cstring>

#include <fmt/format.h>

namespace vkcloth::gpu {
namespace {

bool env_flag(const char* name) {
  const char* v = std::getenv(name);
  return v && *v && std::strcmp(v, "0") != 0 && std::strcmp(v, "false") != 0;
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
std::int64_t Context::live_allocation_count() const {
  return impl_->live_allocations.load(std::memory_order_relaxed);
}
Result<void> Context::wait_idle() const {
  VKCLOTH_VK_TRY(impl_->vk.vkDeviceWaitIdle(impl_->device), "vkDeviceWaitIdle");
  return {};
}

} // namespace vkcloth::gpu
