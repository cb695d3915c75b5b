// SPDX-License-Identifier: MIT
#include "vkcloth/params.hpp"

#include <cmath>
#include <fmt/format.h>

#include <glm/geometric.hpp>

namespace vkcloth {
namespace {

bool finite(glm::dvec3 v) {
  return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z);
}
std::string str(glm::dvec3 v) {
  return fmt::format("[{}, {}, {}]", v.x, v.y, v.z);
}
Error bad(std::string message) {
  return make_error(ErrorCode::invalid_argument, std::move(message));
}

} // namespace

const char* to_string(Integrator integrator) {
  switch (integrator) {
  case Integrator::explicit_euler:
    return "explicit_euler";
  case Integrator::semi_implicit_euler:
    return "semi_implicit_euler";
  case Integrator::rk4:
    return "rk4";
  case Integrator::implicit_euler:
    return "implicit_euler";
  }
  return "?";
}

std::optional<Integrator> parse_integrator(std::string_view name) {
  for (Integrator i : {Integrator::explicit_euler, Integrator::semi_implicit_euler, Integrator::rk4,
                       Integrator::implicit_euler})
    if (name == to_string(i))
      return i;
  return std::nullopt;
}

const char* to_string(StretchLimit::Method method) {
  switch (method) {
  case StretchLimit::Method::off:
    return "off";
  case StretchLimit::Method::tethers:
    return "tethers";
  case StretchLimit::Method::provot:
    return "provot";
  case StretchLimit::Method::both:
    return "both";
  }
  return "?";
}

std::optional<StretchLimit::Method> parse_stretch_method(std::string_view name) {
  using M = StretchLimit::Method;
  for (M m : {M::off, M::tethers, M::provot, M::both})
    if (name == to_string(m))
      return m;
  return std::nullopt;
}

const char* to_string(StretchLimit::TetherDistance distance) {
  return distance == StretchLimit::TetherDistance::euclidean ? "euclidean" : "geodesic";
}

std::optional<StretchLimit::TetherDistance> parse_tether_distance(std::string_view name) {
  using D = StretchLimit::TetherDistance;
  for (D d : {D::euclidean, D::geodesic})
    if (name == to_string(d))
      return d;
  return std::nullopt;
}

Result<void> SimParams::validate() {
  if (static_cast<std::uint32_t>(integrator) > static_cast<std::uint32_t>(Integrator::implicit_euler))
    return bad(
        fmt::format("integrator.method: unknown integrator {}", static_cast<std::uint32_t>(integrator)));
  if (!std::isfinite(dt) || dt <= 0.0)
    return bad(fmt::format("integrator.dt must be finite and > 0, got {}", dt));
  if (substeps < 1 || substeps > 1000000)
    return bad(fmt::format("integrator.substeps must be in 1..1000000, got {}", substeps));
  if (!std::isfinite(cg_tolerance) || cg_tolerance < 0.0 || cg_tolerance >= 1.0)
    return bad(fmt::format("integrator.cg_tolerance must be finite and in [0, 1), got {}", cg_tolerance));
  if (cg_max_iterations < 1 || cg_max_iterations > 100000)
    return bad(fmt::format("integrator.cg_max_iterations must be in 1..100000, got {}", cg_max_iterations));
  if (!finite(gravity))
    return bad("physics.gravity must be finite, got " + str(gravity));
  if (!std::isfinite(damping) || damping < 0.0)
    return bad(fmt::format("physics.damping must be finite and >= 0, got {}", damping));
  if (!std::isfinite(wind.strength))
    return bad(fmt::format("wind.strength must be finite, got {}", wind.strength));
  if (!finite(wind.direction))
    return bad("wind.direction must be finite, got " + str(wind.direction));
  if (wind.strength != 0.0) {
    const double len = glm::length(wind.direction);
    if (!(len > 0.0))
      return bad("wind.direction must be non-zero when wind.strength != 0, got " + str(wind.direction));
    wind.direction /= len;
  }
  if (!std::isfinite(contact_epsilon) || contact_epsilon < 0.0)
    return bad(fmt::format("contact_epsilon must be finite and >= 0, got {}", contact_epsilon));
  if (!std::isfinite(divergence_limit) || divergence_limit <= 0.0)
    return bad(fmt::format("divergence_limit must be finite and > 0, got {}", divergence_limit));
  if (std::uint32_t(stretch_limit.method) > std::uint32_t(StretchLimit::Method::both))
    return bad(fmt::format("stretch_limit.method: unknown method {}", std::uint32_t(stretch_limit.method)));
  if (!std::isfinite(stretch_limit.max_strain) || stretch_limit.max_strain <= 0.0)
    return bad(
        fmt::format("stretch_limit.max_strain must be finite and > 0, got {}", stretch_limit.max_strain));
  if (stretch_limit.iterations < 1 || stretch_limit.iterations > 100)
    return bad(fmt::format("stretch_limit.iterations must be in 1..100, got {}", stretch_limit.iterations));
  for (std::size_t k = 0; k < colliders.size(); ++k) {
    Collider& c = colliders[k];
    if (c.type == Collider::Type::plane) {
      if (!finite(c.normal))
        return bad(fmt::format("colliders[{}].normal must be finite, got {}", k, str(c.normal)));
      const double len = glm::length(c.normal);
      if (!(len > 0.0))
        return bad(fmt::format("colliders[{}].normal must be non-zero, got {}", k, str(c.normal)));
      c.normal /= len;
      if (!std::isfinite(c.offset))
        return bad(fmt::format("colliders[{}].offset must be finite, got {}", k, c.offset));
    } else if (c.type == Collider::Type::sphere) {
      if (!finite(c.center))
        return bad(fmt::format("colliders[{}].center must be finite, got {}", k, str(c.center)));
      if (!std::isfinite(c.radius) || c.radius <= 0.0)
        return bad(fmt::format("colliders[{}].radius must be finite and > 0, got {}", k, c.radius));
    } else {
      return bad(fmt::format("colliders[{}].type is unknown", k));
    }
  }
  return {};
}

SimParams StepParams::applied_to(SimParams params) const {
  if (dt)
    params.dt = *dt;
  if (gravity)
    params.gravity = *gravity;
  if (wind)
    params.wind = *wind;
  if (colliders)
    params.colliders = *colliders;
  return params;
}

} // namespace vkcloth
