// SPDX-License-Identifier: MIT
// Owning, move-only wrappers of every Vulkan object vkcloth creates on a Context's device, and the
// one place that creates buffers, images, shader modules and compute pipelines, and submits
// one-off command buffers. Adding a buffer to a solver means adding one member: its destructor
// frees it (with the host's allocation callbacks), in reverse declaration order.
// Internal to engine/src/vulkan and engine/src/render. Modelled on niagara's resources.h.
#pragma once

#include "internal/vk_internal.hpp"

#include <cstdint>
#include <functional>
#include <span>
#include <utility>
#include <vector>

namespace vkcloth::gpu {

/// One non-dispatchable handle of a Context's device, destroyed by `Destroy` (a vkDestroy* of the
/// device table) with the host's allocation callbacks. The Context::Impl must outlive it (owners
/// hold a shared_ptr to it, declared before their handles).
template <typename T, auto Destroy> class Handle {
public:
  Handle() = default;
  Handle(Handle&& o) noexcept : ctx_(o.ctx_), h_(std::exchange(o.h_, T(VK_NULL_HANDLE))) {}
  Handle& operator=(Handle&& o) noexcept {
    if (this != &o) {
      reset();
      ctx_ = o.ctx_;
      h_ = std::exchange(o.h_, T(VK_NULL_HANDLE));
    }
    return *this;
  }
  Handle(const Handle&) = delete;
  Handle& operator=(const Handle&) = delete;
  ~Handle() { reset(); }

  /// For the vkCreate* call: frees the current object, returns where to write the new handle.
  T* init(Context::Impl& ctx) {
    reset();
    ctx_ = &ctx;
    return &h_;
  }
  void reset() {
    if (h_)
      (ctx_->vk.*Destroy)(ctx_->device, h_, ctx_->vk.allocator);
    h_ = VK_NULL_HANDLE;
  }
  T get() const { return h_; }
  operator T() const { return h_; } // NOLINT: used where the raw handle is expected
  /// Address of the handle, for Vulkan arrays of one (descriptor writes of texel views).
  const T* ptr() const { return &h_; }

private:
  Context::Impl* ctx_ = nullptr;
  T h_ = VK_NULL_HANDLE;
};

using BufferView = Handle<VkBufferView, &VolkDeviceTable::vkDestroyBufferView>;
using DescriptorSetLayout = Handle<VkDescriptorSetLayout, &VolkDeviceTable::vkDestroyDescriptorSetLayout>;
using DescriptorPool = Handle<VkDescriptorPool, &VolkDeviceTable::vkDestroyDescriptorPool>; // frees its sets
using PipelineLayout = Handle<VkPipelineLayout, &VolkDeviceTable::vkDestroyPipelineLayout>;
using Pipeline = Handle<VkPipeline, &VolkDeviceTable::vkDestroyPipeline>;
using PipelineCache = Handle<VkPipelineCache, &VolkDeviceTable::vkDestroyPipelineCache>;
using ShaderModule = Handle<VkShaderModule, &VolkDeviceTable::vkDestroyShaderModule>;
using CommandPool = Handle<VkCommandPool, &VolkDeviceTable::vkDestroyCommandPool>; // frees its buffers
using Fence = Handle<VkFence, &VolkDeviceTable::vkDestroyFence>;
using QueryPool = Handle<VkQueryPool, &VolkDeviceTable::vkDestroyQueryPool>;
using Sampler = Handle<VkSampler, &VolkDeviceTable::vkDestroySampler>;
using RenderPass = Handle<VkRenderPass, &VolkDeviceTable::vkDestroyRenderPass>;
using Framebuffer = Handle<VkFramebuffer, &VolkDeviceTable::vkDestroyFramebuffer>;

enum class MemoryUse {
  device,        ///< device-local; mapped only if also host-visible+coherent and `allow_map`
  host_upload,   ///< host-visible+coherent staging for uploads
  host_readback, ///< host-visible+coherent, cached if possible, for readbacks and flags
};

/// A buffer with its own memory allocation; `mapped` is set when the memory is host-visible and
/// mapped persistently (always host-coherent). The fields are read-only outside create_buffer().
struct Buffer {
  VkBuffer buffer = VK_NULL_HANDLE;
  VkDeviceMemory memory = VK_NULL_HANDLE;
  VkDeviceSize size = 0;
  void* mapped = nullptr;

  Buffer() = default;
  Buffer(Buffer&& o) noexcept { swap(o); }
  Buffer& operator=(Buffer&& o) noexcept {
    Buffer(std::move(o)).swap(*this);
    return *this;
  }
  Buffer(const Buffer&) = delete;
  Buffer& operator=(const Buffer&) = delete;
  ~Buffer() { reset(); }
  void reset();

private:
  friend Result<Buffer> create_buffer(Context::Impl&, VkDeviceSize, VkBufferUsageFlags, MemoryUse, bool,
                                      const char*, const std::vector<std::uint32_t>&);
  void swap(Buffer& o) noexcept {
    std::swap(buffer, o.buffer);
    std::swap(memory, o.memory);
    std::swap(size, o.size);
    std::swap(mapped, o.mapped);
    std::swap(ctx_, o.ctx_);
  }
  Context::Impl* ctx_ = nullptr;
};

/// `sharing_families`: queue families that use the buffer without ownership transfers; two or more
/// distinct ones make it VK_SHARING_MODE_CONCURRENT, otherwise it is EXCLUSIVE.
Result<Buffer> create_buffer(Context::Impl& ctx, VkDeviceSize size, VkBufferUsageFlags usage, MemoryUse use,
                             bool allow_map, const char* what,
                             const std::vector<std::uint32_t>& sharing_families = {});

/// A 2D image with its own device-local memory and one view of `aspect`.
struct ImageResource {
  VkImage image = VK_NULL_HANDLE;
  VkDeviceMemory memory = VK_NULL_HANDLE;
  VkImageView view = VK_NULL_HANDLE;

  ImageResource() = default;
  ImageResource(ImageResource&& o) noexcept { swap(o); }
  ImageResource& operator=(ImageResource&& o) noexcept {
    ImageResource(std::move(o)).swap(*this);
    return *this;
  }
  ImageResource(const ImageResource&) = delete;
  ImageResource& operator=(const ImageResource&) = delete;
  ~ImageResource() { reset(); }
  void reset();

private:
  friend Result<ImageResource> create_image(Context::Impl&, VkFormat, VkImageUsageFlags, VkImageAspectFlags,
                                            std::uint32_t, std::uint32_t, const char*);
  void swap(ImageResource& o) noexcept {
    std::swap(image, o.image);
    std::swap(memory, o.memory);
    std::swap(view, o.view);
    std::swap(ctx_, o.ctx_);
  }
  Context::Impl* ctx_ = nullptr;
};

Result<ImageResource> create_image(Context::Impl& ctx, VkFormat format, VkImageUsageFlags usage,
                                   VkImageAspectFlags aspect, std::uint32_t width, std::uint32_t height,
                                   const char* what);

/// The one vkAllocateMemory of vkcloth (buffers and images): counts Context::live_allocation_count
/// and honours the test hook (testing::set_allocation_failure_hook).
VkResult allocate_memory(Context::Impl& ctx, const VkMemoryAllocateInfo& info, VkDeviceMemory* memory);
/// The matching vkFreeMemory (null: nothing).
void free_memory(Context::Impl& ctx, VkDeviceMemory memory);

/// A shader module from embedded SPIR-V (vkcloth/shaders/*_spv.hpp); `name` names it in errors.
Result<ShaderModule> create_shader_module(Context::Impl& ctx, std::span<const std::uint32_t> code,
                                          const char* name);

/// A descriptor set layout of `bindings`, each one descriptor of `type` for the compute stage.
Result<DescriptorSetLayout> create_compute_set_layout(Context::Impl& ctx,
                                                      std::span<const std::uint32_t> bindings,
                                                      VkDescriptorType type, const char* name);

/// A pipeline layout of `sets` with one push-constant range [0, push_bytes) for `stages`.
Result<PipelineLayout> create_pipeline_layout(Context::Impl& ctx, std::span<const VkDescriptorSetLayout> sets,
                                              VkShaderStageFlags stages, std::uint32_t push_bytes,
                                              const char* name);

/// A pool of two sets of `layout`, each of `descriptors` descriptors of `type`, and the two sets
/// (one per position parity: implicit Euler's, self-collision's and the projection's passes).
Result<void> create_parity_sets(Context::Impl& ctx, VkDescriptorSetLayout layout, std::uint32_t descriptors,
                                DescriptorPool& pool, VkDescriptorSet (&sets)[2], const char* name,
                                VkDescriptorType type = VK_DESCRIPTOR_TYPE_STORAGE_BUFFER);

/// Writes every binding of both parity sets as a whole storage buffer: buffer_of(read, binding)
/// (`read`: the set's position parity, 0 or 1). Creation and buffer replacement only. A binding
/// that buffer_of maps to no buffer is an error naming it (a layout's binding left unwritten would
/// read whatever the set held).
Result<void>
write_parity_sets(Context::Impl& ctx, const VkDescriptorSet (&sets)[2],
                  std::span<const std::uint32_t> bindings,
                  const std::function<VkBuffer(std::uint32_t read, std::uint32_t binding)>& buffer_of);

/// A whole-buffer texel view of `buffer` in `format`.
Result<BufferView> create_buffer_view(Context::Impl& ctx, VkBuffer buffer, VkFormat format, const char* name);

/// A texel buffer view to make (create_texel_views): the whole of `buffer` as `format`, into
/// *view, named `what` in errors.
struct TexelViewSpec {
  VkBuffer buffer;
  VkFormat format;
  BufferView* view;
  const char* what;
};
/// Makes every view of `specs` (create_buffer_view), each replacing what its BufferView held.
Result<void> create_texel_views(Context::Impl& ctx, std::span<const TexelViewSpec> specs);

/// The descriptor write of `view` as the uniform texel buffer at `binding` of `set`.
VkWriteDescriptorSet texel_write(VkDescriptorSet set, std::uint32_t binding, const BufferView& view);

/// The convenience path of solvers, worlds, the renderer and the offscreen target: one resettable
/// command buffer of the Context's queue family and a fence. submit_and_wait() resets the buffer,
/// records `record(cmd)` (one-time submit), submits it on the Context's queue and waits.
class CommandContext {
public:
  /// `owner` names the object in errors ("solver", "world", "offscreen", ...).
  static Result<CommandContext> create(Context::Impl& ctx, const char* owner);
  CommandContext() = default;
  CommandContext(CommandContext&&) noexcept = default;
  CommandContext& operator=(CommandContext&&) noexcept = default;
  /// Waits for a submission whose wait failed (device lost: returns at once).
  ~CommandContext();

  template <typename F> Result<void> submit_and_wait(F&& record) {
    VKCLOTH_TRY(begin());
    record(cmd_);
    return end_submit_wait();
  }
  /// Returns once every command submitted earlier on the Context's queue has completed (an empty
  /// submission behind barriers::drain): before replacing a buffer or descriptor set that the
  /// host's recorded work may still use.
  Result<void> wait_for_earlier_work();

private:
  Result<void> begin();
  Result<void> end_submit_wait();
  Context::Impl* ctx_ = nullptr;
  const char* owner_ = "";
  CommandPool pool_;
  VkCommandBuffer cmd_ = VK_NULL_HANDLE; // freed with pool_
  Fence fence_;
  bool pending_ = false; // submitted, not yet waited for
};

} // namespace vkcloth::gpu
