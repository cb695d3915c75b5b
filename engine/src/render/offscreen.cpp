// SPDX-License-Identifier: MIT
#include "render_internal.hpp"

#include <cstring>
#include <functional>

#include <fmt/format.h>

#include "internal/barriers.hpp"
#include "vkcloth/render/offscreen.hpp"

namespace vkcloth::render {

struct OffscreenTarget::Impl {
  std::shared_ptr<gpu::Context::Impl> ctx; // first: outlives the objects below
  std::uint32_t width = 0, height = 0;
  VkFormat depth_format = VK_FORMAT_UNDEFINED;
  gpu::ImageResource color, depth;
  gpu::RenderPass render_pass;
  gpu::Framebuffer framebuffer;
  gpu::Buffer readback;
  gpu::CommandContext commands;

  Result<void> create_render_pass(VkFormat color_format);
  /// The render pass around `draw` (the renderer's record_draw), then the readback.
  void record_draw_and_readback(VkCommandBuffer c, const ClothRenderer& renderer,
                                const std::function<void(VkExtent2D)>& draw) const;
  Image read_image() const;
};

Result<OffscreenTarget> OffscreenTarget::create(gpu::Context& context, std::uint32_t width,
                                                std::uint32_t height) {
  if (width == 0 || height == 0 || width > 4096 || height > 4096)
    return make_error(ErrorCode::invalid_argument,
                      fmt::format("image size {}x{} is out of range (1..4096 a side)", width, height));
  auto impl = std::make_unique<Impl>();
  Impl& s = *impl;
  s.ctx = gpu::context_impl(context);
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
  auto c = gpu::create_image(*s.ctx, color_format,
                             VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT | VK_IMAGE_USAGE_TRANSFER_SRC_BIT,
                             VK_IMAGE_ASPECT_COLOR_BIT, width, height, "offscreen colour");
  if (!c)
    return c.error();
  s.color = std::move(*c);
  auto dd = gpu::create_image(*s.ctx, s.depth_format, VK_IMAGE_USAGE_DEPTH_STENCIL_ATTACHMENT_BIT,
                              VK_IMAGE_ASPECT_DEPTH_BIT, width, height, "offscreen depth");
  if (!dd)
    return dd.error();
  s.depth = std::move(*dd);

  VKCLOTH_TRY(s.create_render_pass(color_format));
  const VkImageView views[2] = {s.color.view, s.depth.view};
  VkFramebufferCreateInfo fb{};
  fb.sType = VK_STRUCTURE_TYPE_FRAMEBUFFER_CREATE_INFO;
  fb.renderPass = s.render_pass;
  fb.attachmentCount = 2;
  fb.pAttachments = views;
  fb.width = width;
  fb.height = height;
  fb.layers = 1;
  VKCLOTH_VK_TRY(v.vkCreateFramebuffer(d, &fb, v.allocator, s.framebuffer.init(*s.ctx)),
                 "vkCreateFramebuffer (offscreen)");
  auto rb = gpu::create_buffer(*s.ctx, VkDeviceSize(width) * height * 4, VK_BUFFER_USAGE_TRANSFER_DST_BIT,
                               gpu::MemoryUse::host_readback, true, "frame readback");
  if (!rb)
    return rb.error();
  s.readback = std::move(*rb);
  auto commands = gpu::CommandContext::create(*s.ctx, "offscreen");
  if (!commands)
    return commands.error();
  s.commands = std::move(*commands);
  return OffscreenTarget(std::move(impl));
}

// Colour (cleared, then TRANSFER_SRC for the readback) and depth attachments, one subpass.
Result<void> OffscreenTarget::Impl::create_render_pass(VkFormat color_format) {
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
  att[1].format = depth_format;
  att[1].storeOp = VK_ATTACHMENT_STORE_OP_DONT_CARE;
  att[1].finalLayout = VK_IMAGE_LAYOUT_DEPTH_STENCIL_ATTACHMENT_OPTIMAL;
  const VkAttachmentReference color_ref{0, VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL};
  const VkAttachmentReference depth_ref{1, VK_IMAGE_LAYOUT_DEPTH_STENCIL_ATTACHMENT_OPTIMAL};
  VkSubpassDescription sub{};
  sub.pipelineBindPoint = VK_PIPELINE_BIND_POINT_GRAPHICS;
  sub.colorAttachmentCount = 1;
  sub.pColorAttachments = &color_ref;
  sub.pDepthStencilAttachment = &depth_ref;
  const auto dep = gpu::barriers::offscreen_subpass_dependencies(); // and the layout transitions
  VkRenderPassCreateInfo rp{};
  rp.sType = VK_STRUCTURE_TYPE_RENDER_PASS_CREATE_INFO;
  rp.attachmentCount = 2;
  rp.pAttachments = att;
  rp.subpassCount = 1;
  rp.pSubpasses = &sub;
  rp.dependencyCount = static_cast<std::uint32_t>(dep.size());
  rp.pDependencies = dep.data();
  VKCLOTH_VK_TRY(ctx->vk.vkCreateRenderPass(ctx->device, &rp, ctx->vk.allocator, render_pass.init(*ctx)),
                 "vkCreateRenderPass (offscreen)");
  return {};
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

// The render pass (cleared to the renderer's background) with the draws, then the copy of the
// colour image to the readback buffer and the barrier to the host's read.
void OffscreenTarget::Impl::record_draw_and_readback(VkCommandBuffer c, const ClothRenderer& renderer,
                                                     const std::function<void(VkExtent2D)>& draw) const {
  const auto& v = ctx->vk;
  const glm::vec3 bg = renderer.palette().background;
  VkClearValue clears[2]{};
  clears[0].color = {{bg.r, bg.g, bg.b, 1.0f}};
  clears[1].depthStencil = {1.0f, 0};
  VkRenderPassBeginInfo rb{};
  rb.sType = VK_STRUCTURE_TYPE_RENDER_PASS_BEGIN_INFO;
  rb.renderPass = render_pass;
  rb.framebuffer = framebuffer;
  rb.renderArea = {{0, 0}, {width, height}};
  rb.clearValueCount = 2;
  rb.pClearValues = clears;
  v.vkCmdBeginRenderPass(c, &rb, VK_SUBPASS_CONTENTS_INLINE);
  draw({width, height});
  v.vkCmdEndRenderPass(c); // subpass dependency: colour writes -> transfer read, TRANSFER_SRC layout
  VkBufferImageCopy region{};
  region.imageSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1};
  region.imageExtent = {width, height, 1};
  v.vkCmdCopyImageToBuffer(c, color.image, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, readback.buffer, 1, &region);
  // The copy's writes -> visible to the host's read of the mapped readback buffer.
  gpu::barriers::transfer_to_host(v, c);
}

Image OffscreenTarget::Impl::read_image() const {
  Image img;
  img.width = width;
  img.height = height;
  img.rgba.resize(std::size_t(width) * height * 4);
  std::memcpy(img.rgba.data(), readback.mapped, img.rgba.size());
  return img;
}

Result<Image> OffscreenTarget::render(gpu::GpuSolver& solver, const ClothRenderer& renderer,
                                      const Camera& camera, std::uint32_t steps,
                                      const std::function<void(VkCommandBuffer)>& before_steps) {
  Impl& s = *impl_;
  VKCLOTH_TRY(s.commands.submit_and_wait([&](VkCommandBuffer c) {
    if (before_steps)
      before_steps(c);
    solver.record_steps(c, steps);
    // THE compute -> graphics barrier: the steps' shader writes of positions[current] and normals
    // become visible to the vertex fetch of the draws below (VERTEX_INPUT / VERTEX_ATTRIBUTE_READ).
    solver.record_barrier_to(c, VK_PIPELINE_STAGE_VERTEX_INPUT_BIT, VK_ACCESS_VERTEX_ATTRIBUTE_READ_BIT);
    // The solver's colliders where these steps leave them.
    s.record_draw_and_readback(c, renderer,
                               [&](VkExtent2D e) { renderer.record_draw(c, solver, camera, e); });
  }));
  if (steps)
    VKCLOTH_TRY(solver.check_divergence());
  return s.read_image();
}

Result<Image> OffscreenTarget::render(const gpu::InstanceBuffers& buffers, const ClothRenderer& renderer,
                                      const Camera& camera) {
  Impl& s = *impl_;
  // No barrier before the draws: the buffers are the host's (HostClothBuffers), written before
  // this submission, which makes host-coherent writes visible to all of its commands.
  VKCLOTH_TRY(s.commands.submit_and_wait([&](VkCommandBuffer c) {
    s.record_draw_and_readback(c, renderer,
                               [&](VkExtent2D e) { renderer.record_draw(c, buffers, camera, e); });
  }));
  return s.read_image();
}

} // namespace vkcloth::render
