// SPDX-License-Identifier: MIT
// The test host's own Vulkan, through its own (unprefixed) volk: see host_vulkan.hpp.
#include <volk.h>

#include "host_vulkan.hpp"

#include <bit>

#include <cstdio>
#include <cstring>
#include <vector>

namespace vkcloth::gpu::test {
namespace {

VKAPI_ATTR VkBool32 VKAPI_CALL on_message(VkDebugUtilsMessageSeverityFlagBitsEXT,
                                          VkDebugUtilsMessageTypeFlagsEXT,
                                          const VkDebugUtilsMessengerCallbackDataEXT* data, void* user) {
  static_cast<HostVulkan*>(user)->messages.fetch_add(1);
  std::fprintf(stderr, "host validation: %s\n", data && data->pMessage ? data->pMessage : "?");
  return VK_FALSE;
}

} // namespace

std::unique_ptr<HostVulkan> HostVulkan::create(std::string& error, bool separate_compute) {
  if (volkInitialize() != VK_SUCCESS)
    return error = "no Vulkan loader", nullptr;
  auto h = std::make_unique<HostVulkan>();
  VkDebugUtilsMessengerCreateInfoEXT mi{};
  mi.sType = VK_STRUCTURE_TYPE_DEBUG_UTILS_MESSENGER_CREATE_INFO_EXT;
  mi.messageSeverity =
      VK_DEBUG_UTILS_MESSAGE_SEVERITY_WARNING_BIT_EXT | VK_DEBUG_UTILS_MESSAGE_SEVERITY_ERROR_BIT_EXT;
  mi.messageType = VK_DEBUG_UTILS_MESSAGE_TYPE_GENERAL_BIT_EXT |
                   VK_DEBUG_UTILS_MESSAGE_TYPE_VALIDATION_BIT_EXT |
                   VK_DEBUG_UTILS_MESSAGE_TYPE_PERFORMANCE_BIT_EXT;
  mi.pfnUserCallback = on_message;
  mi.pUserData = h.get();
  const VkValidationFeatureEnableEXT enables[] = {
      VK_VALIDATION_FEATURE_ENABLE_SYNCHRONIZATION_VALIDATION_EXT};
  VkValidationFeaturesEXT vf{};
  vf.sType = VK_STRUCTURE_TYPE_VALIDATION_FEATURES_EXT;
  vf.enabledValidationFeatureCount = 1;
  vf.pEnabledValidationFeatures = enables;
  vf.pNext = &mi;
  VkApplicationInfo app{};
  app.sType = VK_STRUCTURE_TYPE_APPLICATION_INFO;
  app.pApplicationName = "vkcloth test host";
  app.apiVersion = VK_API_VERSION_1_2;
  const char* layers[] = {"VK_LAYER_KHRONOS_validation"};
  const char* extensions[] = {VK_EXT_DEBUG_UTILS_EXTENSION_NAME, VK_EXT_VALIDATION_FEATURES_EXTENSION_NAME};
  VkInstanceCreateInfo ci{};
  ci.sType = VK_STRUCTURE_TYPE_INSTANCE_CREATE_INFO;
  ci.pNext = &vf;
  ci.pApplicationInfo = &app;
  ci.enabledLayerCount = 1;
  ci.ppEnabledLayerNames = layers;
  ci.enabledExtensionCount = 2;
  ci.ppEnabledExtensionNames = extensions;
  if (vkCreateInstance(&ci, nullptr, &h->instance) != VK_SUCCESS)
    return error = "vkCreateInstance (with validation) failed", nullptr;
  volkLoadInstanceOnly(h->instance);
  h->get_instance_proc_addr = vkGetInstanceProcAddr;
  vkCreateDebugUtilsMessengerEXT(h->instance, &mi, nullptr, &h->messenger);
  std::uint32_t n = 0;
  vkEnumeratePhysicalDevices(h->instance, &n, nullptr);
  std::vector<VkPhysicalDevice> pds(n);
  vkEnumeratePhysicalDevices(h->instance, &n, pds.data());
  for (VkPhysicalDevice pd : pds) {
    VkPhysicalDeviceProperties props;
    vkGetPhysicalDeviceProperties(pd, &props);
    if (props.apiVersion < VK_API_VERSION_1_2)
      continue;
    std::uint32_t nf = 0;
    vkGetPhysicalDeviceQueueFamilyProperties(pd, &nf, nullptr);
    std::vector<VkQueueFamilyProperties> fams(nf);
    vkGetPhysicalDeviceQueueFamilyProperties(pd, &nf, fams.data());
    constexpr VkQueueFlags both = VK_QUEUE_GRAPHICS_BIT | VK_QUEUE_COMPUTE_BIT;
    std::uint32_t graphics = nf, compute_only = nf;
    for (std::uint32_t f = 0; f < nf; ++f) {
      if ((fams[f].queueFlags & both) == both && graphics == nf)
        graphics = f;
      if ((fams[f].queueFlags & both) == VK_QUEUE_COMPUTE_BIT && compute_only == nf)
        compute_only = f;
    }
    if (h->physical_device || graphics == nf || (separate_compute && compute_only == nf))
      continue;
    h->physical_device = pd;
    h->family = separate_compute ? compute_only : graphics;
    h->graphics_family = graphics;
  }
  if (!h->physical_device)
    return error = separate_compute
                       ? "no Vulkan 1.2 device with a compute-only queue family beside a graphics one"
                       : "no Vulkan 1.2 device with a graphics + compute queue",
           nullptr;
  const float priority = 1.0f;
  VkDeviceQueueCreateInfo qi[2]{};
  for (std::uint32_t k = 0; k < 2; ++k) {
    qi[k].sType = VK_STRUCTURE_TYPE_DEVICE_QUEUE_CREATE_INFO;
    qi[k].queueFamilyIndex = k == 0 ? h->family : h->graphics_family;
    qi[k].queueCount = 1;
    qi[k].pQueuePriorities = &priority;
  }
  VkDeviceCreateInfo di{};
  di.sType = VK_STRUCTURE_TYPE_DEVICE_CREATE_INFO;
  di.queueCreateInfoCount = h->graphics_family == h->family ? 1 : 2;
  di.pQueueCreateInfos = qi;
  if (vkCreateDevice(h->physical_device, &di, nullptr, &h->device) != VK_SUCCESS)
    return error = "vkCreateDevice failed", nullptr;
  volkLoadDevice(h->device);
  vkGetDeviceQueue(h->device, h->family, 0, &h->queue);
  vkGetDeviceQueue(h->device, h->graphics_family, 0, &h->graphics_queue);
  VkCommandPoolCreateInfo cp{};
  cp.sType = VK_STRUCTURE_TYPE_COMMAND_POOL_CREATE_INFO;
  cp.flags = VK_COMMAND_POOL_CREATE_RESET_COMMAND_BUFFER_BIT;
  cp.queueFamilyIndex = h->family;
  vkCreateCommandPool(h->device, &cp, nullptr, &h->pool);
  VkCommandBufferAllocateInfo ca{};
  ca.sType = VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO;
  ca.commandPool = h->pool;
  ca.level = VK_COMMAND_BUFFER_LEVEL_PRIMARY;
  ca.commandBufferCount = 1;
  vkAllocateCommandBuffers(h->device, &ca, &h->cmd);
  VkFenceCreateInfo fi{};
  fi.sType = VK_STRUCTURE_TYPE_FENCE_CREATE_INFO;
  vkCreateFence(h->device, &fi, nullptr, &h->fence);
  ca.commandBufferCount = frames_in_flight;
  vkAllocateCommandBuffers(h->device, &ca, h->frame_cmd);
  fi.flags = VK_FENCE_CREATE_SIGNALED_BIT;
  for (VkFence& f : h->frame_fence)
    vkCreateFence(h->device, &fi, nullptr, &f);
  VkSemaphoreCreateInfo si{};
  si.sType = VK_STRUCTURE_TYPE_SEMAPHORE_CREATE_INFO;
  for (VkSemaphore& s : h->semaphores)
    vkCreateSemaphore(h->device, &si, nullptr, &s);
  if (h->graphics_family != h->family) {
    cp.queueFamilyIndex = h->graphics_family;
    vkCreateCommandPool(h->device, &cp, nullptr, &h->graphics_pool);
  }
  ca.commandPool = h->graphics_pool ? h->graphics_pool : h->pool;
  ca.commandBufferCount = 1;
  vkAllocateCommandBuffers(h->device, &ca, &h->graphics_cmd);
  vkCreateFence(h->device, &fi, nullptr, &h->graphics_fence); // signalled, as the frame fences
  return h;
}

HostVulkan::~HostVulkan() {
  if (device) {
    vkDeviceWaitIdle(device);
    if (fence)
      vkDestroyFence(device, fence, nullptr);
    for (VkFence f : frame_fence)
      if (f)
        vkDestroyFence(device, f, nullptr);
    if (graphics_fence)
      vkDestroyFence(device, graphics_fence, nullptr);
    if (graphics_pool)
      vkDestroyCommandPool(device, graphics_pool, nullptr);
    if (scratch)
      vkDestroyBuffer(device, scratch, nullptr);
    if (scratch_memory)
      vkFreeMemory(device, scratch_memory, nullptr);
    for (VkSemaphore s : semaphores)
      if (s)
        vkDestroySemaphore(device, s, nullptr);
    if (pool)
      vkDestroyCommandPool(device, pool, nullptr);
    vkDestroyDevice(device, nullptr);
  }
  if (messenger)
    vkDestroyDebugUtilsMessengerEXT(instance, messenger, nullptr);
  if (instance)
    vkDestroyInstance(instance, nullptr);
}

bool HostVulkan::begin() {
  return begin_one_time(cmd);
}

bool HostVulkan::submit_and_wait() {
  if (!end_and_submit(queue, cmd, fence, VK_NULL_HANDLE, 0, VK_NULL_HANDLE))
    return false;
  const bool ok = vkWaitForFences(device, 1, &fence, VK_TRUE, UINT64_MAX) == VK_SUCCESS;
  vkResetFences(device, 1, &fence);
  return ok;
}

bool HostVulkan::begin_frame(std::uint32_t k) {
  return wait_and_reset(frame_fence[k]) && begin_one_time(frame_cmd[k]);
}

bool HostVulkan::submit_frame(std::uint32_t k, VkSemaphore wait, VkPipelineStageFlags wait_stage,
                              VkSemaphore signal) {
  return end_and_submit(queue, frame_cmd[k], frame_fence[k], wait, wait_stage, signal);
}

bool HostVulkan::record_read(VkCommandBuffer target, VkBuffer src, VkDeviceSize bytes, VkDeviceSize at) {
  constexpr VkDeviceSize capacity = 1 << 20;
  if (at + bytes > capacity)
    return false;
  if (!scratch) {
    VkBufferCreateInfo bi{};
    bi.sType = VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO;
    bi.size = capacity;
    bi.usage = VK_BUFFER_USAGE_TRANSFER_DST_BIT;
    if (vkCreateBuffer(device, &bi, nullptr, &scratch) != VK_SUCCESS)
      return false;
    VkMemoryRequirements req;
    vkGetBufferMemoryRequirements(device, scratch, &req);
    VkMemoryAllocateInfo ai{};
    ai.sType = VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO;
    ai.allocationSize = req.size;
    ai.memoryTypeIndex = std::uint32_t(std::countr_zero(req.memoryTypeBits)); // any type fits a copy target
    if (vkAllocateMemory(device, &ai, nullptr, &scratch_memory) != VK_SUCCESS ||
        vkBindBufferMemory(device, scratch, scratch_memory, 0) != VK_SUCCESS)
      return false;
  }
  const VkBufferCopy region{0, at, bytes};
  vkCmdCopyBuffer(target, src, scratch, 1, &region);
  return true;
}

bool HostVulkan::begin_graphics() {
  return wait_and_reset(graphics_fence) && begin_one_time(graphics_cmd);
}

bool HostVulkan::submit_graphics(VkSemaphore wait, VkPipelineStageFlags wait_stage, VkSemaphore signal) {
  return end_and_submit(graphics_queue, graphics_cmd, graphics_fence, wait, wait_stage, signal);
}

bool HostVulkan::wait_and_reset(VkFence f) {
  return vkWaitForFences(device, 1, &f, VK_TRUE, UINT64_MAX) == VK_SUCCESS &&
         vkResetFences(device, 1, &f) == VK_SUCCESS;
}

bool HostVulkan::begin_one_time(VkCommandBuffer c) {
  if (vkResetCommandBuffer(c, 0) != VK_SUCCESS)
    return false;
  VkCommandBufferBeginInfo bi{};
  bi.sType = VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO;
  bi.flags = VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT;
  return vkBeginCommandBuffer(c, &bi) == VK_SUCCESS;
}

bool HostVulkan::end_and_submit(VkQueue q, VkCommandBuffer c, VkFence f, VkSemaphore wait,
                                VkPipelineStageFlags wait_stage, VkSemaphore signal) {
  if (vkEndCommandBuffer(c) != VK_SUCCESS)
    return false;
  VkSubmitInfo si{};
  si.sType = VK_STRUCTURE_TYPE_SUBMIT_INFO;
  si.commandBufferCount = 1;
  si.pCommandBuffers = &c;
  si.waitSemaphoreCount = wait ? 1 : 0;
  si.pWaitSemaphores = &wait;
  si.pWaitDstStageMask = &wait_stage;
  si.signalSemaphoreCount = signal ? 1 : 0;
  si.pSignalSemaphores = &signal;
  return vkQueueSubmit(q, 1, &si, f) == VK_SUCCESS;
}

bool HostVulkan::wait_frames() {
  return vkWaitForFences(device, frames_in_flight, frame_fence, VK_TRUE, UINT64_MAX) == VK_SUCCESS &&
         vkWaitForFences(device, 1, &graphics_fence, VK_TRUE, UINT64_MAX) == VK_SUCCESS;
}

bool HostVulkan::still_usable() {
  VkBufferCreateInfo bi{};
  bi.sType = VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO;
  bi.size = 256;
  bi.usage = VK_BUFFER_USAGE_STORAGE_BUFFER_BIT;
  VkBuffer b = VK_NULL_HANDLE;
  if (vkCreateBuffer(device, &bi, nullptr, &b) != VK_SUCCESS)
    return false;
  vkDestroyBuffer(device, b, nullptr);
  if (!begin() || !submit_and_wait())
    return false;
  return vkDeviceWaitIdle(device) == VK_SUCCESS;
}

} // namespace vkcloth::gpu::test
