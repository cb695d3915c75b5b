#include "vk_internal.hpp"

#include <algorithm>
#include <cstdlib>
#include <mutex>
#include <string>

#include <fmt/format.h>

namespace vkcloth::gpu {
namespace {

/// Test hook: VKCLOTH_TEST_FAIL_ALLOCATION=N makes the Nth vkAllocateMemory of this process, counted
/// from the moment the variable took its current value, fail with VK_ERROR_OUT_OF_DEVICE_MEMORY
/// (without calling the driver). Unset or 0: no effect. Lets tests walk every allocation of a
/// solver's creation and check that the failure is reported and everything before it is released.
bool injected_allocation_failure() {
  static std::mutex m;
  static std::string seen;
  static unsigned long count = 0;
  const char* v = std::getenv("VKCLOTH_TEST_FAIL_ALLOCATION");
  const std::string value = v ? v : "";
  const std::lock_guard lock(m);
  if (value != seen) seen = value, count = 0;
  const unsigned long n = std::strtoul(value.c_str(), nullptr, 10);
  return n != 0 && ++count == n;
}

} // namespace

Result<Buffer> create_buffer(Context::Impl& ctx, VkDeviceSize size, VkBufferUsageFlags usage, MemoryUse use, bool allow_map,
                             const char* what, const std::vector<std::uint32_t>& sharing_families) {
  const auto& vk = ctx.vk;
  Buffer b;
  b.size = size;
  VkBufferCreateInfo bi{};
  bi.sType = VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO;
  bi.size = size;
  bi.usage = usage;
  bi.sharingMode = VK_SHARING_MODE_EXCLUSIVE;
  std::vector<std::uint32_t> families;
  for (std::uint32_t f : sharing_families)
    if (std::find(families.begin(), families.end(), f) == families.end()) families.push_back(f);
  if (families.size() >= 2) {
    bi.sharingMode = VK_SHARING_MODE_CONCURRENT;
    bi.queueFamilyIndexCount = static_cast<std::uint32_t>(families.size());
    bi.pQueueFamilyIndices = families.data();
  }
  VKCLOTH_VK_TRY(vk.vkCreateBuffer(ctx.device, &bi, vk.allocator, &b.buffer), fmt::format("vkCreateBuffer ({}, {} bytes)", what, size));
  VkMemoryRequirements req;
  vk.vkGetBufferMemoryRequirements(ctx.device, b.buffer, &req);

  constexpr VkMemoryPropertyFlags mappable = VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT | VK_MEMORY_PROPERTY_HOST_COHERENT_BIT;
  int type = -1;
  bool map = false;
  switch (use) {
  case MemoryUse::device:
    if (allow_map) type = ctx.find_memory_type(req.memoryTypeBits, VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT | mappable, 0);
    map = type >= 0;
    if (type < 0) type = ctx.find_memory_type(req.memoryTypeBits, VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT, 0);
    if (type < 0) type = ctx.find_memory_type(req.memoryTypeBits, 0, 0);
    break;
  case MemoryUse::host_upload:
    type = ctx.find_memory_type(req.memoryTypeBits, mappable, 0);
    map = true;
    break;
  case MemoryUse::host_readback:
    type = ctx.find_memory_type(req.memoryTypeBits, mappable, VK_MEMORY_PROPERTY_HOST_CACHED_BIT);
    map = true;
    break;
  }
  if (type < 0) {
    destroy_buffer(ctx, b);
    return make_error(ErrorCode::unsupported, fmt::format("no suitable memory type for the {} buffer", what));
  }
  VkMemoryAllocateInfo ai{};
  ai.sType = VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO;
  ai.allocationSize = req.size;
  ai.memoryTypeIndex = static_cast<std::uint32_t>(type);
  const VkResult alloc = injected_allocation_failure() ? VK_ERROR_OUT_OF_DEVICE_MEMORY
                                                       : vk.vkAllocateMemory(ctx.device, &ai, vk.allocator, &b.memory);
  if (alloc == VK_SUCCESS) ctx.live_allocations.fetch_add(1, std::memory_order_relaxed);
  if (const VkResult r = alloc; r != VK_SUCCESS) {
    destroy_buffer(ctx, b);
    return vk_error(r, fmt::format("vkAllocateMemory ({}, {} bytes)", what, req.size));
  }
  if (const VkResult r = vk.vkBindBufferMemory(ctx.device, b.buffer, b.memory, 0); r != VK_SUCCESS) {
    destroy_buffer(ctx, b);
    return vk_error(r, fmt::format("vkBindBufferMemory ({})", what));
  }
  if (map) {
    if (const VkResult r = vk.vkMapMemory(ctx.device, b.memory, 0, VK_WHOLE_SIZE, 0, &b.mapped); r != VK_SUCCESS) {
      destroy_buffer(ctx, b);
      return vk_error(r, fmt::format("vkMapMemory ({})", what));
    }
  }
  return b;
}

void destroy_buffer(Context::Impl& ctx, Buffer& b) {
  if (b.buffer) ctx.vk.vkDestroyBuffer(ctx.device, b.buffer, ctx.vk.allocator);
  if (b.memory) {
    ctx.vk.vkFreeMemory(ctx.device, b.memory, ctx.vk.allocator); // unmaps implicitly
    ctx.live_allocations.fetch_sub(1, std::memory_order_relaxed);
  }
  b = Buffer{};
}

} // namespace vkcloth::gpu
