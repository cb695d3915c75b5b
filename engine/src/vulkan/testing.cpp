// SPDX-License-Identifier: MIT
#include "internal/vk_internal.hpp"

#include "internal/pipelines.hpp"
#include "vkcloth/gpu/testing.hpp"

namespace vkcloth::gpu::testing {

void set_allocation_failure_hook(Context& context, std::function<bool()> hook) {
  context_impl(context)->fail_allocation = std::move(hook);
}

std::size_t pipeline_count(const Context& context) {
  return context_impl(context)->pipelines->size();
}

} // namespace vkcloth::gpu::testing
