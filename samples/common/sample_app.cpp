// The samples' shared loop. The offscreen path uses only the engine's API (OffscreenTarget); the
// window path calls Vulkan itself, through its own volk loaded from the Context's handles, as a
// host application embedding vkcloth would (a condensed `vkcloth view`).
#include "sample_app.hpp"

#include <volk.h>
#define GLFW_INCLUDE_NONE
#include <GLFW/glfw3.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <optional>
#include <vector>

#include <fmt/format.h>
#include <glm/geometric.hpp>

#include "vkcloth/gpu/gpu_solver.hpp"
#include "vkcloth/render/cloth_renderer.hpp"
#include "vkcloth/render/offscreen.hpp"

namespace samples {
namespace {

int fail(const vkcloth::Error& e) {
  fmt::print(stderr, "error: {}\n", e.message);
  switch (e.code) {
  case vkcloth::ErrorCode::diverged: return 3;
  case vkcloth::ErrorCode::no_device: return 4;
  default: return 1;
  }
}

std::uint32_t default_steps_per_frame(const vkcloth::Scene& s) {
  return std::uint32_t(std::max(1.0, std::round((1.0 / 60.0) / s.params.dt)));
}

int run_offscreen(const vkcloth::Scene& scene, const Options& o) {
  using namespace vkcloth;
  gpu::ContextOptions co;
  co.require_graphics = true; // the queue draws as well as computes
  auto ctx = gpu::Context::create(co);
  if (!ctx) return fail(ctx.error());
  auto solver = gpu::GpuSolver::create(*ctx, scene.system, scene.params);
  if (!solver) return fail(solver.error());
  auto target = render::OffscreenTarget::create(*ctx, o.width, o.height);
  if (!target) return fail(target.error());
  render::RendererOptions ro;
  ro.render_pass = target->render_pass();
  auto renderer = render::ClothRenderer::create(*ctx, *solver, scene.system, ro);
  if (!renderer) return fail(renderer.error());
  const render::Camera camera =
      render::Camera::frame(render::scene_bounds(scene.system, scene.params), float(o.width) / float(o.height));
  std::error_code ec;
  std::filesystem::create_directories(o.out, ec);
  const std::uint32_t frames = o.frames ? o.frames : 60;
  const std::uint32_t steps = o.steps_per_frame ? o.steps_per_frame : default_steps_per_frame(scene);
  for (std::uint32_t f = 0; f < frames; ++f) {
    // One submission: `steps` steps, the compute -> vertex barrier, the draw, the readback.
    auto img = target->render(*solver, *renderer, camera, f == 0 ? 0 : steps);
    if (!img) return fail(img.error());
    const auto path = o.out / fmt::format("{}_{:04}.png", scene.name, f);
    if (auto w = render::write_png(path, *img); !w) return fail(w.error());
  }
  fmt::print("{}: {} frames ({} steps each, t = {:.3g} s) written to {}/{}_NNNN.png\n", scene.name, frames, steps,
             solver->time(), o.out.string(), scene.name);
  if (ctx->validation_message_count()) return 1;
  return 0;
}

// ---- the window ----------------------------------------------------------------------------------

struct Input {
  bool paused = false, reset = false, resized = false, dragging = false;
  double x = 0, y = 0, last_x = 0, last_y = 0, scroll = 0;
};

struct Window {
  GLFWwindow* window = nullptr;
  VkSurfaceKHR surface = VK_NULL_HANDLE;
  std::optional<vkcloth::gpu::Context> ctx;
  VkDevice dev = VK_NULL_HANDLE;
  VkPhysicalDevice phys = VK_NULL_HANDLE;
  VkFormat color = VK_FORMAT_B8G8R8A8_UNORM, depth = VK_FORMAT_D32_SFLOAT;
  VkColorSpaceKHR space = VK_COLOR_SPACE_SRGB_NONLINEAR_KHR;
  VkRenderPass pass = VK_NULL_HANDLE;
  VkSwapchainKHR swapchain = VK_NULL_HANDLE;
  VkExtent2D extent{};
  std::vector<VkImageView> views;
  std::vector<VkFramebuffer> fbs;
  std::vector<VkSemaphore> done;
  VkImage depth_img = VK_NULL_HANDLE;
  VkDeviceMemory depth_mem = VK_NULL_HANDLE;
  VkImageView depth_view = VK_NULL_HANDLE;
  VkCommandPool pool = VK_NULL_HANDLE;
  VkCommandBuffer cmd = VK_NULL_HANDLE;
  VkFence fence = VK_NULL_HANDLE;
  VkSemaphore acquired = VK_NULL_HANDLE;

  void destroy_swapchain_views() {
    for (auto f : fbs) vkDestroyFramebuffer(dev, f, nullptr);
    for (auto v : views) vkDestroyImageView(dev, v, nullptr);
    for (auto s : done) vkDestroySemaphore(dev, s, nullptr);
    if (depth_view) vkDestroyImageView(dev, depth_view, nullptr);
    if (depth_img) vkDestroyImage(dev, depth_img, nullptr);
    if (depth_mem) vkFreeMemory(dev, depth_mem, nullptr);
    fbs.clear(), views.clear(), done.clear();
    depth_view = VK_NULL_HANDLE, depth_img = VK_NULL_HANDLE, depth_mem = VK_NULL_HANDLE;
  }

  bool create_swapchain() {
    VkSurfaceCapabilitiesKHR caps{};
    vkGetPhysicalDeviceSurfaceCapabilitiesKHR(phys, surface, &caps);
    int fw = 0, fh = 0;
    glfwGetFramebufferSize(window, &fw, &fh);
    extent = caps.currentExtent;
    if (extent.width == UINT32_MAX)
      extent = {std::clamp<std::uint32_t>(std::uint32_t(fw), caps.minImageExtent.width, caps.maxImageExtent.width),
                std::clamp<std::uint32_t>(std::uint32_t(fh), caps.minImageExtent.height, caps.maxImageExtent.height)};
    if (extent.width == 0 || extent.height == 0) return true; // minimised
    VkSwapchainCreateInfoKHR ci{VK_STRUCTURE_TYPE_SWAPCHAIN_CREATE_INFO_KHR};
    ci.surface = surface;
    ci.minImageCount = caps.maxImageCount ? std::min(std::max(caps.minImageCount, 2u), caps.maxImageCount)
                                          : std::max(caps.minImageCount, 2u);
    ci.imageFormat = color;
    ci.imageColorSpace = space;
    ci.imageExtent = extent;
    ci.imageArrayLayers = 1;
    ci.imageUsage = VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT;
    ci.preTransform = caps.currentTransform;
    ci.compositeAlpha = (caps.supportedCompositeAlpha & VK_COMPOSITE_ALPHA_OPAQUE_BIT_KHR)
                            ? VK_COMPOSITE_ALPHA_OPAQUE_BIT_KHR
                            : VK_COMPOSITE_ALPHA_INHERIT_BIT_KHR;
    ci.presentMode = VK_PRESENT_MODE_FIFO_KHR;
    ci.clipped = VK_TRUE;
    ci.oldSwapchain = swapchain;
    VkSwapchainKHR next = VK_NULL_HANDLE;
    const VkResult r = vkCreateSwapchainKHR(dev, &ci, nullptr, &next);
    if (swapchain) vkDestroySwapchainKHR(dev, swapchain, nullptr);
    swapchain = next;
    if (r != VK_SUCCESS) return false;
    std::uint32_t n = 0;
    vkGetSwapchainImagesKHR(dev, swapchain, &n, nullptr);
    std::vector<VkImage> images(n);
    vkGetSwapchainImagesKHR(dev, swapchain, &n, images.data());
    VkImageCreateInfo ii{VK_STRUCTURE_TYPE_IMAGE_CREATE_INFO};
    ii.imageType = VK_IMAGE_TYPE_2D;
    ii.format = depth;
    ii.extent = {extent.width, extent.height, 1};
    ii.mipLevels = ii.arrayLayers = 1;
    ii.samples = VK_SAMPLE_COUNT_1_BIT;
    ii.usage = VK_IMAGE_USAGE_DEPTH_STENCIL_ATTACHMENT_BIT;
    if (vkCreateImage(dev, &ii, nullptr, &depth_img) != VK_SUCCESS) return false;
    VkMemoryRequirements req;
    vkGetImageMemoryRequirements(dev, depth_img, &req);
    VkPhysicalDeviceMemoryProperties mp;
    vkGetPhysicalDeviceMemoryProperties(phys, &mp);
    VkMemoryAllocateInfo ai{VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO};
    ai.allocationSize = req.size;
    for (std::uint32_t i = mp.memoryTypeCount; i-- > 0;) // prefer the lowest device-local type
      if ((req.memoryTypeBits & (1u << i)) &&
          ((mp.memoryTypes[i].propertyFlags & VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT) || ai.memoryTypeIndex == 0))
        ai.memoryTypeIndex = i;
    if (vkAllocateMemory(dev, &ai, nullptr, &depth_mem) != VK_SUCCESS) return false;
    vkBindImageMemory(dev, depth_img, depth_mem, 0);
    VkImageViewCreateInfo vi{VK_STRUCTURE_TYPE_IMAGE_VIEW_CREATE_INFO};
    vi.viewType = VK_IMAGE_VIEW_TYPE_2D;
    vi.image = depth_img;
    vi.format = depth;
    vi.subresourceRange = {VK_IMAGE_ASPECT_DEPTH_BIT, 0, 1, 0, 1};
    if (vkCreateImageView(dev, &vi, nullptr, &depth_view) != VK_SUCCESS) return false;
    for (VkImage img : images) {
      vi.image = img;
      vi.format = color;
      vi.subresourceRange = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 1, 0, 1};
      VkImageView v = VK_NULL_HANDLE;
      if (vkCreateImageView(dev, &vi, nullptr, &v) != VK_SUCCESS) return false;
      views.push_back(v);
      const VkImageView atts[2] = {v, depth_view};
      VkFramebufferCreateInfo fb{VK_STRUCTURE_TYPE_FRAMEBUFFER_CREATE_INFO};
      fb.renderPass = pass;
      fb.attachmentCount = 2;
      fb.pAttachments = atts;
      fb.width = extent.width, fb.height = extent.height, fb.layers = 1;
      VkFramebuffer f = VK_NULL_HANDLE;
      if (vkCreateFramebuffer(dev, &fb, nullptr, &f) != VK_SUCCESS) return false;
      fbs.push_back(f);
      VkSemaphoreCreateInfo si{VK_STRUCTURE_TYPE_SEMAPHORE_CREATE_INFO};
      VkSemaphore s = VK_NULL_HANDLE;
      vkCreateSemaphore(dev, &si, nullptr, &s);
      done.push_back(s);
    }
    return true;
  }

  bool create_render_pass() {
    VkAttachmentDescription att[2]{};
    att[0].format = color;
    att[0].samples = VK_SAMPLE_COUNT_1_BIT;
    att[0].loadOp = VK_ATTACHMENT_LOAD_OP_CLEAR;
    att[0].storeOp = VK_ATTACHMENT_STORE_OP_STORE;
    att[0].stencilLoadOp = VK_ATTACHMENT_LOAD_OP_DONT_CARE;
    att[0].stencilStoreOp = VK_ATTACHMENT_STORE_OP_DONT_CARE;
    att[0].finalLayout = VK_IMAGE_LAYOUT_PRESENT_SRC_KHR;
    att[1] = att[0];
    att[1].format = depth;
    att[1].storeOp = VK_ATTACHMENT_STORE_OP_DONT_CARE;
    att[1].finalLayout = VK_IMAGE_LAYOUT_DEPTH_STENCIL_ATTACHMENT_OPTIMAL;
    const VkAttachmentReference cref{0, VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL};
    const VkAttachmentReference dref{1, VK_IMAGE_LAYOUT_DEPTH_STENCIL_ATTACHMENT_OPTIMAL};
    VkSubpassDescription sub{};
    sub.pipelineBindPoint = VK_PIPELINE_BIND_POINT_GRAPHICS;
    sub.colorAttachmentCount = 1;
    sub.pColorAttachments = &cref;
    sub.pDepthStencilAttachment = &dref;
    VkSubpassDependency dep[2]{};
    // Before: the acquire wait (at COLOR_ATTACHMENT_OUTPUT) and the previous frame's depth writes.
    dep[0].srcSubpass = VK_SUBPASS_EXTERNAL;
    dep[0].srcStageMask = VK_PIPELINE_STAGE_COLOR_ATTACHMENT_OUTPUT_BIT | VK_PIPELINE_STAGE_LATE_FRAGMENT_TESTS_BIT;
    dep[0].srcAccessMask = VK_ACCESS_DEPTH_STENCIL_ATTACHMENT_WRITE_BIT;
    dep[0].dstStageMask = VK_PIPELINE_STAGE_COLOR_ATTACHMENT_OUTPUT_BIT | VK_PIPELINE_STAGE_EARLY_FRAGMENT_TESTS_BIT |
                          VK_PIPELINE_STAGE_LATE_FRAGMENT_TESTS_BIT;
    dep[0].dstAccessMask = VK_ACCESS_COLOR_ATTACHMENT_WRITE_BIT | VK_ACCESS_DEPTH_STENCIL_ATTACHMENT_READ_BIT |
                           VK_ACCESS_DEPTH_STENCIL_ATTACHMENT_WRITE_BIT;
    // After: the colour writes complete before presentation.
    dep[1].srcSubpass = 0;
    dep[1].dstSubpass = VK_SUBPASS_EXTERNAL;
    dep[1].srcStageMask = VK_PIPELINE_STAGE_COLOR_ATTACHMENT_OUTPUT_BIT;
    dep[1].srcAccessMask = VK_ACCESS_COLOR_ATTACHMENT_WRITE_BIT;
    dep[1].dstStageMask = VK_PIPELINE_STAGE_BOTTOM_OF_PIPE_BIT;
    VkRenderPassCreateInfo rp{VK_STRUCTURE_TYPE_RENDER_PASS_CREATE_INFO};
    rp.attachmentCount = 2, rp.pAttachments = att;
    rp.subpassCount = 1, rp.pSubpasses = &sub;
    rp.dependencyCount = 2, rp.pDependencies = dep;
    return vkCreateRenderPass(dev, &rp, nullptr, &pass) == VK_SUCCESS;
  }

  ~Window() {
    if (dev) {
      vkDeviceWaitIdle(dev);
      destroy_swapchain_views();
      if (swapchain) vkDestroySwapchainKHR(dev, swapchain, nullptr);
      if (pass) vkDestroyRenderPass(dev, pass, nullptr);
      if (pool) vkDestroyCommandPool(dev, pool, nullptr);
      if (fence) vkDestroyFence(dev, fence, nullptr);
      if (acquired) vkDestroySemaphore(dev, acquired, nullptr);
    }
    if (surface && ctx) vkDestroySurfaceKHR(ctx->handles().instance, surface, nullptr);
    ctx.reset();
    if (window) glfwDestroyWindow(window);
    glfwTerminate();
  }
};

int run_window(const vkcloth::Scene& scene, const Options& o) {
  using namespace vkcloth;
  if (!glfwInit()) {
    fmt::print(stderr, "error: no display for a window (set DISPLAY, use xvfb-run, or pass --offscreen)\n");
    return 4;
  }
  Window w;
  glfwWindowHint(GLFW_CLIENT_API, GLFW_NO_API);
  w.window = glfwCreateWindow(int(o.width), int(o.height), fmt::format("vkcloth sample: {}", scene.name).c_str(),
                              nullptr, nullptr);
  if (!w.window) return fail(make_error(ErrorCode::no_device, "glfwCreateWindow failed"));
  Input in;
  glfwSetWindowUserPointer(w.window, &in);
  glfwSetKeyCallback(w.window, [](GLFWwindow* win, int key, int, int action, int) {
    auto* i = static_cast<Input*>(glfwGetWindowUserPointer(win));
    if (action != GLFW_PRESS) return;
    if (key == GLFW_KEY_ESCAPE) glfwSetWindowShouldClose(win, GLFW_TRUE);
    if (key == GLFW_KEY_SPACE) i->paused = !i->paused;
    if (key == GLFW_KEY_R) i->reset = true;
  });
  glfwSetMouseButtonCallback(w.window, [](GLFWwindow* win, int button, int action, int) {
    if (button == GLFW_MOUSE_BUTTON_LEFT) static_cast<Input*>(glfwGetWindowUserPointer(win))->dragging = action == GLFW_PRESS;
  });
  glfwSetCursorPosCallback(w.window, [](GLFWwindow* win, double x, double y) {
    auto* i = static_cast<Input*>(glfwGetWindowUserPointer(win));
    i->x = x, i->y = y;
  });
  glfwSetScrollCallback(w.window, [](GLFWwindow* win, double, double y) {
    static_cast<Input*>(glfwGetWindowUserPointer(win))->scroll += y;
  });
  glfwSetFramebufferSizeCallback(w.window, [](GLFWwindow* win, int, int) {
    static_cast<Input*>(glfwGetWindowUserPointer(win))->resized = true;
  });

  // The Context with what a window needs: GLFW's instance extensions, the swapchain, a queue that
  // presents to our surface and draws.
  gpu::ContextOptions co;
  co.require_graphics = true;
  std::uint32_t next = 0;
  const char** exts = glfwGetRequiredInstanceExtensions(&next);
  if (!exts) return fail(make_error(ErrorCode::no_device, "GLFW reports no Vulkan surface support"));
  co.instance_extensions.assign(exts, exts + next);
  co.device_extensions = {VK_KHR_SWAPCHAIN_EXTENSION_NAME};
  co.queue_family_filter = [&](VkInstance instance, VkPhysicalDevice pd, std::uint32_t family) {
    if (!w.surface && glfwCreateWindowSurface(instance, w.window, nullptr, &w.surface) != VK_SUCCESS) return false;
    auto support = reinterpret_cast<PFN_vkGetPhysicalDeviceSurfaceSupportKHR>(
        glfwGetInstanceProcAddress(instance, "vkGetPhysicalDeviceSurfaceSupportKHR"));
    VkBool32 ok = VK_FALSE;
    return support && support(pd, family, w.surface, &ok) == VK_SUCCESS && ok;
  };
  auto ctx = gpu::Context::create(co);
  if (!ctx) {
    w.surface = VK_NULL_HANDLE; // went with the failed Context's instance
    return fail(ctx.error());
  }
  w.ctx.emplace(std::move(*ctx));
  const gpu::HostHandles h = w.ctx->handles();
  volkInitializeCustom(h.get_instance_proc_addr);
  volkLoadInstanceOnly(h.instance);
  volkLoadDevice(h.device);
  w.dev = h.device, w.phys = h.physical_device;
  std::uint32_t nf = 0;
  vkGetPhysicalDeviceSurfaceFormatsKHR(w.phys, w.surface, &nf, nullptr);
  std::vector<VkSurfaceFormatKHR> formats(nf);
  vkGetPhysicalDeviceSurfaceFormatsKHR(w.phys, w.surface, &nf, formats.data());
  if (formats.empty()) return fail(make_error(ErrorCode::unsupported, "the window surface offers no format"));
  w.color = formats[0].format, w.space = formats[0].colorSpace;
  for (const auto& f : formats)
    if (f.format == VK_FORMAT_B8G8R8A8_UNORM || f.format == VK_FORMAT_R8G8B8A8_UNORM) {
      w.color = f.format, w.space = f.colorSpace;
      break;
    }
  for (VkFormat f : {VK_FORMAT_D32_SFLOAT, VK_FORMAT_X8_D24_UNORM_PACK32, VK_FORMAT_D16_UNORM}) {
    VkFormatProperties fp;
    vkGetPhysicalDeviceFormatProperties(w.phys, f, &fp);
    if (fp.optimalTilingFeatures & VK_FORMAT_FEATURE_DEPTH_STENCIL_ATTACHMENT_BIT) {
      w.depth = f;
      break;
    }
  }
  if (!w.create_render_pass()) return fail(make_error(ErrorCode::vulkan, "vkCreateRenderPass failed"));

  auto solver = gpu::GpuSolver::create(*w.ctx, scene.system, scene.params);
  if (!solver) return fail(solver.error());
  render::RendererOptions ro;
  ro.render_pass = w.pass;
  auto renderer = render::ClothRenderer::create(*w.ctx, *solver, scene.system, ro);
  if (!renderer) return fail(renderer.error());

  VkCommandPoolCreateInfo cp{VK_STRUCTURE_TYPE_COMMAND_POOL_CREATE_INFO};
  cp.flags = VK_COMMAND_POOL_CREATE_RESET_COMMAND_BUFFER_BIT;
  cp.queueFamilyIndex = h.queue_family;
  vkCreateCommandPool(w.dev, &cp, nullptr, &w.pool);
  VkCommandBufferAllocateInfo ca{VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO};
  ca.commandPool = w.pool;
  ca.level = VK_COMMAND_BUFFER_LEVEL_PRIMARY;
  ca.commandBufferCount = 1;
  vkAllocateCommandBuffers(w.dev, &ca, &w.cmd);
  VkFenceCreateInfo fi{VK_STRUCTURE_TYPE_FENCE_CREATE_INFO};
  fi.flags = VK_FENCE_CREATE_SIGNALED_BIT;
  vkCreateFence(w.dev, &fi, nullptr, &w.fence);
  VkSemaphoreCreateInfo si{VK_STRUCTURE_TYPE_SEMAPHORE_CREATE_INFO};
  vkCreateSemaphore(w.dev, &si, nullptr, &w.acquired);
  if (!w.create_swapchain()) return fail(make_error(ErrorCode::vulkan, "swapchain creation failed"));

  // Orbit camera around the scene's bounds.
  const render::Bounds b = render::scene_bounds(scene.system, scene.params);
  render::Camera cam = render::Camera::frame(b, float(o.width) / float(o.height));
  const glm::vec3 off = cam.eye - cam.target;
  float dist = glm::length(off), yaw = std::atan2(off.y, off.x), pitch = std::asin(off.z / dist);
  const std::uint32_t steps = o.steps_per_frame ? o.steps_per_frame : default_steps_per_frame(scene);
  fmt::print("{} on {}: drag orbits, wheel zooms, space pauses, R resets, Esc quits\n", scene.name,
             w.ctx->device_name());
  std::uint64_t frame = 0;
  while (!glfwWindowShouldClose(w.window) && (!o.frames || frame < o.frames)) {
    glfwPollEvents();
    vkWaitForFences(w.dev, 1, &w.fence, VK_TRUE, UINT64_MAX);
    if (frame % 30 == 0)
      if (auto r = solver->check_divergence(); !r) return fail(r.error());
    if (in.reset) { // a fresh solver from the initial state (nothing is pending: the fence above)
      in.reset = false;
      auto s = gpu::GpuSolver::create(*w.ctx, scene.system, scene.params);
      if (!s) return fail(s.error());
      *solver = std::move(*s);
    }
    if (in.dragging) {
      yaw -= float(in.x - in.last_x) * 0.01f;
      pitch = std::clamp(pitch + float(in.y - in.last_y) * 0.01f, -1.5f, 1.5f);
    }
    in.last_x = in.x, in.last_y = in.y;
    dist *= std::pow(0.9f, float(in.scroll));
    in.scroll = 0;
    cam.eye = cam.target + dist * glm::vec3(std::cos(pitch) * std::cos(yaw), std::cos(pitch) * std::sin(yaw), std::sin(pitch));
    if (in.resized || w.views.empty()) {
      in.resized = false;
      vkDeviceWaitIdle(w.dev);
      w.destroy_swapchain_views();
      if (!w.create_swapchain()) return fail(make_error(ErrorCode::vulkan, "swapchain creation failed"));
      if (w.views.empty()) continue; // minimised
    }
    std::uint32_t index = 0;
    VkResult r = vkAcquireNextImageKHR(w.dev, w.swapchain, UINT64_MAX, w.acquired, VK_NULL_HANDLE, &index);
    if (r == VK_ERROR_OUT_OF_DATE_KHR) {
      in.resized = true;
      continue;
    }
    vkResetFences(w.dev, 1, &w.fence);
    vkResetCommandBuffer(w.cmd, 0);
    VkCommandBufferBeginInfo bi{VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO};
    bi.flags = VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT;
    vkBeginCommandBuffer(w.cmd, &bi);
    if (!in.paused) solver->record_steps(w.cmd, steps);
    // The compute -> graphics barrier: the steps' positions and normals, visible to the vertex fetch.
    solver->record_barrier_to(w.cmd, VK_PIPELINE_STAGE_VERTEX_INPUT_BIT, VK_ACCESS_VERTEX_ATTRIBUTE_READ_BIT);
    const glm::vec3 bg = renderer->palette().background;
    VkClearValue clears[2]{};
    clears[0].color = {{bg.r, bg.g, bg.b, 1.0f}};
    clears[1].depthStencil = {1.0f, 0};
    VkRenderPassBeginInfo rb{VK_STRUCTURE_TYPE_RENDER_PASS_BEGIN_INFO};
    rb.renderPass = w.pass;
    rb.framebuffer = w.fbs[index];
    rb.renderArea = {{0, 0}, w.extent};
    rb.clearValueCount = 2;
    rb.pClearValues = clears;
    vkCmdBeginRenderPass(w.cmd, &rb, VK_SUBPASS_CONTENTS_INLINE);
    renderer->record_draw(w.cmd, *solver, cam, w.extent);
    vkCmdEndRenderPass(w.cmd);
    vkEndCommandBuffer(w.cmd);
    const VkPipelineStageFlags wait = VK_PIPELINE_STAGE_COLOR_ATTACHMENT_OUTPUT_BIT;
    VkSubmitInfo sub{VK_STRUCTURE_TYPE_SUBMIT_INFO};
    sub.waitSemaphoreCount = 1, sub.pWaitSemaphores = &w.acquired, sub.pWaitDstStageMask = &wait;
    sub.commandBufferCount = 1, sub.pCommandBuffers = &w.cmd;
    sub.signalSemaphoreCount = 1, sub.pSignalSemaphores = &w.done[index];
    if (vkQueueSubmit(h.queue, 1, &sub, w.fence) != VK_SUCCESS)
      return fail(make_error(ErrorCode::vulkan, "vkQueueSubmit failed"));
    VkPresentInfoKHR pi{VK_STRUCTURE_TYPE_PRESENT_INFO_KHR};
    pi.waitSemaphoreCount = 1, pi.pWaitSemaphores = &w.done[index];
    pi.swapchainCount = 1, pi.pSwapchains = &w.swapchain, pi.pImageIndices = &index;
    r = vkQueuePresentKHR(h.queue, &pi);
    if (r == VK_ERROR_OUT_OF_DATE_KHR || r == VK_SUBOPTIMAL_KHR) in.resized = true;
    ++frame;
  }
  vkDeviceWaitIdle(w.dev);
  if (auto r = solver->check_divergence(); !r) return fail(r.error());
  fmt::print("{}: {} frames, step {}\n", scene.name, frame, solver->step_index());
  return 0;
}

[[noreturn]] void usage_exit(const char* prog, const std::string& about, const std::string& presets, int code) {
  std::FILE* f = code ? stderr : stdout;
  fmt::print(f,
             "{}\n\nUsage: {} [options]\n"
             "  --offscreen          render to PNG files instead of a window (no display needed)\n"
             "  --frames N           stop after N frames (offscreen default 60; windowed: until closed)\n"
             "  --steps-per-frame K  solver steps between frames (default: about real time at 60 fps)\n"
             "  --out DIR            where the PNG frames and plots go (default ./out)\n"
             "  --size WxH           image or window size (default 800x600)\n"
             "{}"
             "  --help               this text\n"
             "Environment: VKCLOTH_VALIDATION=1 enables the Vulkan validation layer, VKCLOTH_DEVICE picks a device.\n",
             about, prog, presets.empty() ? "" : "  --preset NAME        one of:\n" + presets);
  std::exit(code);
}

} // namespace

Options parse_args(int argc, char** argv, const std::string& about, const std::string& presets_help) {
  Options o;
  auto value = [&](int& i) -> std::string {
    if (i + 1 >= argc) {
      fmt::print(stderr, "error: {} needs a value\n", argv[i]);
      usage_exit(argv[0], about, presets_help, 2);
    }
    return argv[++i];
  };
  auto number = [&](const std::string& s, const char* what) -> std::uint32_t {
    char* end = nullptr;
    const unsigned long v = std::strtoul(s.c_str(), &end, 10);
    if (s.empty() || *end || v == 0 || v > 100000) {
      fmt::print(stderr, "error: {} {}: expected a positive whole number\n", what, s);
      std::exit(2);
    }
    return std::uint32_t(v);
  };
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--help" || a == "-h") usage_exit(argv[0], about, presets_help, 0);
    else if (a == "--offscreen") o.offscreen = true;
    else if (a == "--frames") o.frames = number(value(i), "--frames");
    else if (a == "--steps-per-frame") o.steps_per_frame = number(value(i), "--steps-per-frame");
    else if (a == "--out") o.out = value(i);
    else if (a == "--size") {
      const std::string s = value(i);
      unsigned w = 0, h = 0;
      char x = 0, extra = 0;
      if (std::sscanf(s.c_str(), "%u%c%u%c", &w, &x, &h, &extra) != 3 || x != 'x' || !w || !h || w > 4096 || h > 4096) {
        fmt::print(stderr, "error: --size {}: expected WxH, e.g. 800x600\n", s);
        std::exit(2);
      }
      o.width = w, o.height = h;
    } else if (a == "--preset" && !presets_help.empty()) o.preset = value(i);
    else {
      fmt::print(stderr, "error: unknown option {}\n", a);
      usage_exit(argv[0], about, presets_help, 2);
    }
  }
  return o;
}

int run(const vkcloth::Scene& scene, const Options& options) {
  return options.offscreen ? run_offscreen(scene, options) : run_window(scene, options);
}

} // namespace samples
