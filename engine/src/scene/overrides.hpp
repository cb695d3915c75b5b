// SPDX-License-Identifier: MIT
// "key.path=value" overrides applied to a scene document before it is validated.
#pragma once

#include <string_view>

#include <nlohmann/json.hpp>

#include "vkcloth/result.hpp"

namespace vkcloth::scene_detail {

/// Most parts a key path may have ("a.b.c" has 3); the scene format needs 4.
inline constexpr std::size_t max_override_depth = 16;

/// Sets the value at `key.path` in `doc` (an object), creating missing objects/arrays on the way.
/// The value is parsed as JSON, or kept as a string when it is not valid JSON ("rk4", "cloth").
/// Array elements are addressed as `colliders.0.radius` or `colliders[0].radius`; index == size
/// appends. Walking through a scalar, or an index past the end, is an error naming the path.
Result<void> apply_override(nlohmann::json& doc, std::string_view spec);

} // namespace vkcloth::scene_detail
