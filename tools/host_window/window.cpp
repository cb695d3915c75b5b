// SPDX-License-Identifier: MIT
#include "vkcloth_host_window/window.hpp"

#include <algorithm>

#include <fmt/format.h>

namespace vkcloth::host {
namespace {

Error vk_fail(VkResult r, const char* what) {
  return make_error(ErrorCode::vulkan, fmt::format("{} failed (VkResult {})", what, static_cast<int>(r)));
}

} // namespace

Window::~Window() {
  if (device_) {
    vkDeviceWaitIdle(device_);
    destroy_swapchain_views();
    if (swapchain_)
      vkDestroySwapchainKHR(device_, swapchain_, nullptr);
    if (render_pass_)
      vkDestroyRenderPass(device_, render_pass_, nullptr);
    if (pool_)
      vkDestroyCommandPool(device_, pool_, nullptr);
    if (in_flight_)
      vkDestroyFence(device_, in_flight_, nullptr);
    if (acquired_)
      vkDestroySemaphore(device_, acquired_, nullptr);
  }
  if (surface_ && context_)
    vkDestroySurfaceKHR(context_->handles().instance, surface_, nullptr);
  context_.reset(); // destroys the device and instance
  if (window_)
    glfwDestroyWindow(window_);
  glfwTerminate();
}

std::optional<Window::OpenFailure> Window::open(std::uint32_t width, std::uint32_t height,
                                                const std::string& title) {
  if (!glfwInit())
    return OpenFailure::no_display;
  if (!glfwVulkanSupported())
    return OpenFailure::no_vulkan;
  glfwWindowHint(GLFW_CLIENT_API, GLFW_NO_API);
  window_ = glfwCreateWindow(int(width), int(height), title.c_str(), nullptr, nullptr);
  if (!window_)
    return OpenFailure::no_window;
  glfwSetWindowUserPointer(window_, this);
  glfwSetFramebufferSizeCallback(window_, on_resize);
  return std::nullopt;
}

void* Window::host_pointer(GLFWwindow* w) {
  return static_cast<Window*>(glfwGetWindowUserPointer(w))->host_pointer_;
}

void Window::on_resize(GLFWwindow* w, int, int) {
  static_cast<Window*>(glfwGetWindowUserPointer(w))->resized_ = true;
}

bool Window::add_presentation(gpu::ContextOptions& options) {
  std::uint32_t count = 0;
  const char** exts = glfwGetRequiredInstanceExtensions(&count);
  if (!exts)
    return false;
  options.instance_extensions.assign(exts, exts + count);
  options.device_extensions = {VK_KHR_SWAPCHAIN_EXTENSION_NAME};
  // Called per queue family once the instance exists: the surface is created from that instance
  // the first time (before this library's volk is loaded, hence GLFW's loader lookup).
  options.queue_family_filter = [this](VkInstance instance, VkPhysicalDevice pd, std::uint32_t family) {
    if (!surface_ && glfwCreateWindowSurface(instance, window_, nullptr, &surface_) != VK_SUCCESS)
      return false;
    auto support = reinterpret_cast<PFN_vkGetPhysicalDeviceSurfaceSupportKHR>(
        glfwGetInstanceProcAddress(instance, "vkGetPhysicalDeviceSurfaceSupportKHR"));
    VkBool32 ok = VK_FALSE;
    return support && support(pd, family, surface_, &ok) == VK_SUCCESS && ok;
  };
  return true;
}

Result<void> Window::create_context(const gpu::ContextOptions& options) {
  auto ctx = gpu::Context::create(options);
  if (!ctx) {
    surface_ = VK_NULL_HANDLE; // went with the failed Context's instance
    return ctx.error();
  }
  context_.emplace(std::move(*ctx));
  const gpu::HostHandles h = context_->handles();
  volkInitializeCustom(h.get_instance_proc_addr);
  volkLoadInstanceOnly(h.instance);
  volkLoadDevice(h.device);
  device_ = h.device;
  physical_ = h.physical_device;
  queue_ = h.queue;
  queue_family_ = h.queue_family;

  std::uint32_t nf = 0;
  vkGetPhysicalDeviceSurfaceFormatsKHR(physical_, surface_, &nf, nullptr);
  std::vector<VkSurfaceFormatKHR> formats(nf);
  vkGetPhysicalDeviceSurfaceFormatsKHR(physical_, surface_, &nf, formats.data());
  if (formats.empty())
    return make_error(ErrorCode::unsupported, "the window surface offers no format");
  color_format_ = formats[0].format;
  color_space_ = formats[0].colorSpace;
  for (const auto& f : formats)
    if (f.format == VK_FORMAT_B8G8R8A8_UNORM || f.format == VK_FORMAT_R8G8B8A8_UNORM) {
      color_format_ = f.format; // same (linear) output as the offscreen PNGs
      color_space_ = f.colorSpace;
      break;
    }
  for (VkFormat f : {VK_FORMAT_D32_SFLOAT, VK_FORMAT_X8_D24_UNORM_PACK32, VK_FORMAT_D24_UNORM_S8_UINT,
                     VK_FORMAT_D16_UNORM}) {
    VkFormatProperties fp;
    vkGetPhysicalDeviceFormatProperties(physical_, f, &fp);
    if (fp.optimalTilingFeatures & VK_FORMAT_FEATURE_DEPTH_STENCIL_ATTACHMENT_BIT) {
      depth_format_ = f;
      break;
    }
  }
  return {};
}

Result<void> Window::create_render_pass() {
  VkAttachmentDescription att[2]{};
  att[0].format = color_format_;
  att[0].samples = VK_SAMPLE_COUNT_1_BIT;
  att[0].loadOp = VK_ATTACHMENT_LOAD_OP_CLEAR;
  att[0].storeOp = VK_ATTACHMENT_STORE_OP_STORE;
  att[0].stencilLoadOp = VK_ATTACHMENT_LOAD_OP_DONT_CARE;
  att[0].stencilStoreOp = VK_ATTACHMENT_STORE_OP_DONT_CARE;
  att[0].initialLayout = VK_IMAGE_LAYOUT_UNDEFINED; // cleared: the old contents do not matter
  att[0].finalLayout = VK_IMAGE_LAYOUT_PRESENT_SRC_KHR;
  att[1] = att[0];
  att[1].format = depth_format_;
  att[1].storeOp = VK_ATTACHMENT_STORE_OP_DONT_CARE;
  att[1].finalLayout = VK_IMAGE_LAYOUT_DEPTH_STENCIL_ATTACHMENT_OPTIMAL;
  const VkAttachmentReference color_ref{0, VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL};
  const VkAttachmentReference depth_ref{1, VK_IMAGE_LAYOUT_DEPTH_STENCIL_ATTACHMENT_OPTIMAL};
  VkSubpassDescription sub{};
  sub.pipelineBindPoint = VK_PIPELINE_BIND_POINT_GRAPHICS;
  sub.colorAttachmentCount = 1;
  sub.pColorAttachments = &color_ref;
  sub.pDepthStencilAttachment = &depth_ref;
  VkSubpassDependency dep[2]{};
  // Before: the acquire semaphore is waited at COLOR_ATTACHMENT_OUTPUT, so the image's layout
  // transition and clear wait for it; the previous frame's depth writes finish before this clear
  // (one depth image serves every frame).
  dep[0].srcSubpass = VK_SUBPASS_EXTERNAL;
  dep[0].dstSubpass = 0;
  dep[0].srcStageMask =
      VK_PIPELINE_STAGE_COLOR_ATTACHMENT_OUTPUT_BIT | VK_PIPELINE_STAGE_LATE_FRAGMENT_TESTS_BIT;
  dep[0].srcAccessMask = VK_ACCESS_DEPTH_STENCIL_ATTACHMENT_WRITE_BIT;
  dep[0].dstStageMask = VK_PIPELINE_STAGE_COLOR_ATTACHMENT_OUTPUT_BIT |
                        VK_PIPELINE_STAGE_EARLY_FRAGMENT_TESTS_BIT |
                        VK_PIPELINE_STAGE_LATE_FRAGMENT_TESTS_BIT;
  dep[0].dstAccessMask = VK_ACCESS_COLOR_ATTACHMENT_WRITE_BIT | VK_ACCESS_DEPTH_STENCIL_ATTACHMENT_READ_BIT |
                         VK_ACCESS_DEPTH_STENCIL_ATTACHMENT_WRITE_BIT;
  // After: colour writes complete before presentation (the render-done semaphore follows).
  dep[1].srcSubpass = 0;
  dep[1].dstSubpass = VK_SUBPASS_EXTERNAL;
  dep[1].srcStageMask = VK_PIPELINE_STAGE_COLOR_ATTACHMENT_OUTPUT_BIT;
  dep[1].srcAccessMask = VK_ACCESS_COLOR_ATTACHMENT_WRITE_BIT;
  dep[1].dstStageMask = VK_PIPELINE_STAGE_BOTTOM_OF_PIPE_BIT;
  dep[1].dstAccessMask = 0;
  VkRenderPassCreateInfo rp{};
  rp.sType = VK_STRUCTURE_TYPE_RENDER_PASS_CREATE_INFO;
  rp.attachmentCount = 2;
  rp.pAttachments = att;
  rp.subpassCount = 1;
  rp.pSubpasses = &sub;
  rp.dependencyCount = 2;
  rp.pDependencies = dep;
  if (VkResult r = vkCreateRenderPass(device_, &rp, nullptr, &render_pass_); r != VK_SUCCESS)
    return vk_fail(r, "vkCreateRenderPass (window)");
  return {};
}

Result<void> Window::create_frame_resources() {
  VkCommandPoolCreateInfo cp{};
  cp.sType = VK_STRUCTURE_TYPE_COMMAND_POOL_CREATE_INFO;
  cp.flags = VK_COMMAND_POOL_CREATE_RESET_COMMAND_BUFFER_BIT;
  cp.queueFamilyIndex = queue_family_;
  if (VkResult r = vkCreateCommandPool(device_, &cp, nullptr, &pool_); r != VK_SUCCESS)
    return vk_fail(r, "vkCreateCommandPool");
  VkCommandBufferAllocateInfo ca{};
  ca.sType = VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO;
  ca.commandPool = pool_;
  ca.level = VK_COMMAND_BUFFER_LEVEL_PRIMARY;
  ca.commandBufferCount = 1;
  if (VkResult r = vkAllocateCommandBuffers(device_, &ca, &cmd_); r != VK_SUCCESS)
    return vk_fail(r, "vkAllocateCommandBuffers");
  VkFenceCreateInfo fi{};
  fi.sType = VK_STRUCTURE_TYPE_FENCE_CREATE_INFO;
  fi.flags = VK_FENCE_CREATE_SIGNALED_BIT; // the first wait_last_frame() does not block
  if (VkResult r = vkCreateFence(device_, &fi, nullptr, &in_flight_); r != VK_SUCCESS)
    return vk_fail(r, "vkCreateFence");
  VkSemaphoreCreateInfo si{};
  si.sType = VK_STRUCTURE_TYPE_SEMAPHORE_CREATE_INFO;
  if (VkResult r = vkCreateSemaphore(device_, &si, nullptr, &acquired_); r != VK_SUCCESS)
    return vk_fail(r, "vkCreateSemaphore");
  return create_swapchain();
}

void Window::destroy_swapchain_views() {
  for (VkFramebuffer f : framebuffers_)
    vkDestroyFramebuffer(device_, f, nullptr);
  for (VkImageView v : views_)
    vkDestroyImageView(device_, v, nullptr);
  for (VkSemaphore s : render_done_)
    vkDestroySemaphore(device_, s, nullptr);
  if (depth_view_)
    vkDestroyImageView(device_, depth_view_, nullptr);
  if (depth_)
    vkDestroyImage(device_, depth_, nullptr);
  if (depth_memory_)
    vkFreeMemory(device_, depth_memory_, nullptr);
  framebuffers_.clear();
  views_.clear();
  render_done_.clear();
  depth_view_ = VK_NULL_HANDLE;
  depth_ = VK_NULL_HANDLE;
  depth_memory_ = VK_NULL_HANDLE;
  extent_ = {};
  // swapchain_ stays: it is the next one's oldSwapchain, destroyed once that one exists
}

Result<void> Window::create_swapchain() {
  VkSurfaceCapabilitiesKHR caps{};
  if (VkResult r = vkGetPhysicalDeviceSurfaceCapabilitiesKHR(physical_, surface_, &caps); r != VK_SUCCESS)
    return vk_fail(r, "vkGetPhysicalDeviceSurfaceCapabilitiesKHR");
  int fw = 0, fh = 0;
  glfwGetFramebufferSize(window_, &fw, &fh);
  VkExtent2D extent = caps.currentExtent;
  if (extent.width == UINT32_MAX) // the surface takes the swapchain's size: the framebuffer's
    extent = {
        std::clamp<std::uint32_t>(std::uint32_t(fw), caps.minImageExtent.width, caps.maxImageExtent.width),
        std::clamp<std::uint32_t>(std::uint32_t(fh), caps.minImageExtent.height, caps.maxImageExtent.height)};
  if (extent.width == 0 || extent.height == 0)
    return {}; // minimised: no swapchain until restored
  std::uint32_t count = std::max(caps.minImageCount, 2u);
  if (caps.maxImageCount)
    count = std::min(count, caps.maxImageCount);
  VkSwapchainCreateInfoKHR ci{};
  ci.sType = VK_STRUCTURE_TYPE_SWAPCHAIN_CREATE_INFO_KHR;
  ci.surface = surface_;
  ci.minImageCount = count;
  ci.imageFormat = color_format_;
  ci.imageColorSpace = color_space_;
  ci.imageExtent = extent;
  ci.imageArrayLayers = 1;
  ci.imageUsage = VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT;
  ci.imageSharingMode = VK_SHARING_MODE_EXCLUSIVE;
  ci.preTransform = caps.currentTransform;
  ci.compositeAlpha = (caps.supportedCompositeAlpha & VK_COMPOSITE_ALPHA_OPAQUE_BIT_KHR)
                          ? VK_COMPOSITE_ALPHA_OPAQUE_BIT_KHR
                          : VK_COMPOSITE_ALPHA_INHERIT_BIT_KHR;
  ci.presentMode = VK_PRESENT_MODE_FIFO_KHR; // always supported
  ci.clipped = VK_TRUE;
  ci.oldSwapchain = swapchain_;
  VkSwapchainKHR handle = VK_NULL_HANDLE;
  const VkResult cr = vkCreateSwapchainKHR(device_, &ci, nullptr, &handle);
  if (swapchain_) // retired by the create (the device was idle before it): nothing uses it now
    vkDestroySwapchainKHR(device_, swapchain_, nullptr);
  swapchain_ = handle;
  if (cr != VK_SUCCESS)
    return vk_fail(cr, "vkCreateSwapchainKHR");
  std::uint32_t n = 0;
  vkGetSwapchainImagesKHR(device_, swapchain_, &n, nullptr);
  std::vector<VkImage> images(n);
  vkGetSwapchainImagesKHR(device_, swapchain_, &n, images.data());

  // One depth image of the window's size serves every frame (one frame in flight).
  VkImageCreateInfo ii{};
  ii.sType = VK_STRUCTURE_TYPE_IMAGE_CREATE_INFO;
  ii.imageType = VK_IMAGE_TYPE_2D;
  ii.format = depth_format_;
  ii.extent = {extent.width, extent.height, 1};
  ii.mipLevels = ii.arrayLayers = 1;
  ii.samples = VK_SAMPLE_COUNT_1_BIT;
  ii.tiling = VK_IMAGE_TILING_OPTIMAL;
  ii.usage = VK_IMAGE_USAGE_DEPTH_STENCIL_ATTACHMENT_BIT;
  if (VkResult r = vkCreateImage(device_, &ii, nullptr, &depth_); r != VK_SUCCESS)
    return vk_fail(r, "vkCreateImage (depth)");
  VkMemoryRequirements req;
  vkGetImageMemoryRequirements(device_, depth_, &req);
  VkPhysicalDeviceMemoryProperties mp;
  vkGetPhysicalDeviceMemoryProperties(physical_, &mp);
  std::uint32_t type = UINT32_MAX; // the first device-local type allowed, else the first allowed
  for (std::uint32_t i = 0; i < mp.memoryTypeCount && type == UINT32_MAX; ++i)
    if ((req.memoryTypeBits & (1u << i)) &&
        (mp.memoryTypes[i].propertyFlags & VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT))
      type = i;
  for (std::uint32_t i = 0; i < mp.memoryTypeCount && type == UINT32_MAX; ++i)
    if (req.memoryTypeBits & (1u << i))
      type = i;
  VkMemoryAllocateInfo ai{};
  ai.sType = VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO;
  ai.allocationSize = req.size;
  ai.memoryTypeIndex = type;
  if (VkResult r = vkAllocateMemory(device_, &ai, nullptr, &depth_memory_); r != VK_SUCCESS)
    return vk_fail(r, "vkAllocateMemory (depth)");
  vkBindImageMemory(device_, depth_, depth_memory_, 0);
  VkImageViewCreateInfo vi{};
  vi.sType = VK_STRUCTURE_TYPE_IMAGE_VIEW_CREATE_INFO;
  vi.viewType = VK_IMAGE_VIEW_TYPE_2D;
  vi.image = depth_;
  vi.format = depth_format_;
  vi.subresourceRange = {VK_IMAGE_ASPECT_DEPTH_BIT, 0, 1, 0, 1};
  if (VkResult r = vkCreateImageView(device_, &vi, nullptr, &depth_view_); r != VK_SUCCESS)
    return vk_fail(r, "vkCreateImageView (depth)");

  for (VkImage img : images) {
    vi.image = img;
    vi.format = color_format_;
    vi.subresourceRange = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 1, 0, 1};
    VkImageView view = VK_NULL_HANDLE;
    if (VkResult r = vkCreateImageView(device_, &vi, nullptr, &view); r != VK_SUCCESS)
      return vk_fail(r, "vkCreateImageView (swapchain)");
    views_.push_back(view);
    const VkImageView atts[2] = {view, depth_view_};
    VkFramebufferCreateInfo fb{};
    fb.sType = VK_STRUCTURE_TYPE_FRAMEBUFFER_CREATE_INFO;
    fb.renderPass = render_pass_;
    fb.attachmentCount = 2;
    fb.pAttachments = atts;
    fb.width = extent.width;
    fb.height = extent.height;
    fb.layers = 1;
    VkFramebuffer f = VK_NULL_HANDLE;
    if (VkResult r = vkCreateFramebuffer(device_, &fb, nullptr, &f); r != VK_SUCCESS)
      return vk_fail(r, "vkCreateFramebuffer");
    framebuffers_.push_back(f);
    VkSemaphoreCreateInfo si{};
    si.sType = VK_STRUCTURE_TYPE_SEMAPHORE_CREATE_INFO;
    VkSemaphore s = VK_NULL_HANDLE;
    if (VkResult r = vkCreateSemaphore(device_, &si, nullptr, &s); r != VK_SUCCESS)
      return vk_fail(r, "vkCreateSemaphore");
    render_done_.push_back(s);
  }
  extent_ = extent;
  return {};
}

void Window::wait_last_frame() {
  vkWaitForFences(device_, 1, &in_flight_, VK_TRUE, UINT64_MAX);
}

void Window::wait_idle() {
  if (device_)
    vkDeviceWaitIdle(device_);
}

Result<bool> Window::ensure_swapchain() {
  if (resized_ || views_.empty()) {
    resized_ = false;
    vkDeviceWaitIdle(device_); // the old images, views and depth may still be in use
    destroy_swapchain_views();
    if (auto r = create_swapchain(); !r)
      return r.error();
  }
  return !views_.empty();
}

Result<std::optional<Frame>> Window::begin_frame() {
  Frame f;
  const VkResult r =
      vkAcquireNextImageKHR(device_, swapchain_, UINT64_MAX, acquired_, VK_NULL_HANDLE, &f.image);
  if (r == VK_ERROR_OUT_OF_DATE_KHR) {
    resized_ = true;
    return std::optional<Frame>{};
  }
  if (r != VK_SUCCESS && r != VK_SUBOPTIMAL_KHR) // suboptimal still presents; present() flags it
    return vk_fail(r, "vkAcquireNextImageKHR");
  vkResetFences(device_, 1, &in_flight_); // only now: an acquire that fails leaves it signalled
  vkResetCommandBuffer(cmd_, 0);
  VkCommandBufferBeginInfo bi{};
  bi.sType = VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO;
  bi.flags = VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT;
  vkBeginCommandBuffer(cmd_, &bi);
  f.cmd = cmd_;
  f.extent = extent_;
  return std::optional<Frame>{f};
}

void Window::begin_render_pass(const Frame& f, const glm::vec3& background) {
  VkClearValue clears[2]{};
  clears[0].color = {{background.r, background.g, background.b, 1.0f}};
  clears[1].depthStencil = {1.0f, 0};
  VkRenderPassBeginInfo rb{};
  rb.sType = VK_STRUCTURE_TYPE_RENDER_PASS_BEGIN_INFO;
  rb.renderPass = render_pass_;
  rb.framebuffer = framebuffers_[f.image];
  rb.renderArea = {{0, 0}, f.extent};
  rb.clearValueCount = 2;
  rb.pClearValues = clears;
  vkCmdBeginRenderPass(f.cmd, &rb, VK_SUBPASS_CONTENTS_INLINE);
}

Result<void> Window::end_render_pass_and_submit(const Frame& f) {
  vkCmdEndRenderPass(f.cmd);
  if (VkResult e = vkEndCommandBuffer(f.cmd); e != VK_SUCCESS)
    return vk_fail(e, "vkEndCommandBuffer");
  // The acquire semaphore is waited where the colour attachment is first touched (its clear);
  // the render pass's first dependency chains the layout transition and depth clear after it.
  const VkPipelineStageFlags wait_stage = VK_PIPELINE_STAGE_COLOR_ATTACHMENT_OUTPUT_BIT;
  VkSubmitInfo si{};
  si.sType = VK_STRUCTURE_TYPE_SUBMIT_INFO;
  si.waitSemaphoreCount = 1;
  si.pWaitSemaphores = &acquired_;
  si.pWaitDstStageMask = &wait_stage;
  si.commandBufferCount = 1;
  si.pCommandBuffers = &f.cmd;
  si.signalSemaphoreCount = 1;
  si.pSignalSemaphores = &render_done_[f.image];
  if (VkResult e = vkQueueSubmit(queue_, 1, &si, in_flight_); e != VK_SUCCESS)
    return vk_fail(e, "vkQueueSubmit");
  return {};
}

Result<void> Window::present(const Frame& f) {
  // Presentation waits for the image's render-done semaphore, signalled by end_render_pass_and_submit().
  VkPresentInfoKHR pi{};
  pi.sType = VK_STRUCTURE_TYPE_PRESENT_INFO_KHR;
  pi.waitSemaphoreCount = 1;
  pi.pWaitSemaphores = &render_done_[f.image];
  pi.swapchainCount = 1;
  pi.pSwapchains = &swapchain_;
  pi.pImageIndices = &f.image;
  const VkResult r = vkQueuePresentKHR(queue_, &pi);
  if (r == VK_ERROR_OUT_OF_DATE_KHR || r == VK_SUBOPTIMAL_KHR)
    resized_ = true;
  else if (r != VK_SUCCESS)
    return vk_fail(r, "vkQueuePresentKHR");
  return {};
}

} // namespace vkcloth::host
