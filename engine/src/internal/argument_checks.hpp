// SPDX-License-Identifier: MIT
// What the core's parameter checks share: the error they return, the finiteness of a vector and
// how a message writes one.
#pragma once

#include <cmath>
#include <string>

#include <fmt/format.h>

#include <glm/vec3.hpp>

#include "vkcloth/result.hpp"

namespace vkcloth {
struct Collider;
struct ParticleSystem;
} // namespace vkcloth

namespace vkcloth::detail {

inline Error bad_argument(std::string message) {
  return make_error(ErrorCode::invalid_argument, std::move(message));
}
inline bool finite(glm::dvec3 v) {
  return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z);
}
/// The largest magnitude a collider's or the wind's vector or length may have, the mesh readers'
/// coordinate limit: beyond it the solvers' float turns it into inf and the contact into NaN.
inline constexpr double max_magnitude = 1e30;
inline bool in_range(double x) {
  return std::isfinite(x) && std::abs(x) <= max_magnitude;
}
inline bool in_range(glm::dvec3 v) {
  return in_range(v.x) && in_range(v.y) && in_range(v.z);
}
/// A vector as the messages write it: [x, y, z].
inline std::string str(glm::dvec3 v) {
  return fmt::format("[{}, {}, {}]", v.x, v.y, v.z);
}

/// Every free particle's mass is a normal float (>= 1.2e-38 kg): what the float solvers (CPU float,
/// Vulkan) need, where a smaller mass rounds to zero or loses its precision and the first step
/// divides by it (system.cpp; their create / add check it).
Result<void> check_float_masses(const ParticleSystem& system);

/// What a divergence message advises: a shorter step, lower stiffness or more damping; but where
/// the step is already under a microsecond, a longer one (vbd's m / h^2 and implicit Euler's
/// system overflow float there: a NaN at the first step).
std::string divergence_advice(double dt);

/// One collider's fields (the message names `at`.field and the value); normalises a plane's
/// normal (collider.cpp; SimParams::validate checks each of its colliders with it).
Result<void> validate_collider(Collider& c, const std::string& at);

} // namespace vkcloth::detail
