// SPDX-License-Identifier: MIT
// vkcloth_host_window: what a host program needs to show vkcloth in a window, shared by
// `vkcloth view` and the samples' windowed mode. A GLFW window and its Vulkan surface, the Context
// that presents to it, a swapchain (recreated on resize) with a depth buffer, the present render
// pass and its framebuffers, and one frame in flight (command buffer, fence, semaphores).
//
// Host code, not part of the engine: never installed or exported; the engine never sees GLFW.
// Vulkan is called through this library's own volk, loaded from the Context's handles (the
// engine's volk is renamed vkcloth_*); a host linking this library uses that volk too, so it
// includes this header before any other Vulkan header.
#pragma once

#include <volk.h>
#define GLFW_INCLUDE_NONE
#include <GLFW/glfw3.h>

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include <glm/vec3.hpp>

#include "vkcloth/gpu/context.hpp"
#include "vkcloth/result.hpp"

namespace vkcloth::host {

/// The frame being recorded: the host records its compute work into `cmd`, then draws between
/// Window::begin_render_pass and Window::end_render_pass_and_submit.
struct Frame {
  VkCommandBuffer cmd = VK_NULL_HANDLE;
  std::uint32_t image = 0; ///< the acquired swapchain image
  VkExtent2D extent{};
};

/// Set up in this order: open, add_presentation, create_context, create_render_pass (then the
/// host creates its pipelines for render_pass()), create_frame_resources. Each frame:
/// wait_last_frame, ensure_swapchain, begin_frame, begin_render_pass, end_render_pass_and_submit,
/// present.
class Window {
public:
  /// Why open() failed; each host words its own message (its messages are its contract).
  enum class OpenFailure { no_display, no_vulkan, no_window };

  Window() = default;
  Window(const Window&) = delete;
  Window& operator=(const Window&) = delete;
  /// Waits for the device, destroys the swapchain, the frame objects, the surface, the Context,
  /// the window, and terminates GLFW. Whatever the host created on the Context goes first.
  ~Window();

  /// Initialises GLFW and opens a window without a client API (Vulkan draws into it).
  std::optional<OpenFailure> open(std::uint32_t width, std::uint32_t height, const std::string& title);
  GLFWwindow* glfw() const { return window_; }
  /// GLFW's user pointer is the Window's (its resize callback); the host's own callbacks keep
  /// their state here.
  void set_host_pointer(void* p) { host_pointer_ = p; }
  static void* host_pointer(GLFWwindow* w);

  /// Adds to `options` what presenting to this window needs: GLFW's instance extensions,
  /// VK_KHR_swapchain, and a queue family filter that creates the surface and keeps the families
  /// that present to it. false: GLFW offers no Vulkan surface extensions for this display.
  bool add_presentation(gpu::ContextOptions& options);
  /// Creates the Context, points volk at its handles, and picks the surface's colour format
  /// (8-bit UNORM when offered: the same linear output as the offscreen PNGs) and a depth format.
  Result<void> create_context(const gpu::ContextOptions& options);
  gpu::Context& context() { return *context_; }

  /// The present render pass: colour cleared and left for presentation, depth cleared.
  Result<void> create_render_pass();
  VkRenderPass render_pass() const { return render_pass_; }
  /// The frame's command pool and buffer, fence and acquire semaphore, then the swapchain.
  Result<void> create_frame_resources();

  /// Waits until the last frame's submission completed: its command buffer may be reused and
  /// nothing the host submitted is pending.
  void wait_last_frame();
  void wait_idle();
  /// Recreates the swapchain when the window was resized or presentation found it out of date.
  /// false: the window is minimised (no swapchain); skip this frame.
  Result<bool> ensure_swapchain();
  /// The swapchain's size; 0 x 0 while there is none (minimised).
  VkExtent2D extent() const { return extent_; }
  /// Acquires the next image and begins the frame's command buffer. nullopt: the swapchain is
  /// out of date (recreated by the next ensure_swapchain); skip this frame.
  Result<std::optional<Frame>> begin_frame();
  /// Begins the present render pass on the frame's image, cleared to `background` and depth 1.
  void begin_render_pass(const Frame& f, const glm::vec3& background);
  /// Ends the render pass and the command buffer and submits it: it waits for the image's
  /// acquisition and signals the image's render-done semaphore and the frame fence.
  Result<void> end_render_pass_and_submit(const Frame& f);
  /// Presents the frame's image once rendered; out of date or suboptimal: recreated next frame.
  Result<void> present(const Frame& f);

private:
  static void on_resize(GLFWwindow* w, int width, int height);
  Result<void> create_swapchain();
  void destroy_swapchain_views();

  GLFWwindow* window_ = nullptr;
  void* host_pointer_ = nullptr;
  bool resized_ = false;
  VkSurfaceKHR surface_ = VK_NULL_HANDLE;
  std::optional<gpu::Context> context_;
  VkDevice device_ = VK_NULL_HANDLE;
  VkPhysicalDevice physical_ = VK_NULL_HANDLE;
  VkQueue queue_ = VK_NULL_HANDLE;
  std::uint32_t queue_family_ = 0;
  VkFormat color_format_ = VK_FORMAT_B8G8R8A8_UNORM, depth_format_ = VK_FORMAT_D32_SFLOAT;
  VkColorSpaceKHR color_space_ = VK_COLOR_SPACE_SRGB_NONLINEAR_KHR;
  VkRenderPass render_pass_ = VK_NULL_HANDLE;
  VkSwapchainKHR swapchain_ = VK_NULL_HANDLE;
  VkExtent2D extent_{};
  std::vector<VkImageView> views_;
  std::vector<VkFramebuffer> framebuffers_;
  std::vector<VkSemaphore> render_done_; // one per image: present waits on the one of its image
  VkImage depth_ = VK_NULL_HANDLE;
  VkDeviceMemory depth_memory_ = VK_NULL_HANDLE;
  VkImageView depth_view_ = VK_NULL_HANDLE;
  VkCommandPool pool_ = VK_NULL_HANDLE;
  VkCommandBuffer cmd_ = VK_NULL_HANDLE;
  VkFence in_flight_ = VK_NULL_HANDLE;
  VkSemaphore acquired_ = VK_NULL_HANDLE;
};

} // namespace vkcloth::host
