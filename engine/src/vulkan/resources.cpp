// SPDX-License-Identifier: MIT
#include "internal/resources.hpp"

#include "internal/barriers.hpp"

#include <algorithm>
#include <string>

#include <fmt/format.h>

namespace vkcloth::gpu {

VkResult allocate_memory(Context::Impl& ctx, const VkMemoryAllocateInfo& info, VkDeviceMemory* memory) {
  // Test hook (testing::set_allocation_failure_hook): one branch when unset.
  if (ctx.fail_allocation && ctx.fail_allocation())
    return VK_ERROR_OUT_OF_DEVICE_MEMORY;
  const VkResult r = ctx.vk.vkAllocateMemory(ctx.device, &info, ctx.vk.allocator, memory);
  if (r == VK_SUCCESS)
    ctx.live_allocations.fetch_add(1, std::memory_order_relaxed);
  return r;
}

void free_memory(Context::Impl& ctx, VkDeviceMemory memory) {
  if (!memory)
    return;
  ctx.vk.vkFreeMemory(ctx.device, memory, ctx.vk.allocator); // unmaps implicitly
  ctx.live_allocations.fetch_sub(1, std::memory_order_relaxed);
}

namespace {

/// The memory type for `use`; `map` says whether to map it persistently. -1: none.
int pick_memory_type(const Context::Impl& ctx, std::uint32_t type_bits, MemoryUse use, bool allow_map,
                     bool& map) {
  constexpr VkMemoryPropertyFlags mappable =
      VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT | VK_MEMORY_PROPERTY_HOST_COHERENT_BIT;
  int type = -1;
  map = false;
  switch (use) {
  case MemoryUse::device:
    if (allow_map)
      type = ctx.find_memory_type(type_bits, VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT | mappable, 0);
    map = type >= 0;
    if (type < 0)
      type = ctx.find_memory_type(type_bits, VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT, 0);
    if (type < 0)
      type = ctx.find_memory_type(type_bits, 0, 0);
    break;
  case MemoryUse::host_upload:
    type = ctx.find_memory_type(type_bits, mappable, 0);
    map = true;
    break;
  case MemoryUse::host_readback:
    type = ctx.find_memory_type(type_bits, mappable, VK_MEMORY_PROPERTY_HOST_CACHED_BIT);
    map = true;
    break;
  }
  return type;
}

} // namespace

void Buffer::reset() {
  if (ctx_) {
    if (buffer)
      ctx_->vk.vkDestroyBuffer(ctx_->device, buffer, ctx_->vk.allocator);
    free_memory(*ctx_, memory);
  }
  buffer = VK_NULL_HANDLE;
  memory = VK_NULL_HANDLE;
  size = 0;
  mapped = nullptr;
}

Result<Buffer> create_buffer(Context::Impl& ctx, VkDeviceSize size, VkBufferUsageFlags usage, MemoryUse use,
                             bool allow_map, const char* what,
                             const std::vector<std::uint32_t>& sharing_families) {
  const auto& vk = ctx.vk;
  Buffer b; // frees whatever was created if a later call fails
  b.ctx_ = &ctx;
  b.size = size;
  VkBufferCreateInfo bi{};
  bi.sType = VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO;
  bi.size = size;
  bi.usage = usage;
  bi.sharingMode = VK_SHARING_MODE_EXCLUSIVE;
  std::vector<std::uint32_t> families;
  for (std::uint32_t f : sharing_families)
    if (std::find(families.begin(), families.end(), f) == families.end())
      families.push_back(f);
  if (families.size() >= 2) {
    bi.sharingMode = VK_SHARING_MODE_CONCURRENT;
    bi.queueFamilyIndexCount = static_cast<std::uint32_t>(families.size());
    bi.pQueueFamilyIndices = families.data();
  }
  VKCLOTH_VK_TRY(vk.vkCreateBuffer(ctx.device, &bi, vk.allocator, &b.buffer),
                 fmt::format("vkCreateBuffer ({}, {} bytes)", what, size));
  VkMemoryRequirements req;
  vk.vkGetBufferMemoryRequirements(ctx.device, b.buffer, &req);
  bool map = false;
  const int type = pick_memory_type(ctx, req.memoryTypeBits, use, allow_map, map);
  if (type < 0)
    return make_error(ErrorCode::unsupported, fmt::format("no suitable memory type for the {} buffer", what));
  VkMemoryAllocateInfo ai{};
  ai.sType = VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO;
  ai.allocationSize = req.size;
  ai.memoryTypeIndex = static_cast<std::uint32_t>(type);
  VKCLOTH_VK_TRY(allocate_memory(ctx, ai, &b.memory),
                 fmt::format("vkAllocateMemory ({}, {} bytes)", what, req.size));
  VKCLOTH_VK_TRY(vk.vkBindBufferMemory(ctx.device, b.buffer, b.memory, 0),
                 fmt::format("vkBindBufferMemory ({})", what));
  if (map)
    VKCLOTH_VK_TRY(vk.vkMapMemory(ctx.device, b.memory, 0, VK_WHOLE_SIZE, 0, &b.mapped),
                   fmt::format("vkMapMemory ({})", what));
  return b;
}

void ImageResource::reset() {
  if (ctx_) {
    const auto& vk = ctx_->vk;
    if (view)
      vk.vkDestroyImageView(ctx_->device, view, vk.allocator);
    if (image)
      vk.vkDestroyImage(ctx_->device, image, vk.allocator);
    free_memory(*ctx_, memory);
  }
  image = VK_NULL_HANDLE;
  memory = VK_NULL_HANDLE;
  view = VK_NULL_HANDLE;
}

Result<ImageResource> create_image(Context::Impl& ctx, VkFormat format, VkImageUsageFlags usage,
                                   VkImageAspectFlags aspect, std::uint32_t width, std::uint32_t height,
                                   const char* what) {
  const auto& vk = ctx.vk;
  ImageResource r;
  r.ctx_ = &ctx;
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
  if (type < 0)
    return make_error(ErrorCode::unsupported, fmt::format("no memory type for the {} image", what));
  VkMemoryAllocateInfo ai{};
  ai.sType = VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO;
  ai.allocationSize = req.size;
  ai.memoryTypeIndex = static_cast<std::uint32_t>(type);
  VKCLOTH_VK_TRY(allocate_memory(ctx, ai, &r.memory), fmt::format("vkAllocateMemory ({} image)", what));
  VKCLOTH_VK_TRY(vk.vkBindImageMemory(ctx.device, r.image, r.memory, 0),
                 fmt::format("vkBindImageMemory ({} image)", what));
  VkImageViewCreateInfo vi{};
  vi.sType = VK_STRUCTURE_TYPE_IMAGE_VIEW_CREATE_INFO;
  vi.image = r.image;
  vi.viewType = VK_IMAGE_VIEW_TYPE_2D;
  vi.format = format;
  vi.subresourceRange = {aspect, 0, 1, 0, 1};
  VKCLOTH_VK_TRY(vk.vkCreateImageView(ctx.device, &vi, vk.allocator, &r.view),
                 fmt::format("vkCreateImageView ({} image)", what));
  return r;
}

Result<ShaderModule> create_shader_module(Context::Impl& ctx, std::span<const std::uint32_t> code,
                                          const char* name) {
  VkShaderModuleCreateInfo ci{};
  ci.sType = VK_STRUCTURE_TYPE_SHADER_MODULE_CREATE_INFO;
  ci.codeSize = code.size_bytes();
  ci.pCode = code.data();
  ShaderModule m;
  VKCLOTH_VK_TRY(ctx.vk.vkCreateShaderModule(ctx.device, &ci, ctx.vk.allocator, m.init(ctx)),
                 fmt::format("vkCreateShaderModule ({})", name));
  return m;
}

Result<DescriptorSetLayout> create_compute_set_layout(Context::Impl& ctx,
                                                      std::span<const std::uint32_t> bindings,
                                                      VkDescriptorType type, const char* name) {
  std::vector<VkDescriptorSetLayoutBinding> b;
  b.reserve(bindings.size());
  for (std::uint32_t i : bindings)
    b.push_back({i, type, 1, VK_SHADER_STAGE_COMPUTE_BIT, nullptr});
  VkDescriptorSetLayoutCreateInfo li{};
  li.sType = VK_STRUCTURE_TYPE_DESCRIPTOR_SET_LAYOUT_CREATE_INFO;
  li.bindingCount = static_cast<std::uint32_t>(b.size());
  li.pBindings = b.data();
  DescriptorSetLayout l;
  VKCLOTH_VK_TRY(ctx.vk.vkCreateDescriptorSetLayout(ctx.device, &li, ctx.vk.allocator, l.init(ctx)),
                 fmt::format("vkCreateDescriptorSetLayout ({})", name));
  return l;
}

Result<PipelineLayout> create_pipeline_layout(Context::Impl& ctx, std::span<const VkDescriptorSetLayout> sets,
                                              VkShaderStageFlags stages, std::uint32_t push_bytes,
                                              const char* name) {
  const VkPushConstantRange range{stages, 0, push_bytes};
  VkPipelineLayoutCreateInfo pi{};
  pi.sType = VK_STRUCTURE_TYPE_PIPELINE_LAYOUT_CREATE_INFO;
  pi.setLayoutCount = static_cast<std::uint32_t>(sets.size());
  pi.pSetLayouts = sets.data();
  pi.pushConstantRangeCount = 1;
  pi.pPushConstantRanges = &range;
  PipelineLayout l;
  VKCLOTH_VK_TRY(ctx.vk.vkCreatePipelineLayout(ctx.device, &pi, ctx.vk.allocator, l.init(ctx)),
                 fmt::format("vkCreatePipelineLayout ({})", name));
  return l;
}

Result<void> create_parity_sets(Context::Impl& ctx, VkDescriptorSetLayout layout, std::uint32_t descriptors,
                                DescriptorPool& pool, VkDescriptorSet (&sets)[2], const char* name,
                                VkDescriptorType type) {
  const auto& v = ctx.vk;
  const VkDescriptorPoolSize size{type, 2 * descriptors};
  VkDescriptorPoolCreateInfo dp{};
  dp.sType = VK_STRUCTURE_TYPE_DESCRIPTOR_POOL_CREATE_INFO;
  dp.maxSets = 2;
  dp.poolSizeCount = 1;
  dp.pPoolSizes = &size;
  VKCLOTH_VK_TRY(v.vkCreateDescriptorPool(ctx.device, &dp, v.allocator, pool.init(ctx)),
                 fmt::format("vkCreateDescriptorPool ({})", name));
  const VkDescriptorSetLayout layouts[2] = {layout, layout};
  VkDescriptorSetAllocateInfo ai{};
  ai.sType = VK_STRUCTURE_TYPE_DESCRIPTOR_SET_ALLOCATE_INFO;
  ai.descriptorPool = pool;
  ai.descriptorSetCount = 2;
  ai.pSetLayouts = layouts;
  VKCLOTH_VK_TRY(v.vkAllocateDescriptorSets(ctx.device, &ai, sets),
                 fmt::format("vkAllocateDescriptorSets ({})", name));
  return {};
}

Result<void>
write_parity_sets(Context::Impl& ctx, const VkDescriptorSet (&sets)[2],
                  std::span<const std::uint32_t> bindings,
                  const std::function<VkBuffer(std::uint32_t read, std::uint32_t binding)>& buffer_of) {
  std::vector<VkDescriptorBufferInfo> infos(2 * bindings.size());
  std::vector<VkWriteDescriptorSet> writes(2 * bindings.size());
  std::size_t k = 0;
  for (std::uint32_t read = 0; read < 2; ++read)
    for (std::uint32_t binding : bindings) {
      infos[k] = {buffer_of(read, binding), 0, VK_WHOLE_SIZE};
      if (infos[k].buffer == VK_NULL_HANDLE)
        return make_error(
            ErrorCode::unsupported,
            fmt::format("internal: descriptor binding {} has no buffer (parity {})", binding, read));
      writes[k] =
          VkWriteDescriptorSet{VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET, nullptr, sets[read], binding, 0, 1,
                               VK_DESCRIPTOR_TYPE_STORAGE_BUFFER,      nullptr, &infos[k],  nullptr};
      ++k;
    }
  ctx.vk.vkUpdateDescriptorSets(ctx.device, static_cast<std::uint32_t>(k), writes.data(), 0, nullptr);
  return {};
}

Result<BufferView> create_buffer_view(Context::Impl& ctx, VkBuffer buffer, VkFormat format,
                                      const char* name) {
  VkBufferViewCreateInfo bvi{};
  bvi.sType = VK_STRUCTURE_TYPE_BUFFER_VIEW_CREATE_INFO;
  bvi.buffer = buffer;
  bvi.format = format;
  bvi.offset = 0;
  bvi.range = VK_WHOLE_SIZE;
  BufferView v;
  VKCLOTH_VK_TRY(ctx.vk.vkCreateBufferView(ctx.device, &bvi, ctx.vk.allocator, v.init(ctx)),
                 fmt::format("vkCreateBufferView ({})", name));
  return v;
}

Result<void> create_texel_views(Context::Impl& ctx, std::span<const TexelViewSpec> specs) {
  for (const TexelViewSpec& s : specs) {
    auto r = create_buffer_view(ctx, s.buffer, s.format, s.what);
    if (!r)
      return r.error();
    *s.view = std::move(*r);
  }
  return {};
}

VkWriteDescriptorSet texel_write(VkDescriptorSet set, std::uint32_t binding, const BufferView& view) {
  VkWriteDescriptorSet w{};
  w.sType = VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET;
  w.dstSet = set;
  w.dstBinding = binding;
  w.descriptorCount = 1;
  w.descriptorType = VK_DESCRIPTOR_TYPE_UNIFORM_TEXEL_BUFFER;
  w.pTexelBufferView = view.ptr();
  return w;
}

Result<CommandContext> CommandContext::create(Context::Impl& ctx, const char* owner) {
  const auto& v = ctx.vk;
  CommandContext c;
  c.ctx_ = &ctx;
  c.owner_ = owner;
  VkCommandPoolCreateInfo cp{};
  cp.sType = VK_STRUCTURE_TYPE_COMMAND_POOL_CREATE_INFO;
  cp.flags = VK_COMMAND_POOL_CREATE_RESET_COMMAND_BUFFER_BIT;
  cp.queueFamilyIndex = ctx.queue_family;
  VKCLOTH_VK_TRY(v.vkCreateCommandPool(ctx.device, &cp, v.allocator, c.pool_.init(ctx)),
                 fmt::format("vkCreateCommandPool ({})", owner));
  VkCommandBufferAllocateInfo ca{};
  ca.sType = VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO;
  ca.commandPool = c.pool_;
  ca.level = VK_COMMAND_BUFFER_LEVEL_PRIMARY;
  ca.commandBufferCount = 1;
  VKCLOTH_VK_TRY(v.vkAllocateCommandBuffers(ctx.device, &ca, &c.cmd_),
                 fmt::format("vkAllocateCommandBuffers ({})", owner));
  VkFenceCreateInfo fi{};
  fi.sType = VK_STRUCTURE_TYPE_FENCE_CREATE_INFO;
  VKCLOTH_VK_TRY(v.vkCreateFence(ctx.device, &fi, v.allocator, c.fence_.init(ctx)),
                 fmt::format("vkCreateFence ({})", owner));
  return c;
}

CommandContext::~CommandContext() {
  if (pending_)
    ctx_->vk.vkWaitForFences(ctx_->device, 1, fence_.ptr(), VK_TRUE, UINT64_MAX);
}

Result<void> CommandContext::begin() {
  const auto& v = ctx_->vk;
  VKCLOTH_VK_TRY(v.vkResetCommandBuffer(cmd_, 0), fmt::format("vkResetCommandBuffer ({})", owner_));
  VkCommandBufferBeginInfo bi{};
  bi.sType = VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO;
  bi.flags = VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT;
  VKCLOTH_VK_TRY(v.vkBeginCommandBuffer(cmd_, &bi), fmt::format("vkBeginCommandBuffer ({})", owner_));
  return {};
}

Result<void> CommandContext::wait_for_earlier_work() {
  return submit_and_wait([&](VkCommandBuffer c) { barriers::drain(ctx_->vk, c); });
}

Result<void> CommandContext::end_submit_wait() {
  const auto& v = ctx_->vk;
  const VkDevice d = ctx_->device;
  VKCLOTH_VK_TRY(v.vkEndCommandBuffer(cmd_), fmt::format("vkEndCommandBuffer ({})", owner_));
  VkSubmitInfo si{};
  si.sType = VK_STRUCTURE_TYPE_SUBMIT_INFO;
  si.commandBufferCount = 1;
  si.pCommandBuffers = &cmd_;
  VKCLOTH_VK_TRY(v.vkResetFences(d, 1, fence_.ptr()), fmt::format("vkResetFences ({})", owner_));
  VKCLOTH_VK_TRY(v.vkQueueSubmit(ctx_->queue, 1, &si, fence_), fmt::format("vkQueueSubmit ({})", owner_));
  pending_ = true;
  VKCLOTH_VK_TRY(v.vkWaitForFences(d, 1, fence_.ptr(), VK_TRUE, UINT64_MAX),
                 fmt::format("vkWaitForFences ({})", owner_));
  pending_ = false;
  return {};
}

} // namespace vkcloth::gpu
