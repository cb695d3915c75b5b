// Test-only hooks of the Vulkan backend: not part of the stable API. Tests, benchmarks and
// diagnostics include this header; applications have no reason to.
#pragma once

#include <functional>

#include "vkcloth/gpu/context.hpp"

namespace vkcloth::gpu::testing {

/// Called before every device memory allocation vkcloth makes on `context` (solvers, worlds,
/// renderers, offscreen targets); returning true makes that allocation fail with
/// VK_ERROR_OUT_OF_DEVICE_MEMORY without calling the driver. Lets tests walk every allocation of
/// an object's creation and check that the failure is reported and everything before it is
/// released. An empty function removes the hook (then an allocation costs one branch more).
void set_allocation_failure_hook(Context& context, std::function<bool()> hook);

} // namespace vkcloth::gpu::testing
