// SPDX-License-Identifier: MIT
// What the core's parameter checks share: the error they return and the finiteness of a vector.
#pragma once

#include <cmath>
#include <string>

#include <glm/vec3.hpp>

#include "vkcloth/result.hpp"

namespace vkcloth::detail {

inline Error bad_argument(std::string message) {
  return make_error(ErrorCode::invalid_argument, std::move(message));
}
inline bool finite(glm::dvec3 v) {
  return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z);
}

} // namespace vkcloth::detail
