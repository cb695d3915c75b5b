// SPDX-License-Identifier: MIT
// The device limits a batch's buffers and texel views must fit, checked before any allocation; each
// error names the buffer, its size and the limit. Defined in solver_batch_create.cpp. Internal to
// engine/src/vulkan.
#pragma once

#include <cstdint>

#include "internal/vk_internal.hpp"
#include "vkcloth/gpu/testing.hpp"
#include "vkcloth/result.hpp"

namespace vkcloth::gpu {

/// The largest storage buffer: the device's maxStorageBufferRange, or the testing knob below it.
struct StorageLimit {
  std::uint64_t bytes;
  const char* source;
};
StorageLimit storage_limit(const Context::Impl& ctx, const testing::SolverKnobs& knobs);
/// A buffer of `items` x `per` bytes within the storage limit, else the error naming both.
Result<void> check_buffer(const Context::Impl& ctx, const StorageLimit& limit, const char* what,
                          std::uint64_t items, std::uint64_t per);
/// A texel buffer view of `texels` texels within maxTexelBufferElements, else the error naming
/// `what` and the limit, ending with `advice`.
Result<void> check_texels(const Context::Impl& ctx, const char* what, std::uint64_t texels,
                          const char* advice);

} // namespace vkcloth::gpu
