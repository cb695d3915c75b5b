// SPDX-License-Identifier: MIT
// A test "host application": its own Vulkan instance, device, queue, command buffer and fence,
// created through its own volk (host_vulkan.cpp), NOT through vkcloth::gpu::Context::create.
// Validation + synchronization validation on; messages are counted (and printed).
#pragma once

#include <atomic>
#include <cstdint>
#include <memory>
#include <string>

#include <vulkan/vulkan_core.h>

namespace vkcloth::gpu::test {

struct HostVulkan {
  VkInstance instance = VK_NULL_HANDLE;
  VkDebugUtilsMessengerEXT messenger = VK_NULL_HANDLE;
  VkPhysicalDevice physical_device = VK_NULL_HANDLE;
  VkDevice device = VK_NULL_HANDLE;
  std::uint32_t family = 0;
  VkQueue queue = VK_NULL_HANDLE;
  VkCommandPool pool = VK_NULL_HANDLE;
  VkCommandBuffer cmd = VK_NULL_HANDLE;
  VkFence fence = VK_NULL_HANDLE;
  PFN_vkGetInstanceProcAddr get_instance_proc_addr = nullptr;
  std::atomic<std::uint64_t> messages{0};
  /// Frames in flight (a renderer's ring): a command buffer and a fence each, used by
  /// begin_frame / submit_frame (created signalled, as a host's first frame expects).
  static constexpr std::uint32_t frames_in_flight = 2;
  VkCommandBuffer frame_cmd[frames_in_flight] = {};
  VkFence frame_fence[frames_in_flight] = {};
  /// Two binary semaphores for a compute -> graphics -> compute hand-over (submit_frame).
  VkSemaphore semaphores[2] = {};
  /// The graphics side of a hand-over: `family` itself, or with separate_compute a graphics
  /// family apart from `family` (a compute-only one); its own queue, pool, command buffer and
  /// fence (begin_graphics / submit_graphics).
  std::uint32_t graphics_family = 0;
  VkQueue graphics_queue = VK_NULL_HANDLE;
  VkCommandPool graphics_pool = VK_NULL_HANDLE; // null: `pool` (one family)
  VkCommandBuffer graphics_cmd = VK_NULL_HANDLE;
  VkFence graphics_fence = VK_NULL_HANDLE;

  /// Null with `error` set when no Vulkan 1.2 device with a graphics + compute queue (or no
  /// validation layer). `separate_compute`: `family` is a compute-only family and
  /// `graphics_family` another one with graphics (null when no device has both).
  static std::unique_ptr<HostVulkan> create(std::string& error, bool separate_compute = false);
  HostVulkan() = default;
  HostVulkan(const HostVulkan&) = delete;
  HostVulkan& operator=(const HostVulkan&) = delete;
  ~HostVulkan();

  /// Resets and begins `cmd`.
  bool begin();
  /// Ends `cmd`, submits it on `queue` and waits for `fence`.
  bool submit_and_wait();
  /// Waits for frame slot `k`'s previous submission (its fence), resets and begins its command
  /// buffer, as a renderer does at the start of a frame.
  bool begin_frame(std::uint32_t k);
  /// Ends frame slot `k`'s command buffer and submits it WITHOUT waiting (its fence signals);
  /// optionally waiting on `wait` at `wait_stage` and signalling `signal`.
  bool submit_frame(std::uint32_t k, VkSemaphore wait = VK_NULL_HANDLE, VkPipelineStageFlags wait_stage = 0,
                    VkSemaphore signal = VK_NULL_HANDLE);
  /// Records a copy of `bytes` from `src` into the host's scratch buffer at `at` (device memory,
  /// created on first use, freed with the device): a stand-in for a draw that reads the cloth's
  /// buffers (copies to one region from two frames must be ordered by the host, as any write).
  bool record_read(VkCommandBuffer target, VkBuffer src, VkDeviceSize bytes, VkDeviceSize at);
  VkBuffer scratch = VK_NULL_HANDLE;
  VkDeviceMemory scratch_memory = VK_NULL_HANDLE;
  /// begin_frame / submit_frame for graphics_cmd on graphics_queue.
  bool begin_graphics();
  bool submit_graphics(VkSemaphore wait, VkPipelineStageFlags wait_stage, VkSemaphore signal);
  /// Waits for every frame slot's last submission.
  bool wait_frames();
  /// The shared steps of the calls above: wait for a fence and reset it; reset and begin a command
  /// buffer for one submission; end it and submit it on `q` with an optional semaphore each way.
  bool wait_and_reset(VkFence f);
  static bool begin_one_time(VkCommandBuffer c);
  static bool end_and_submit(VkQueue q, VkCommandBuffer c, VkFence f, VkSemaphore wait,
                             VkPipelineStageFlags wait_stage, VkSemaphore signal);
  /// The host's device still works: creates and destroys a buffer, submits an empty command
  /// buffer and waits, vkDeviceWaitIdle.
  bool still_usable();
};

} // namespace vkcloth::gpu::test
