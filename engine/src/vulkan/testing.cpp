#include "vk_internal.hpp"

#include "vkcloth/gpu/testing.hpp"

namespace vkcloth::gpu::testing {

void set_allocation_failure_hook(Context& context, std::function<bool()> hook) {
  context_impl(context)->fail_allocation = std::move(hook);
}

} // namespace vkcloth::gpu::testing
