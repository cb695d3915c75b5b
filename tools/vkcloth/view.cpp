// `vkcloth view`: an interactive window (GLFW + a Vulkan swapchain) drawing the GPU solver live.
// Mouse: left-drag orbits, or drags the particle under the cursor (the report's hand lifting the
// cloth); wheel zooms. Keys: space pause, S / right arrow single step, R reset, W wind on/off,
// Esc quit. --frames N quits by itself after N frames; --screenshot FILE saves the last frame.
//
// The tool calls Vulkan through its own copy of volk (loaded from the Context's handles), as a host
// application would; the library's volk is private to the library.
#include <volk.h>
#define GLFW_INCLUDE_NONE
#include <GLFW/glfw3.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>
#include <optional>
#include <vector>

#include <fmt/format.h>
#include <glm/geometric.hpp>
#include <glm/mat4x4.hpp>
#include <glm/matrix.hpp>

#include "commands.hpp"
#include "render_common.hpp"
#include "vkcloth/gpu/gpu_solver.hpp"
#include "vkcloth/render/cloth_renderer.hpp"
#include "vkcloth/render/interaction.hpp"
#include "vkcloth/render/offscreen.hpp"
#include "vkcloth/scene.hpp"

namespace vkcloth::cli {
namespace {

struct ViewOptions {
  SceneArgs args;
  std::string size = "1024x768";
  std::string texture;
  std::uint64_t frames = 0; ///< 0: until closed
  std::string screenshot;
  std::uint32_t steps_per_frame = 0; ///< 0: about real time at 60 frames per second
};

Error vk_fail(VkResult r, const char* what) {
  return make_error(ErrorCode::vulkan, fmt::format("{} failed (VkResult {})", what, static_cast<int>(r)));
}

/// Mouse and keyboard state, written by the GLFW callbacks, consumed once per frame.
struct Input {
  bool paused = false, step_once = false, reset = false, toggle_wind = false, resized = false;
  bool left_down = false, left_pressed = false, left_released = false;
  double x = 0, y = 0, last_x = 0, last_y = 0, scroll = 0;
};

/// Orbit camera around a target (z up).
struct Orbit {
  glm::vec3 target{0.0f};
  float yaw = 0, pitch = 0, distance = 1, fov = 40, scene_radius = 1;
  render::Camera camera() const {
    render::Camera c;
    c.target = target;
    c.eye = target + distance * glm::vec3(std::cos(pitch) * std::cos(yaw), std::cos(pitch) * std::sin(yaw),
                                          std::sin(pitch));
    c.fov_y_degrees = fov;
    c.near_plane = std::max(distance * 0.01f, distance - 4.0f * scene_radius);
    c.far_plane = distance + 30.0f * scene_radius + 10.0f;
    return c;
  }
};

/// The cursor's ray in world space.
struct Ray {
  glm::vec3 origin, dir;
};
Ray cursor_ray(const render::Camera& cam, double x, double y, VkExtent2D e) {
  const glm::mat4 inv = glm::inverse(cam.view_projection(float(e.width) / float(e.height)));
  const float nx = float(x) / float(e.width) * 2.0f - 1.0f, ny = float(y) / float(e.height) * 2.0f - 1.0f;
  glm::vec4 a = inv * glm::vec4(nx, ny, 0.0f, 1.0f), b = inv * glm::vec4(nx, ny, 1.0f, 1.0f);
  const glm::vec3 p0 = glm::vec3(a) / a.w, p1 = glm::vec3(b) / b.w;
  return {p0, glm::normalize(p1 - p0)};
}

struct Swapchain {
  VkSwapchainKHR handle = VK_NULL_HANDLE;
  VkExtent2D extent{};
  std::vector<VkImage> images;
  std::vector<VkImageView> views;
  std::vector<VkFramebuffer> framebuffers;
  std::vector<VkSemaphore> render_done; // one per image: present waits on the one of its image
  VkImage depth = VK_NULL_HANDLE;
  VkDeviceMemory depth_memory = VK_NULL_HANDLE;
  VkImageView depth_view = VK_NULL_HANDLE;
};

class Viewer {
public:
  ~Viewer() { shutdown(); }
  int run(const ViewOptions& opt);

private:
  Result<void> create_render_pass();
  Result<void> create_swapchain();
  void destroy_swapchain();
  void shutdown();
  Result<void> reset_solver();
  void handle_input();
  Result<void> draw_frame();

  GLFWwindow* window_ = nullptr;
  VkSurfaceKHR surface_ = VK_NULL_HANDLE;
  std::optional<gpu::Context> context_;
  std::optional<Scene> scene_;
  std::optional<gpu::GpuSolver> solver_;
  std::optional<render::ClothRenderer> renderer_;
  render::Image texture_;
  VkDevice device_ = VK_NULL_HANDLE;
  VkQueue queue_ = VK_NULL_HANDLE;
  VkPhysicalDevice physical_ = VK_NULL_HANDLE;
  VkFormat color_format_ = VK_FORMAT_B8G8R8A8_UNORM, depth_format_ = VK_FORMAT_D32_SFLOAT;
  VkColorSpaceKHR color_space_ = VK_COLOR_SPACE_SRGB_NONLINEAR_KHR;
  VkRenderPass render_pass_ = VK_NULL_HANDLE;
  Swapchain sc_;
  VkCommandPool pool_ = VK_NULL_HANDLE;
  VkCommandBuffer cmd_ = VK_NULL_HANDLE;
  VkFence in_flight_ = VK_NULL_HANDLE;
  VkSemaphore acquired_ = VK_NULL_HANDLE;
  Input input_;
  Orbit orbit_;
  bool wind_on_ = false;
  Wind base_wind_;
  std::uint32_t steps_per_frame_ = 1;
  std::optional<std::uint32_t> held_;
  glm::vec3 held_pos_{0.0f}, drag_normal_{0.0f};
};

void Viewer::shutdown() {
  if (device_)
    vkDeviceWaitIdle(device_);
  renderer_.reset();
  solver_.reset();
  if (device_) {
    destroy_swapchain();
    if (sc_.handle)
      vkDestroySwapchainKHR(device_, sc_.handle, nullptr);
    sc_.handle = VK_NULL_HANDLE;
    if (render_pass_)
      vkDestroyRenderPass(device_, render_pass_, nullptr);
    if (pool_)
      vkDestroyCommandPool(device_, pool_, nullptr);
    if (in_flight_)
      vkDestroyFence(device_, in_flight_, nullptr);
    if (acquired_)
      vkDestroySemaphore(device_, acquired_, nullptr);
    render_pass_ = VK_NULL_HANDLE;
    pool_ = VK_NULL_HANDLE;
    in_flight_ = VK_NULL_HANDLE;
    acquired_ = VK_NULL_HANDLE;
  }
  if (surface_ && context_)
    vkDestroySurfaceKHR(context_->handles().instance, surface_, nullptr);
  surface_ = VK_NULL_HANDLE;
  context_.reset(); // destroys the device and instance
  device_ = VK_NULL_HANDLE;
  if (window_)
    glfwDestroyWindow(window_);
  window_ = nullptr;
  glfwTerminate();
}

Result<void> Viewer::create_render_pass() {
  VkAttachmentDescription att[2]{};
  att[0].format = color_format_;
  att[0].samples = VK_SAMPLE_COUNT_1_BIT;
  att[0].loadOp = VK_ATTACHMENT_LOAD_OP_CLEAR;
  att[0].storeOp = VK_ATTACHMENT_STORE_OP_STORE;
  att[0].stencilLoadOp = VK_ATTACHMENT_LOAD_OP_DONT_CARE;
  att[0].stencilStoreOp = VK_ATTACHMENT_STORE_OP_DONT_CARE;
  att[0].initialLayout = VK_IMAGE_LAYOUT_UNDEFINED;
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
  // transition and clear wait for it; the previous frame's depth writes finish before this clear.
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

void Viewer::destroy_swapchain() {
  for (VkFramebuffer f : sc_.framebuffers)
    vkDestroyFramebuffer(device_, f, nullptr);
  for (VkImageView v : sc_.views)
    vkDestroyImageView(device_, v, nullptr);
  for (VkSemaphore s : sc_.render_done)
    vkDestroySemaphore(device_, s, nullptr);
  if (sc_.depth_view)
    vkDestroyImageView(device_, sc_.depth_view, nullptr);
  if (sc_.depth)
    vkDestroyImage(device_, sc_.depth, nullptr);
  if (sc_.depth_memory)
    vkFreeMemory(device_, sc_.depth_memory, nullptr);
  VkSwapchainKHR old = sc_.handle;
  sc_ = Swapchain{};
  sc_.handle = old; // kept for oldSwapchain; destroyed by the caller
}

Result<void> Viewer::create_swapchain() {
  VkSurfaceCapabilitiesKHR caps{};
  if (VkResult r = vkGetPhysicalDeviceSurfaceCapabilitiesKHR(physical_, surface_, &caps); r != VK_SUCCESS)
    return vk_fail(r, "vkGetPhysicalDeviceSurfaceCapabilitiesKHR");
  int fw = 0, fh = 0;
  glfwGetFramebufferSize(window_, &fw, &fh);
  VkExtent2D extent = caps.currentExtent;
  if (extent.width == UINT32_MAX)
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
  ci.oldSwapchain = sc_.handle;
  VkSwapchainKHR handle = VK_NULL_HANDLE;
  const VkResult cr = vkCreateSwapchainKHR(device_, &ci, nullptr, &handle);
  if (sc_.handle)
    vkDestroySwapchainKHR(device_, sc_.handle, nullptr);
  sc_.handle = VK_NULL_HANDLE;
  if (cr != VK_SUCCESS)
    return vk_fail(cr, "vkCreateSwapchainKHR");
  sc_.handle = handle;
  sc_.extent = extent;
  std::uint32_t n = 0;
  vkGetSwapchainImagesKHR(device_, handle, &n, nullptr);
  sc_.images.resize(n);
  vkGetSwapchainImagesKHR(device_, handle, &n, sc_.images.data());

  // Depth image of the window's size.
  VkImageCreateInfo ii{};
  ii.sType = VK_STRUCTURE_TYPE_IMAGE_CREATE_INFO;
  ii.imageType = VK_IMAGE_TYPE_2D;
  ii.format = depth_format_;
  ii.extent = {extent.width, extent.height, 1};
  ii.mipLevels = ii.arrayLayers = 1;
  ii.samples = VK_SAMPLE_COUNT_1_BIT;
  ii.tiling = VK_IMAGE_TILING_OPTIMAL;
  ii.usage = VK_IMAGE_USAGE_DEPTH_STENCIL_ATTACHMENT_BIT;
  if (VkResult r = vkCreateImage(device_, &ii, nullptr, &sc_.depth); r != VK_SUCCESS)
    return vk_fail(r, "vkCreateImage (depth)");
  VkMemoryRequirements req;
  vkGetImageMemoryRequirements(device_, sc_.depth, &req);
  VkPhysicalDeviceMemoryProperties mp;
  vkGetPhysicalDeviceMemoryProperties(physical_, &mp);
  std::uint32_t type = UINT32_MAX;
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
  if (VkResult r = vkAllocateMemory(device_, &ai, nullptr, &sc_.depth_memory); r != VK_SUCCESS)
    return vk_fail(r, "vkAllocateMemory (depth)");
  vkBindImageMemory(device_, sc_.depth, sc_.depth_memory, 0);
  VkImageViewCreateInfo vi{};
  vi.sType = VK_STRUCTURE_TYPE_IMAGE_VIEW_CREATE_INFO;
  vi.viewType = VK_IMAGE_VIEW_TYPE_2D;
  vi.image = sc_.depth;
  vi.format = depth_format_;
  vi.subresourceRange = {VK_IMAGE_ASPECT_DEPTH_BIT, 0, 1, 0, 1};
  if (VkResult r = vkCreateImageView(device_, &vi, nullptr, &sc_.depth_view); r != VK_SUCCESS)
    return vk_fail(r, "vkCreateImageView (depth)");

  for (VkImage img : sc_.images) {
    vi.image = img;
    vi.format = color_format_;
    vi.subresourceRange = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 1, 0, 1};
    VkImageView view = VK_NULL_HANDLE;
    if (VkResult r = vkCreateImageView(device_, &vi, nullptr, &view); r != VK_SUCCESS)
      return vk_fail(r, "vkCreateImageView (swapchain)");
    sc_.views.push_back(view);
    const VkImageView atts[2] = {view, sc_.depth_view};
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
    sc_.framebuffers.push_back(f);
    VkSemaphoreCreateInfo si{};
    si.sType = VK_STRUCTURE_TYPE_SEMAPHORE_CREATE_INFO;
    VkSemaphore s = VK_NULL_HANDLE;
    if (VkResult r = vkCreateSemaphore(device_, &si, nullptr, &s); r != VK_SUCCESS)
      return vk_fail(r, "vkCreateSemaphore");
    sc_.render_done.push_back(s);
  }
  return {};
}

Result<void> Viewer::reset_solver() {
  if (device_)
    vkDeviceWaitIdle(device_);
  solver_.reset();
  SimParams p = scene_->params;
  p.wind = wind_on_ ? base_wind_ : Wind{0.0, base_wind_.direction};
  auto s = gpu::GpuSolver::create(*context_, scene_->system, p);
  if (!s)
    return s.error();
  solver_.emplace(std::move(*s));
  held_.reset();
  return {};
}

void Viewer::handle_input() {
  const render::Camera cam = orbit_.camera();
  if (input_.scroll != 0.0) {
    orbit_.distance *= std::pow(0.9f, float(input_.scroll));
    orbit_.distance =
        std::clamp(orbit_.distance, 0.05f * orbit_.scene_radius, 50.0f * orbit_.scene_radius + 1.0f);
    input_.scroll = 0.0;
  }
  if (input_.left_pressed && sc_.extent.width) {
    input_.left_pressed = false;
    // Pick the particle nearest to the cursor's ray (within 3% of the camera distance).
    const Ray ray = cursor_ray(cam, input_.x, input_.y, sc_.extent);
    vkDeviceWaitIdle(device_);
    if (auto pos = solver_->positions()) {
      float best = 0.03f * orbit_.distance;
      for (std::uint32_t i = 0; i < pos->size(); ++i) {
        const glm::vec3 d = (*pos)[i] - ray.origin;
        const float along = glm::dot(d, ray.dir);
        if (along <= 0.0f)
          continue;
        const float off = glm::length(d - along * ray.dir);
        if (off < best) {
          best = off;
          held_ = i;
          held_pos_ = (*pos)[i];
        }
      }
      drag_normal_ = glm::normalize(cam.target - cam.eye);
    }
  }
  if (input_.left_released) {
    input_.left_released = false;
    held_.reset();
  }
  const double dx = input_.x - input_.last_x, dy = input_.y - input_.last_y;
  input_.last_x = input_.x;
  input_.last_y = input_.y;
  if (input_.left_down && held_ && sc_.extent.width) {
    // Move the held particle in the plane through it facing the camera.
    const Ray ray = cursor_ray(cam, input_.x, input_.y, sc_.extent);
    const float denom = glm::dot(ray.dir, drag_normal_);
    if (std::abs(denom) > 1e-6f) {
      const float t = glm::dot(held_pos_ - ray.origin, drag_normal_) / denom;
      if (t > 0.0f)
        held_pos_ = ray.origin + t * ray.dir;
    }
  } else if (input_.left_down) {
    orbit_.yaw -= float(dx) * 0.008f;
    orbit_.pitch = std::clamp(orbit_.pitch + float(dy) * 0.008f, -1.5f, 1.5f);
  }
}

Result<void> Viewer::draw_frame() {
  vkWaitForFences(device_, 1, &in_flight_, VK_TRUE, UINT64_MAX);
  if (input_.reset) {
    input_.reset = false;
    VKCLOTH_TRY(reset_solver());
  }
  if (input_.toggle_wind) {
    input_.toggle_wind = false;
    wind_on_ = !wind_on_;
    SimParams p = solver_->params();
    p.wind = wind_on_ ? base_wind_ : Wind{0.0, base_wind_.direction};
    VKCLOTH_TRY(solver_->set_params(p)); // nothing pending: the fence above was the last submission
    fmt::print("wind {}\n", wind_on_ ? "on" : "off");
  }
  handle_input();
  if (input_.resized || !sc_.handle || sc_.images.empty()) {
    input_.resized = false;
    vkDeviceWaitIdle(device_);
    destroy_swapchain();
    VKCLOTH_TRY(create_swapchain());
    if (sc_.images.empty())
      return {}; // minimised
  }
  std::uint32_t index = 0;
  VkResult r = vkAcquireNextImageKHR(device_, sc_.handle, UINT64_MAX, acquired_, VK_NULL_HANDLE, &index);
  if (r == VK_ERROR_OUT_OF_DATE_KHR) {
    input_.resized = true;
    return {};
  }
  if (r != VK_SUCCESS && r != VK_SUBOPTIMAL_KHR)
    return vk_fail(r, "vkAcquireNextImageKHR");
  vkResetFences(device_, 1, &in_flight_);
  vkResetCommandBuffer(cmd_, 0);
  VkCommandBufferBeginInfo bi{};
  bi.sType = VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO;
  bi.flags = VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT;
  vkBeginCommandBuffer(cmd_, &bi);
  if (held_)
    render::record_hold_particle(*context_, cmd_, *solver_, *held_, held_pos_);
  if (!input_.paused) {
    solver_->record_steps(cmd_, steps_per_frame_);
  } else if (input_.step_once) {
    solver_->record_steps(cmd_, 1);
  }
  input_.step_once = false;
  // THE compute -> graphics barrier: this frame's compute writes of positions and normals become
  // visible to the vertex fetch of the draws (VERTEX_INPUT / VERTEX_ATTRIBUTE_READ).
  solver_->record_barrier_to(cmd_, VK_PIPELINE_STAGE_VERTEX_INPUT_BIT, VK_ACCESS_VERTEX_ATTRIBUTE_READ_BIT);
  const glm::vec3 bg = renderer_->palette().background;
  VkClearValue clears[2]{};
  clears[0].color = {{bg.r, bg.g, bg.b, 1.0f}};
  clears[1].depthStencil = {1.0f, 0};
  VkRenderPassBeginInfo rb{};
  rb.sType = VK_STRUCTURE_TYPE_RENDER_PASS_BEGIN_INFO;
  rb.renderPass = render_pass_;
  rb.framebuffer = sc_.framebuffers[index];
  rb.renderArea = {{0, 0}, sc_.extent};
  rb.clearValueCount = 2;
  rb.pClearValues = clears;
  vkCmdBeginRenderPass(cmd_, &rb, VK_SUBPASS_CONTENTS_INLINE);
  renderer_->record_draw(cmd_, *solver_, orbit_.camera(), sc_.extent);
  vkCmdEndRenderPass(cmd_);
  if (VkResult e = vkEndCommandBuffer(cmd_); e != VK_SUCCESS)
    return vk_fail(e, "vkEndCommandBuffer");
  const VkPipelineStageFlags wait_stage = VK_PIPELINE_STAGE_COLOR_ATTACHMENT_OUTPUT_BIT;
  VkSubmitInfo si{};
  si.sType = VK_STRUCTURE_TYPE_SUBMIT_INFO;
  si.waitSemaphoreCount = 1;
  si.pWaitSemaphores = &acquired_;
  si.pWaitDstStageMask = &wait_stage;
  si.commandBufferCount = 1;
  si.pCommandBuffers = &cmd_;
  si.signalSemaphoreCount = 1;
  si.pSignalSemaphores = &sc_.render_done[index];
  if (VkResult e = vkQueueSubmit(queue_, 1, &si, in_flight_); e != VK_SUCCESS)
    return vk_fail(e, "vkQueueSubmit");
  VkPresentInfoKHR pi{};
  pi.sType = VK_STRUCTURE_TYPE_PRESENT_INFO_KHR;
  pi.waitSemaphoreCount = 1;
  pi.pWaitSemaphores = &sc_.render_done[index];
  pi.swapchainCount = 1;
  pi.pSwapchains = &sc_.handle;
  pi.pImageIndices = &index;
  r = vkQueuePresentKHR(queue_, &pi);
  if (r == VK_ERROR_OUT_OF_DATE_KHR || r == VK_SUBOPTIMAL_KHR)
    input_.resized = true;
  else if (r != VK_SUCCESS)
    return vk_fail(r, "vkQueuePresentKHR");
  return {};
}

int Viewer::run(const ViewOptions& opt) {
  auto size = parse_size(opt.size);
  if (!size)
    return report(size.error());
  auto scene = load_scene_file(opt.args.scene, opt.args.overrides());
  if (!scene)
    return report(scene.error());
  scene_.emplace(std::move(*scene));
  if (!opt.texture.empty()) {
    auto tex = render::load_image(opt.texture);
    if (!tex)
      return report(tex.error());
    texture_ = std::move(*tex);
  }
  if (!glfwInit())
    return report(make_error(ErrorCode::no_device,
                             "cannot open a window: GLFW found no display (set DISPLAY, or run "
                             "under xvfb-run; `vkcloth render` needs no display)"));
  if (!glfwVulkanSupported())
    return report(make_error(ErrorCode::no_device, "GLFW found no Vulkan loader with window-system support"));
  glfwWindowHint(GLFW_CLIENT_API, GLFW_NO_API);
  window_ = glfwCreateWindow(int(size->first), int(size->second),
                             fmt::format("vkcloth: {}", scene_->name).c_str(), nullptr, nullptr);
  if (!window_)
    return report(make_error(ErrorCode::no_device, "glfwCreateWindow failed"));
  glfwSetWindowUserPointer(window_, &input_);
  glfwSetKeyCallback(window_, [](GLFWwindow* w, int key, int, int action, int) {
    auto* in = static_cast<Input*>(glfwGetWindowUserPointer(w));
    if (action != GLFW_PRESS && !(action == GLFW_REPEAT && (key == GLFW_KEY_S || key == GLFW_KEY_RIGHT)))
      return;
    switch (key) {
    case GLFW_KEY_ESCAPE:
      glfwSetWindowShouldClose(w, GLFW_TRUE);
      break;
    case GLFW_KEY_SPACE:
      in->paused = !in->paused;
      break;
    case GLFW_KEY_S:
    case GLFW_KEY_RIGHT:
      in->paused = true;
      in->step_once = true;
      break;
    case GLFW_KEY_R:
      in->reset = true;
      break;
    case GLFW_KEY_W:
      in->toggle_wind = true;
      break;
    default:
      break;
    }
  });
  glfwSetMouseButtonCallback(window_, [](GLFWwindow* w, int button, int action, int) {
    auto* in = static_cast<Input*>(glfwGetWindowUserPointer(w));
    if (button != GLFW_MOUSE_BUTTON_LEFT)
      return;
    in->left_down = action == GLFW_PRESS;
    (action == GLFW_PRESS ? in->left_pressed : in->left_released) = true;
  });
  glfwSetCursorPosCallback(window_, [](GLFWwindow* w, double x, double y) {
    auto* in = static_cast<Input*>(glfwGetWindowUserPointer(w));
    in->x = x;
    in->y = y;
  });
  glfwSetScrollCallback(window_, [](GLFWwindow* w, double, double y) {
    static_cast<Input*>(glfwGetWindowUserPointer(w))->scroll += y;
  });
  glfwSetFramebufferSizeCallback(window_, [](GLFWwindow* w, int, int) {
    static_cast<Input*>(glfwGetWindowUserPointer(w))->resized = true;
  });

  gpu::ContextOptions co = render_context_options();
  std::uint32_t next = 0;
  const char** exts = glfwGetRequiredInstanceExtensions(&next);
  if (!exts)
    return report(
        make_error(ErrorCode::no_device, "GLFW reports no Vulkan surface extensions for this display"));
  co.instance_extensions.assign(exts, exts + next);
  co.device_extensions = {VK_KHR_SWAPCHAIN_EXTENSION_NAME};
  co.queue_family_filter = [&](VkInstance instance, VkPhysicalDevice pd, std::uint32_t family) {
    if (!surface_) {
      if (glfwCreateWindowSurface(instance, window_, nullptr, &surface_) != VK_SUCCESS)
        return false;
    }
    auto support = reinterpret_cast<PFN_vkGetPhysicalDeviceSurfaceSupportKHR>(
        glfwGetInstanceProcAddress(instance, "vkGetPhysicalDeviceSurfaceSupportKHR"));
    VkBool32 ok = VK_FALSE;
    return support && support(pd, family, surface_, &ok) == VK_SUCCESS && ok;
  };
  auto ctx = gpu::Context::create(co);
  if (!ctx) {
    surface_ = VK_NULL_HANDLE; // went with the failed Context's instance
    return report(ctx.error());
  }
  context_.emplace(std::move(*ctx));
  const gpu::HostHandles h = context_->handles();
  volkInitializeCustom(h.get_instance_proc_addr);
  volkLoadInstanceOnly(h.instance);
  volkLoadDevice(h.device);
  device_ = h.device;
  queue_ = h.queue;
  physical_ = h.physical_device;

  std::uint32_t nf = 0;
  vkGetPhysicalDeviceSurfaceFormatsKHR(physical_, surface_, &nf, nullptr);
  std::vector<VkSurfaceFormatKHR> formats(nf);
  vkGetPhysicalDeviceSurfaceFormatsKHR(physical_, surface_, &nf, formats.data());
  if (formats.empty())
    return report(make_error(ErrorCode::unsupported, "the window surface offers no format"));
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
  if (auto r = create_render_pass(); !r)
    return report(r.error());
  const Wind& w = scene_->params.wind;
  wind_on_ = w.strength != 0.0;
  base_wind_ = wind_on_ ? w : Wind{0.05, glm::dvec3(1.0, 0.0, 0.0)};
  if (auto r = reset_solver(); !r)
    return report(r.error());
  render::RendererOptions ro;
  ro.render_pass = render_pass_;
  ro.texture = texture_;
  auto rend = render::ClothRenderer::create(*context_, *solver_, scene_->system, ro);
  if (!rend)
    return report(rend.error());
  renderer_.emplace(std::move(*rend));
  if (!renderer_->draws_cloth())
    fmt::print(stderr, "vkcloth: {} is a chain: masses drawn as spheres, springs as lines\n", scene_->name);

  VkCommandPoolCreateInfo cp{};
  cp.sType = VK_STRUCTURE_TYPE_COMMAND_POOL_CREATE_INFO;
  cp.flags = VK_COMMAND_POOL_CREATE_RESET_COMMAND_BUFFER_BIT;
  cp.queueFamilyIndex = h.queue_family;
  vkCreateCommandPool(device_, &cp, nullptr, &pool_);
  VkCommandBufferAllocateInfo ca{};
  ca.sType = VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO;
  ca.commandPool = pool_;
  ca.level = VK_COMMAND_BUFFER_LEVEL_PRIMARY;
  ca.commandBufferCount = 1;
  vkAllocateCommandBuffers(device_, &ca, &cmd_);
  VkFenceCreateInfo fi{};
  fi.sType = VK_STRUCTURE_TYPE_FENCE_CREATE_INFO;
  fi.flags = VK_FENCE_CREATE_SIGNALED_BIT;
  vkCreateFence(device_, &fi, nullptr, &in_flight_);
  VkSemaphoreCreateInfo si{};
  si.sType = VK_STRUCTURE_TYPE_SEMAPHORE_CREATE_INFO;
  vkCreateSemaphore(device_, &si, nullptr, &acquired_);
  if (auto r = create_swapchain(); !r)
    return report(r.error());

  const render::Bounds b = render::scene_bounds(scene_->system, scene_->params);
  const render::Camera start = render::Camera::frame(b, float(size->first) / float(size->second));
  const glm::vec3 off = start.eye - start.target;
  orbit_.target = start.target;
  orbit_.distance = glm::length(off);
  orbit_.yaw = std::atan2(off.y, off.x);
  orbit_.pitch = std::asin(off.z / orbit_.distance);
  orbit_.fov = start.fov_y_degrees;
  orbit_.scene_radius = std::max(b.radius(), 0.05f);
  steps_per_frame_ = opt.steps_per_frame
                         ? opt.steps_per_frame
                         : std::uint32_t(std::max(1.0, std::round((1.0 / 60.0) / scene_->params.dt)));
  fmt::print(
      "vkcloth view: {} on {} — drag: orbit / move a particle, wheel: zoom, space: pause, S: step, R: reset, "
      "W: wind, Esc: quit\n",
      scene_->name, context_->device_name());

  std::uint64_t frame = 0;
  while (!glfwWindowShouldClose(window_)) {
    glfwPollEvents();
    if (auto r = draw_frame(); !r)
      return report(r.error());
    ++frame;
    if (frame % 30 == 0 || (opt.frames && frame >= opt.frames)) {
      vkWaitForFences(device_, 1, &in_flight_, VK_TRUE, UINT64_MAX);
      if (auto r = solver_->check_divergence(); !r)
        return report(r.error());
    }
    if (opt.frames && frame >= opt.frames)
      break;
  }
  vkDeviceWaitIdle(device_);
  if (!opt.screenshot.empty()) {
    // The last frame, drawn again offscreen at the window's size with the same camera.
    const VkExtent2D e = sc_.extent.width ? sc_.extent : VkExtent2D{size->first, size->second};
    auto target = render::OffscreenTarget::create(*context_, e.width, e.height);
    if (!target)
      return report(target.error());
    render::RendererOptions so;
    so.render_pass = target->render_pass();
    so.texture = texture_;
    auto shot_renderer = render::ClothRenderer::create(*context_, *solver_, scene_->system, so);
    if (!shot_renderer)
      return report(shot_renderer.error());
    auto img = target->render(*solver_, *shot_renderer, orbit_.camera(), 0);
    if (!img)
      return report(img.error());
    if (auto wr = render::write_png(opt.screenshot, *img); !wr)
      return report(wr.error());
    fmt::print("screenshot of frame {} written to {}\n", frame, opt.screenshot);
  }
  fmt::print("vkcloth view: {} frames, step {}\n", frame, solver_->step_index());
  return exit_ok;
}

} // namespace

void add_view_command(CLI::App& app, int* exit) {
  auto opt = std::make_shared<ViewOptions>();
  CLI::App* cmd =
      app.add_subcommand("view", "Open a window and watch the GPU simulation live (orbit, pause, step, "
                                 "reset, wind, drag a particle)");
  cmd->footer(exit_codes_footer);
  add_scene_options(*cmd, opt->args);
  cmd->add_option("--size", opt->size, "Window size WxH (default 1024x768)");
  cmd->add_option("--texture", opt->texture, "Cloth texture (PNG or JPEG; default: the built-in fabric)");
  cmd->add_option("--frames", opt->frames, "Quit by itself after N frames (0: run until closed)");
  cmd->add_option("--screenshot", opt->screenshot, "Save the last frame as a PNG on exit");
  cmd->add_option("--steps-per-frame", opt->steps_per_frame,
                  "Solver steps per frame (default: about real time at 60 fps)");
  cmd->callback([opt, exit] {
    Viewer viewer;
    *exit = viewer.run(*opt);
  });
}

} // namespace vkcloth::cli
