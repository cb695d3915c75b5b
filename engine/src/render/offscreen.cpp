#include "render_internal.hpp"

#include <cstring>

#include <fmt/format.h>

#include "vkcloth/render/offscreen.hpp"

namespace vkcloth::render {

struct OffscreenTarget::Impl {
  std::shared_ptr<gpu::Context::Impl> ctx;
  std::uint32_t width = 0, height = 0;
  VkFormat depth_format = VK_FORMAT_UNDEFINED;
  detail::ImageResource color, depth;
  VkRenderPass render_pass = VK_NULL_HANDLE;
  VkFramebuffer framebuffer = VK_NULL_HANDLE;
  gpu::Buffer readback;
  VkCommandPool cmd_pool = VK_NULL_HANDLE;
  VkCommandBuffer cmd = VK_NULL_HANDLE;
  VkFence fence = VK_NULL_HANDLE;

  Impl() = default;
  Impl(const Impl&) = delete;
  Impl& operator=(const Impl&) = delete;
  ~Impl() {
    if (!ctx || !ctx->device)
      return;
    const auto& v = ctx->vk;
    const VkDevice d = ctx->device;
    if (fence) {
      v.vkWaitForFences(d, 1, &fence, VK_TRUE, UINT64_MAX);
      v.vkDestroyFence(d, fence, v.allocator);
    }
    if (cmd_pool)
      v.vkDestroyCommandPool(d, cmd_pool, v.allocator);
    if (framebuffer)
      v.vkDestroyFramebuffer(d, framebuffer, v.allocator);
    if (render_pass)
      v.vkDestroyRenderPass(d, render_pass, v.allocator);
    detail::destroy_image(*ctx, color);
    detail::destroy_image(*ctx, depth);
    gpu::destroy_buffer(*ctx, readback);
  }
};

Result<OffscreenTarget> OffscreenTarget::create(gpu::Context& context, std::uint32_t width,
                                                std::uint32_t height) {
  if (width == 0 || height == 0 || width > 4096 || height > 4096)
    return make_error(ErrorCode::invalid_argument,
                      fmt::format("image size {}x{} is out of range (1..4096 a side)", width, height));
  auto impl = std::make_unique<Impl>();
  Impl& s = *impl;
  s.ctx = context.impl();
  s.width = width;
  s.height = height;
  if (!detail::queue_has_graphics(*s.ctx))
    return make_error(ErrorCode::unsupported,
                      fmt::format("the Context's queue on '{}' has no graphics support (create it with "
                                  "ContextOptions::require_graphics)",
                                  s.ctx->name));
  const auto& v = s.ctx->vk;
  const VkDevice d = s.ctx->device;
  for (VkFormat f : {VK_FORMAT_D32_SFLOAT, VK_FORMAT_X8_D24_UNORM_PACK32, VK_FORMAT_D24_UNORM_S8_UINT,
                     VK_FORMAT_D16_UNORM}) {
    VkFormatProperties fp{};
    auto get = reinterpret_cast<PFN_vkGetPhysicalDeviceFormatProperties>(
        s.ctx->get_instance_proc_addr(s.ctx->instance, "vkGetPhysicalDeviceFormatProperties"));
    get(s.ctx->physical_device, f, &fp);
    if (fp.optimalTilingFeatures & VK_FORMAT_FEATURE_DEPTH_STENCIL_ATTACHMENT_BIT) {
      s.depth_format = f;
      break;
    }
  }
  if (s.depth_format == VK_FORMAT_UNDEFINED)
    return make_error(ErrorCode::unsupported, "no depth attachment format");
  constexpr VkFormat color_format = VK_FORMAT_R8G8B8A8_UNORM;
  auto c = detail::create_image(*s.ctx, color_format,
                                VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT | VK_IMAGE_USAGE_TRANSFER_SRC_BIT,
                                VK_IMAGE_ASPECT_COLOR_BIT, width, height, "offscreen colour");
  if (!c)
    return c.error();
  s.color = *c;
  auto dd = detail::create_image(*s.ctx, s.depth_format, VK_IMAGE_USAGE_DEPTH_STENCIL_ATTACHMENT_BIT,
                                 VK_IMAGE_ASPECT_DEPTH_BIT, width, height, "offscreen depth");
  if (!dd)
    return dd.error();
  s.depth = *dd;

  VkAttachmentDescription att[2]{};
  att[0].format = color_format;
  att[0].samples = VK_SAMPLE_COUNT_1_BIT;
  att[0].loadOp = VK_ATTACHMENT_LOAD_OP_CLEAR;
  att[0].storeOp = VK_ATTACHMENT_STORE_OP_STORE;
  att[0].stencilLoadOp = VK_ATTACHMENT_LOAD_OP_DONT_CARE;
  att[0].stencilStoreOp = VK_ATTACHMENT_STORE_OP_DONT_CARE;
  att[0].initialLayout = VK_IMAGE_LAYOUT_UNDEFINED;
  att[0].finalLayout = VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL; // for the readback copy
  att[1] = att[0];
  att[1].format = s.depth_format;
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
  // Before: the previous frame's readback copy (transfer read of the colour image) and its
  // attachment writes finish before this frame's layout transition, clears and writes.
  dep[0].srcSubpass = VK_SUBPASS_EXTERNAL;
  dep[0].dstSubpass = 0;
  dep[0].srcStageMask = VK_PIPELINE_STAGE_TRANSFER_BIT | VK_PIPELINE_STAGE_COLOR_ATTACHMENT_OUTPUT_BIT |
                        VK_PIPELINE_STAGE_EARLY_FRAGMENT_TESTS_BIT |
                        VK_PIPELINE_STAGE_LATE_FRAGMENT_TESTS_BIT;
  dep[0].srcAccessMask = VK_ACCESS_COLOR_ATTACHMENT_WRITE_BIT | VK_ACCESS_DEPTH_STENCIL_ATTACHMENT_WRITE_BIT;
  dep[0].dstStageMask = VK_PIPELINE_STAGE_COLOR_ATTACHMENT_OUTPUT_BIT |
                        VK_PIPELINE_STAGE_EARLY_FRAGMENT_TESTS_BIT |
                        VK_PIPELINE_STAGE_LATE_FRAGMENT_TESTS_BIT;
  dep[0].dstAccessMask = VK_ACCESS_COLOR_ATTACHMENT_READ_BIT | VK_ACCESS_COLOR_ATTACHMENT_WRITE_BIT |
                         VK_ACCESS_DEPTH_STENCIL_ATTACHMENT_READ_BIT |
                         VK_ACCESS_DEPTH_STENCIL_ATTACHMENT_WRITE_BIT;
  // After: the colour writes (and the transition to TRANSFER_SRC) before the readback copy.
  dep[1].srcSubpass = 0;
  dep[1].dstSubpass = VK_SUBPASS_EXTERNAL;
  dep[1].srcStageMask = VK_PIPELINE_STAGE_COLOR_ATTACHMENT_OUTPUT_BIT;
  dep[1].srcAccessMask = VK_ACCESS_COLOR_ATTACHMENT_WRITE_BIT;
  dep[1].dstStageMask = VK_PIPELINE_STAGE_TRANSFER_BIT;
  dep[1].dstAccessMask = VK_ACCESS_TRANSFER_READ_BIT;
  VkRenderPassCreateInfo rp{};
  rp.sType = VK_STRUCTURE_TYPE_RENDER_PASS_CREATE_INFO;
  rp.attachmentCount = 2;
  rp.pAttachments = att;
  rp.subpassCount = 1;
  rp.pSubpasses = &sub;
  rp.dependencyCount = 2;
  rp.pDependencies = dep;
  VKCLOTH_VK_TRY(v.vkCreateRenderPass(d, &rp, v.allocator, &s.render_pass), "vkCreateRenderPass (offscreen)");
  const VkImageView views[2] = {s.color.view, s.depth.view};
  VkFramebufferCreateInfo fb{};
  fb.sType = VK_STRUCTURE_TYPE_FRAMEBUFFER_CREATE_INFO;
  fb.renderPass = s.render_pass;
  fb.attachmentCount = 2;
  fb.pAttachments = views;
  fb.width = width;
  fb.height = height;
  fb.layers = 1;
  VKCLOTH_VK_TRY(v.vkCreateFramebuffer(d, &fb, v.allocator, &s.framebuffer), "vkCreateFramebuffer (offscreen)");
  auto rb = gpu::create_buffer(*s.ctx, VkDeviceSize(width) * height * 4, VK_BUFFER_USAGE_TRANSFER_DST_BIT,
                               gpu::MemoryUse::host_readback, true, "frame readback");
  if (!rb)
    return rb.error();
  s.readback = *rb;
  VkCommandPoolCreateInfo cp{};
  cp.sType = VK_STRUCTURE_TYPE_COMMAND_POOL_CREATE_INFO;
  cp.flags = VK_COMMAND_POOL_CREATE_RESET_COMMAND_BUFFER_BIT;
  cp.queueFamilyIndex = s.ctx->queue_family;
  VKCLOTH_VK_TRY(v.vkCreateCommandPool(d, &cp, v.allocator, &s.cmd_pool), "vkCreateCommandPool (offscreen)");
  VkCommandBufferAllocateInfo ca{};
  ca.sType = VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO;
  ca.commandPool = s.cmd_pool;
  ca.level = VK_COMMAND_BUFFER_LEVEL_PRIMARY;
  ca.commandBufferCount = 1;
  VKCLOTH_VK_TRY(v.vkAllocateCommandBuffers(d, &ca, &s.cmd), "vkAllocateCommandBuffers (offscreen)");
  VkFenceCreateInfo fi{};
  fi.sType = VK_STRUCTURE_TYPE_FENCE_CREATE_INFO;
  VKCLOTH_VK_TRY(v.vkCreateFence(d, &fi, v.allocator, &s.fence), "vkCreateFence (offscreen)");
  return OffscreenTarget(std::move(impl));
}

OffscreenTarget::OffscreenTarget(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
OffscreenTarget::OffscreenTarget(OffscreenTarget&&) noexcept = default;
OffscreenTarget& OffscreenTarget::operator=(OffscreenTarget&&) noexcept = default;
OffscreenTarget::~OffscreenTarget() = default;
VkRenderPass OffscreenTarget::render_pass() const {
  return impl_->render_pass;
}
std::uint32_t OffscreenTarget::width() const {
  return impl_->width;
}
std::uint32_t OffscreenTarget::height() const {
  return impl_->height;
}

Result<Image> OffscreenTarget::render(gpu::GpuSolver& solver, const ClothRenderer& renderer,
                                      const Camera& camera, std::uint32_t steps,
                                      const std::function<void(VkCommandBuffer)>& before_steps) {
  Impl& s = *impl_;
  const auto& v = s.ctx->vk;
  VKCLOTH_VK_TRY(v.vkResetCommandBuffer(s.cmd, 0), "vkResetCommandBuffer (offscreen)");
  VkCommandBufferBeginInfo bi{};
  bi.sType = VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO;
  bi.flags = VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT;
  VKCLOTH_VK_TRY(v.vkBeginCommandBuffer(s.cmd, &bi), "vkBeginCommandBuffer (offscreen)");
  if (before_steps)
    before_steps(s.cmd);
  solver.record_steps(s.cmd, steps);
  // THE compute -> graphics barrier: the steps' shader writes of positions[current] and normals
  // become visible to the vertex fetch of the draws below (VERTEX_INPUT / VERTEX_ATTRIBUTE_READ).
  solver.record_barrier_to(s.cmd, VK_PIPELINE_STAGE_VERTEX_INPUT_BIT, VK_ACCESS_VERTEX_ATTRIBUTE_READ_BIT);
  const glm::vec3 bg = renderer.palette().background;
  VkClearValue clears[2]{};
  clears[0].color = {{bg.r, bg.g, bg.b, 1.0f}};
  clears[1].depthStencil = {1.0f, 0};
  VkRenderPassBeginInfo rb{};
  rb.sType = VK_STRUCTURE_TYPE_RENDER_PASS_BEGIN_INFO;
  rb.renderPass = s.render_pass;
  rb.framebuffer = s.framebuffer;
  rb.renderArea = {{0, 0}, {s.width, s.height}};
  rb.clearValueCount = 2;
  rb.pClearValues = clears;
  v.vkCmdBeginRenderPass(s.cmd, &rb, VK_SUBPASS_CONTENTS_INLINE);
  renderer.record_draw(s.cmd, solver, camera, {s.width, s.height});
  v.vkCmdEndRenderPass(s.cmd); // subpass dependency: colour writes -> transfer read, TRANSFER_SRC layout
  VkBufferImageCopy region{};
  region.imageSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1};
  region.imageExtent = {s.width, s.height, 1};
  v.vkCmdCopyImageToBuffer(s.cmd, s.color.image, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, s.readback.buffer, 1,
                           &region);
  // The copy's writes -> visible to the host's read of the mapped readback buffer.
  VkMemoryBarrier mb{};
  mb.sType = VK_STRUCTURE_TYPE_MEMORY_BARRIER;
  mb.srcAccessMask = VK_ACCESS_TRANSFER_WRITE_BIT;
  mb.dstAccessMask = VK_ACCESS_HOST_READ_BIT;
  v.vkCmdPipelineBarrier(s.cmd, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_PIPELINE_STAGE_HOST_BIT, 0, 1, &mb, 0,
                         nullptr, 0, nullptr);
  VKCLOTH_VK_TRY(v.vkEndCommandBuffer(s.cmd), "vkEndCommandBuffer (offscreen)");
  VkSubmitInfo si{};
  si.sType = VK_STRUCTURE_TYPE_SUBMIT_INFO;
  si.commandBufferCount = 1;
  si.pCommandBuffers = &s.cmd;
  VKCLOTH_VK_TRY(v.vkResetFences(s.ctx->device, 1, &s.fence), "vkResetFences (offscreen)");
  VKCLOTH_VK_TRY(v.vkQueueSubmit(s.ctx->queue, 1, &si, s.fence), "vkQueueSubmit (offscreen)");
  VKCLOTH_VK_TRY(v.vkWaitForFences(s.ctx->device, 1, &s.fence, VK_TRUE, UINT64_MAX),
                 "vkWaitForFences (offscreen)");
  if (steps)
    VKCLOTH_TRY(solver.check_divergence());
  Image img;
  img.width = s.width;
  img.height = s.height;
  img.rgba.resize(std::size_t(s.width) * s.height * 4);
  std::memcpy(img.rgba.data(), s.readback.mapped, img.rgba.size());
  return img;
}

} // namespace vkcloth::render
