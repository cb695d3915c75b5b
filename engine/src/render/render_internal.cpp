#include "render_internal.hpp"

#include <vector>

#include <fmt/format.h>

namespace vkcloth::render::detail {

Result<ImageResource> create_image(gpu::Context::Impl& ctx, VkFormat format, VkImageUsageFlags usage,
                                   VkImageAspectFlags aspect, std::uint32_t width, std::uint32_t height,
                                   const char* what) {
  const auto& vk = ctx.vk;
  ImageResource r;
  VkImageCreateInfo ii{};
  ii.sType = VK_STRUCTURE_TYPE_IMAGE_CREATE_INFO;
  ii.imageType = VK_IMAGE_TYPE_2D;
  ii.format = format;
  ii.extent = {width, height, 1};
  ii.mipLevels = 1;
  ii.arrayLayers = 1;
  ii.samples = VK_SAMPLE_COUNT_1_BIT;
  ii.tiling = VK_IMAGE_TILING_OPTIMAL;
  ii.usage = usage;
  ii.sharingMode = VK_SHARING_MODE_EXCLUSIVE;
  ii.initialLayout = VK_IMAGE_LAYOUT_UNDEFINED;
  VKCLOTH_VK_TRY(vk.vkCreateImage(ctx.device, &ii, vk.allocator, &r.image),
                 fmt::format("vkCreateImage ({}, {}x{})", what, width, height));
  VkMemoryRequirements req;
  vk.vkGetImageMemoryRequirements(ctx.device, r.image, &req);
  int type = ctx.find_memory_type(req.memoryTypeBits, VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT, 0);
  if (type < 0)
    type = ctx.find_memory_type(req.memoryTypeBits, 0, 0);
  if (type < 0) {
    destroy_image(ctx, r);
    return make_error(ErrorCode::unsupported, fmt::format("no memory type for the {} image", what));
  }
  VkMemoryAllocateInfo ai{};
  ai.sType = VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO;
  ai.allocationSize = req.size;
  ai.memoryTypeIndex = static_cast<std::uint32_t>(type);
  if (const VkResult e = vk.vkAllocateMemory(ctx.device, &ai, vk.allocator, &r.memory); e != VK_SUCCESS) {
    destroy_image(ctx, r);
    return gpu::vk_error(e, fmt::format("vkAllocateMemory ({} image)", what));
  }
  if (const VkResult e = vk.vkBindImageMemory(ctx.device, r.image, r.memory, 0); e != VK_SUCCESS) {
    destroy_image(ctx, r);
    return gpu::vk_error(e, fmt::format("vkBindImageMemory ({} image)", what));
  }
  VkImageViewCreateInfo vi{};
  vi.sType = VK_STRUCTURE_TYPE_IMAGE_VIEW_CREATE_INFO;
  vi.image = r.image;
  vi.viewType = VK_IMAGE_VIEW_TYPE_2D;
  vi.format = format;
  vi.subresourceRange = {aspect, 0, 1, 0, 1};
  if (const VkResult e = vk.vkCreateImageView(ctx.device, &vi, vk.allocator, &r.view); e != VK_SUCCESS) {
    destroy_image(ctx, r);
    return gpu::vk_error(e, fmt::format("vkCreateImageView ({} image)", what));
  }
  return r;
}

void destroy_image(gpu::Context::Impl& ctx, ImageResource& img) {
  if (img.view)
    ctx.vk.vkDestroyImageView(ctx.device, img.view, ctx.vk.allocator);
  if (img.image)
    ctx.vk.vkDestroyImage(ctx.device, img.image, ctx.vk.allocator);
  if (img.memory)
    ctx.vk.vkFreeMemory(ctx.device, img.memory, ctx.vk.allocator);
  img = ImageResource{};
}

Result<VkShaderModule> create_shader(gpu::Context::Impl& ctx, const std::uint32_t* code, std::size_t words,
                                     const char* name) {
  VkShaderModuleCreateInfo ci{};
  ci.sType = VK_STRUCTURE_TYPE_SHADER_MODULE_CREATE_INFO;
  ci.codeSize = words * sizeof(std::uint32_t);
  ci.pCode = code;
  VkShaderModule m = VK_NULL_HANDLE;
  VKCLOTH_VK_TRY(ctx.vk.vkCreateShaderModule(ctx.device, &ci, ctx.vk.allocator, &m),
                 fmt::format("vkCreateShaderModule ({})", name));
  return m;
}

bool queue_has_graphics(gpu::Context::Impl& ctx) {
  std::uint32_t n = 0;
  ctx.fi.vkGetPhysicalDeviceQueueFamilyProperties(ctx.physical_device, &n, nullptr);
  std::vector<VkQueueFamilyProperties> qf(n);
  ctx.fi.vkGetPhysicalDeviceQueueFamilyProperties(ctx.physical_device, &n, qf.data());
  return ctx.queue_family < n && (qf[ctx.queue_family].queueFlags & VK_QUEUE_GRAPHICS_BIT);
}

} // namespace vkcloth::render::detail
