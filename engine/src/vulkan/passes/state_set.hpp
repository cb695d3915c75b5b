// SPDX-License-Identifier: MIT
// The state set's binding table: the layout of every pass that reads the batch's state through the
// batch's descriptor sets (force, integrate, fused, strain_links, strain_finish, vertices). Set 0:
// every VKCLOTH_BINDING_* (vkcloth_shared.h); set 1: the texel views of the *_texel builds.
#pragma once

#include <array>
#include <cstdint>

#include "internal/pipelines.hpp"
#include "kernel/layout/vkcloth_shared.h"

namespace vkcloth::gpu {

inline constexpr std::array<std::uint32_t, VKCLOTH_BINDING_COUNT> kStateStorageBindings = [] {
  std::array<std::uint32_t, VKCLOTH_BINDING_COUNT> b{};
  for (std::uint32_t i = 0; i < b.size(); ++i)
    b[i] = i;
  return b;
}();

inline constexpr BindingTable kStateBindings{"solver state", kStateStorageBindings,
                                             shared::state_texel_bindings};

} // namespace vkcloth::gpu
