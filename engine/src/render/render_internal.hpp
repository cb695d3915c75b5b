// SPDX-License-Identifier: MIT
// Internal to engine/src/render: builds on the Vulkan internals of engine/src/vulkan (volk device
// table, owned objects and their creation in resources.hpp, barriers, errors).
#pragma once

#include "internal/resources.hpp"

namespace vkcloth::render::detail {

/// True when the Context's queue family can record graphics work.
bool queue_has_graphics(gpu::Context::Impl& ctx);

} // namespace vkcloth::render::detail
