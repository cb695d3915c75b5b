// Internal to engine/src/render: images with their own memory, shader modules. Builds on the
// Vulkan internals of engine/src/vulkan (volk device table, buffers, errors).
#pragma once

#include "../vulkan/vk_internal.hpp"

#include <cstdint>

namespace vkcloth::render::detail {

/// An image with its own memory and one view.
struct ImageResource {
  VkImage image = VK_NULL_HANDLE;
  VkDeviceMemory memory = VK_NULL_HANDLE;
  VkImageView view = VK_NULL_HANDLE;
};

Result<ImageResource> create_image(gpu::Context::Impl& ctx, VkFormat format, VkImageUsageFlags usage,
                                   VkImageAspectFlags aspect, std::uint32_t width, std::uint32_t height,
                                   const char* what);
void destroy_image(gpu::Context::Impl& ctx, ImageResource& img);

Result<VkShaderModule> create_shader(gpu::Context::Impl& ctx, const std::uint32_t* code, std::size_t words,
                                     const char* name);

/// True when the Context's queue family can record graphics work.
bool queue_has_graphics(gpu::Context::Impl& ctx);

} // namespace vkcloth::render::detail
