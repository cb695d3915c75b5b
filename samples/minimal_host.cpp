// SPDX-License-Identifier: MIT
// The smallest complete host of docs/embedding.md (shown there verbatim, checked by the test
// docs:embedding_minimal_host): its own Vulkan 1.2 instance, device and compute queue (through
// volk; a host linking the Vulkan loader drops the three volk calls), a cloth stepped in its own
// command buffer with a new dt every frame, the positions read back. Exit 0 on success, 1 on a
// failure, 4 without a Vulkan 1.2 device with a graphics + compute queue.
// [minimal-host]
#include <volk.h>

#include <cstdio>
#include <vector>

#include "vkcloth/vkcloth.hpp"

int main() {
  if (volkInitialize() != VK_SUCCESS)
    return std::puts("no Vulkan loader"), 4;
  VkApplicationInfo app{.sType = VK_STRUCTURE_TYPE_APPLICATION_INFO, .apiVersion = VK_API_VERSION_1_2};
  VkInstanceCreateInfo ici{.sType = VK_STRUCTURE_TYPE_INSTANCE_CREATE_INFO, .pApplicationInfo = &app};
  VkInstance instance;
  if (vkCreateInstance(&ici, nullptr, &instance) != VK_SUCCESS)
    return std::puts("no Vulkan 1.2 instance"), 4;
  volkLoadInstance(instance);

  // The first Vulkan 1.2 device with a graphics + compute queue family (vkcloth needs compute; the
  // host draws the cloth from the same queue).
  std::uint32_t count = 0;
  vkEnumeratePhysicalDevices(instance, &count, nullptr);
  std::vector<VkPhysicalDevice> devices(count);
  vkEnumeratePhysicalDevices(instance, &count, devices.data());
  VkPhysicalDevice gpu = VK_NULL_HANDLE;
  std::uint32_t family = 0;
  for (VkPhysicalDevice d : devices) {
    VkPhysicalDeviceProperties p;
    vkGetPhysicalDeviceProperties(d, &p);
    std::uint32_t n = 0;
    vkGetPhysicalDeviceQueueFamilyProperties(d, &n, nullptr);
    std::vector<VkQueueFamilyProperties> families(n);
    vkGetPhysicalDeviceQueueFamilyProperties(d, &n, families.data());
    for (std::uint32_t f = 0; f < n && !gpu; ++f)
      if (p.apiVersion >= VK_API_VERSION_1_2 &&
          (families[f].queueFlags & (VK_QUEUE_GRAPHICS_BIT | VK_QUEUE_COMPUTE_BIT)) ==
              (VK_QUEUE_GRAPHICS_BIT | VK_QUEUE_COMPUTE_BIT))
        gpu = d, family = f;
  }
  if (!gpu)
    return std::puts("no Vulkan 1.2 device with a graphics + compute queue"), 4;
  const float priority = 1.0f;
  VkDeviceQueueCreateInfo qci{.sType = VK_STRUCTURE_TYPE_DEVICE_QUEUE_CREATE_INFO,
                              .queueFamilyIndex = family,
                              .queueCount = 1,
                              .pQueuePriorities = &priority};
  VkDeviceCreateInfo dci{
      .sType = VK_STRUCTURE_TYPE_DEVICE_CREATE_INFO, .queueCreateInfoCount = 1, .pQueueCreateInfos = &qci};
  VkDevice device;
  if (vkCreateDevice(gpu, &dci, nullptr, &device) != VK_SUCCESS)
    return std::puts("vkCreateDevice failed"), 1;
  volkLoadDevice(device);
  VkQueue queue;
  vkGetDeviceQueue(device, family, 0, &queue);
  VkCommandPoolCreateInfo pci{.sType = VK_STRUCTURE_TYPE_COMMAND_POOL_CREATE_INFO,
                              .flags = VK_COMMAND_POOL_CREATE_RESET_COMMAND_BUFFER_BIT,
                              .queueFamilyIndex = family};
  VkCommandPool pool;
  vkCreateCommandPool(device, &pci, nullptr, &pool);
  VkCommandBufferAllocateInfo cai{.sType = VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO,
                                  .commandPool = pool,
                                  .level = VK_COMMAND_BUFFER_LEVEL_PRIMARY,
                                  .commandBufferCount = 1};
  VkCommandBuffer cmd;
  vkAllocateCommandBuffers(device, &cai, &cmd);

  int status = 0;
  { // vkcloth objects live in this scope: destroyed before the device
    vkcloth::gpu::HostHandles h{.instance = instance,
                                .physical_device = gpu,
                                .device = device,
                                .queue_family = family,
                                .queue = queue,
                                .get_instance_proc_addr = vkGetInstanceProcAddr};
    auto context = vkcloth::gpu::Context::adopt(h); // errors are values with a message
    auto solver = context
                      ? vkcloth::gpu::GpuSolver::create(*context, vkcloth::make_cloth({.nx = 32}).value(), {})
                      : vkcloth::Result<vkcloth::gpu::GpuSolver>(context.error());
    if (!solver)
      status = std::printf("vkcloth: %s\n", solver.error().message.c_str()) > 0;
    for (int frame = 0; frame < 60 && status == 0; ++frame) {
      VkCommandBufferBeginInfo begin{.sType = VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO};
      vkBeginCommandBuffer(cmd, &begin);
      const double frame_time =
          frame % 2 ? 1.0 / 60 : 1.0 / 50; // the host's frame timer: a new dt every frame
      if (!solver->record_steps(cmd, 2, {.dt = frame_time / 2}))
        status = 1;
      solver->record_barrier_to(cmd, VK_PIPELINE_STAGE_VERTEX_INPUT_BIT, VK_ACCESS_VERTEX_ATTRIBUTE_READ_BIT);
      vkEndCommandBuffer(cmd); // a renderer would draw solver->buffers() here
      VkSubmitInfo submit{
          .sType = VK_STRUCTURE_TYPE_SUBMIT_INFO, .commandBufferCount = 1, .pCommandBuffers = &cmd};
      vkQueueSubmit(queue, 1, &submit, VK_NULL_HANDLE);
      vkQueueWaitIdle(queue); // a real host waits on a fence of the frame in flight instead
    }
    if (status == 0) {
      auto positions = solver->positions(); // a readback: submits on the queue and waits
      if (!positions || !solver->check_divergence())
        status = 1;
      else
        std::printf("t = %.3f s, particle 0 at (%.3f, %.3f, %.3f)\n", solver->time(), (*positions)[0].x,
                    (*positions)[0].y, (*positions)[0].z);
    }
  }
  vkDestroyCommandPool(device, pool, nullptr);
  vkDestroyDevice(device, nullptr);
  vkDestroyInstance(instance, nullptr);
  return status;
}
// [/minimal-host]
