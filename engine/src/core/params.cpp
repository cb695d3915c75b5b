// SPDX-License-Identifier: MIT
// The simulation parameters' names and checks (SimParams::validate: each key's domain, named with its
// value) and attachments to colliders; the colliders themselves: collider.cpp.
#include "vkcloth/params.hpp"

#include <algorithm>
#include <cmath>
#include <initializer_list>
#include <limits>
#include <optional>
#include <fmt/format.h>

#include <glm/geometric.hpp>
#include <glm/matrix.hpp>

#include "internal/argument_checks.hpp"
#include "system_triangles.hpp"

namespace vkcloth {
using detail::bad_argument;
using detail::finite;
using detail::str;
namespace {

// An attachment's collider (in the list, not a plane), offsets (one per particle, finite) and
// distance; its particles are the solver's to check against the cloth (PinTargets::check).
Result<void> validate_attachment(const Attachment& a, const std::vector<Collider>& colliders,
                                 const std::string& at) {
  if (a.collider >= colliders.size())
    return bad_argument(
        fmt::format("{}.collider is {}, but there are {} colliders", at, a.collider, colliders.size()));
  if (colliders[a.collider].type == Collider::Type::plane)
    return bad_argument(fmt::format("{}.collider {} is a plane, which has no frame to follow (attach to a "
                                    "sphere, capsule, box or mesh)",
                                    at, a.collider));
  if (a.offsets.size() != a.particles.size())
    return bad_argument(fmt::format("{} has {} particles but {} offsets (one each)", at, a.particles.size(),
                                    a.offsets.size()));
  for (std::size_t i = 0; i < a.offsets.size(); ++i)
    if (!finite(a.offsets[i]))
      return bad_argument(fmt::format("{}.offsets[{}] must be finite, got {}", at, i, str(a.offsets[i])));
  if (!std::isfinite(a.max_distance) || a.max_distance < 0.0)
    return bad_argument(fmt::format("{}.max_distance must be finite and >= 0, got {}", at, a.max_distance));
  return {};
}

/// The value among `values` whose to_string is `name` (a scene key's string); nullopt for none.
template <typename Enum>
std::optional<Enum> parse_named(std::string_view name, std::initializer_list<Enum> values) {
  for (Enum v : values)
    if (name == to_string(v))
      return v;
  return std::nullopt;
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
  case Integrator::vbd:
    return "vbd";
  }
  return "?";
}

std::optional<Integrator> parse_integrator(std::string_view name) {
  return parse_named(name, {Integrator::explicit_euler, Integrator::semi_implicit_euler, Integrator::rk4,
                            Integrator::implicit_euler, Integrator::vbd});
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
  case StretchLimit::Method::projection:
    return "projection";
  }
  return "?";
}

std::optional<StretchLimit::Method> parse_stretch_method(std::string_view name) {
  using M = StretchLimit::Method;
  return parse_named(name, {M::off, M::tethers, M::provot, M::both, M::projection});
}

const char* to_string(StretchLimit::TetherDistance distance) {
  return distance == StretchLimit::TetherDistance::euclidean ? "euclidean" : "geodesic";
}

std::optional<StretchLimit::TetherDistance> parse_tether_distance(std::string_view name) {
  using D = StretchLimit::TetherDistance;
  return parse_named(name, {D::euclidean, D::geodesic});
}

const char* to_string(StretchLimit::SweepOrder order) {
  return order == StretchLimit::SweepOrder::colours ? "colours" : "chains";
}

std::optional<StretchLimit::SweepOrder> parse_sweep_order(std::string_view name) {
  using O = StretchLimit::SweepOrder;
  return parse_named(name, {O::colours, O::chains});
}

namespace detail {
std::string divergence_advice(double dt) {
  if (dt < 1e-6)
    return fmt::format("integrator.dt = {:g} s is under a microsecond, where terms in 1 / dt^2 overflow "
                       "float: use a longer step (or the double CPU solver)",
                       dt);
  return "try a smaller integrator.dt, lower stiffness or more damping";
}
} // namespace detail

Result<void> SimParams::validate() {
  if (static_cast<std::uint32_t>(integrator) > static_cast<std::uint32_t>(Integrator::vbd))
    return bad_argument(
        fmt::format("integrator.method: unknown integrator {}", static_cast<std::uint32_t>(integrator)));
  if (!std::isfinite(dt) || dt <= 0.0)
    return bad_argument(fmt::format("integrator.dt must be finite and > 0, got {}", dt));
  if (substeps < 1 || substeps > 1000000)
    return bad_argument(fmt::format("integrator.substeps must be in 1..1000000, got {}", substeps));
  if (!std::isfinite(cg_tolerance) || cg_tolerance < 0.0 || cg_tolerance >= 1.0)
    return bad_argument(
        fmt::format("integrator.cg_tolerance must be finite and in [0, 1), got {}", cg_tolerance));
  if (cg_max_iterations < 1 || cg_max_iterations > 100000)
    return bad_argument(
        fmt::format("integrator.cg_max_iterations must be in 1..100000, got {}", cg_max_iterations));
  if (vbd_iterations < 1 || vbd_iterations > 1000)
    return bad_argument(
        fmt::format("integrator.iterations (vbd) must be in 1..1000, got {}", vbd_iterations));
  if (!finite(gravity))
    return bad_argument("physics.gravity must be finite, got " + str(gravity));
  if (!std::isfinite(damping) || damping < 0.0)
    return bad_argument(fmt::format("physics.damping must be finite and >= 0, got {}", damping));
  if (!std::isfinite(wind.strength))
    return bad_argument(fmt::format("wind.strength must be finite, got {}", wind.strength));
  if (!detail::in_range(wind.direction))
    return bad_argument("wind.direction must be finite and within +-1e30, got " + str(wind.direction));
  if (wind.strength != 0.0) {
    const double len = glm::length(wind.direction);
    if (!(len > 0.0))
      return bad_argument("wind.direction must be non-zero when wind.strength != 0, got " +
                          str(wind.direction));
    wind.direction /= len;
  }
  if (!std::isfinite(contact_epsilon) || contact_epsilon < 0.0)
    return bad_argument(fmt::format("contact_epsilon must be finite and >= 0, got {}", contact_epsilon));
  if (!std::isfinite(divergence_limit) || divergence_limit <= 0.0)
    return bad_argument(fmt::format("divergence_limit must be finite and > 0, got {}", divergence_limit));
  if (std::uint32_t(stretch_limit.method) > std::uint32_t(StretchLimit::Method::projection))
    return bad_argument(
        fmt::format("stretch_limit.method: unknown method {}", std::uint32_t(stretch_limit.method)));
  if (!std::isfinite(stretch_limit.max_strain) || stretch_limit.max_strain <= 0.0)
    return bad_argument(
        fmt::format("stretch_limit.max_strain must be finite and > 0, got {}", stretch_limit.max_strain));
  if (std::uint32_t(stretch_limit.order) > std::uint32_t(StretchLimit::SweepOrder::chains))
    return bad_argument(
        fmt::format("stretch_limit.order: unknown sweep order {}", std::uint32_t(stretch_limit.order)));
  if (stretch_limit.iterations < 1 || stretch_limit.iterations > 100)
    return bad_argument(
        fmt::format("stretch_limit.iterations must be in 1..100, got {}", stretch_limit.iterations));
  for (std::size_t k = 0; k < colliders.size(); ++k)
    VKCLOTH_TRY(detail::validate_collider(colliders[k], fmt::format("colliders[{}]", k)));
  if (!std::isfinite(self_collision.thickness) || self_collision.thickness <= 0.0)
    return bad_argument(fmt::format("self_collision.thickness must be finite and > 0 (metres), got {}",
                                    self_collision.thickness));
  if (!std::isfinite(self_collision.friction) || self_collision.friction < 0.0)
    return bad_argument(
        fmt::format("self_collision.friction must be finite and >= 0, got {}", self_collision.friction));
  // A skin of many thicknesses puts most of the cloth in each particle's list (quadratic).
  if (!std::isfinite(self_collision.skin) || self_collision.skin < 0.0 ||
      self_collision.skin > 10.0 * self_collision.thickness)
    return bad_argument(fmt::format("self_collision.skin must be finite, >= 0 and at most 10 x the thickness "
                                    "({} m), got {}",
                                    10.0 * self_collision.thickness, self_collision.skin));
  if (!std::isfinite(self_collision.stiffness) || self_collision.stiffness < 0.0)
    return bad_argument(fmt::format("self_collision.stiffness must be finite and >= 0 (N/m), got {}",
                                    self_collision.stiffness));
  if (self_collision.stiffness > 0.0 && !(self_collision.skin > 0.0))
    return bad_argument(fmt::format("self_collision.stiffness {} needs a self_collision.skin > 0 (the vertex "
                                    "steps read the neighbour lists), got skin {}",
                                    self_collision.stiffness, self_collision.skin));
  if (self_collision.iterations < 1 || self_collision.iterations > 16)
    return bad_argument(
        fmt::format("self_collision.iterations must be in 1..16, got {}", self_collision.iterations));
  for (std::size_t k = 0; k < attachments.size(); ++k)
    VKCLOTH_TRY(validate_attachment(attachments[k], colliders, fmt::format("attachments[{}]", k)));
  if (inertia.collider) {
    if (*inertia.collider >= colliders.size())
      return bad_argument(fmt::format("inertia.collider is {}, but there are {} colliders", *inertia.collider,
                                      colliders.size()));
    if (colliders[*inertia.collider].type == Collider::Type::plane)
      return bad_argument(fmt::format("inertia.collider {} is a plane, which has no frame (use a sphere, "
                                      "capsule, box or mesh)",
                                      *inertia.collider));
  }
  if (inertia.frame) {
    if (inertia.collider)
      return bad_argument("inertia: give a collider or a frame, not both");
    if (auto r = inertia.frame->validate(); !r)
      return bad_argument("inertia.frame: " + r.error().message);
  }
  for (const auto& [key, value] :
       {std::pair{"linear", inertia.linear}, std::pair{"angular", inertia.angular}})
    if (!(value >= 0.0 && value <= 1.0))
      return bad_argument(fmt::format("inertia.{} must be in [0, 1], got {}", key, value));
  return {};
}

Result<Attachment> Attachment::at_rest(const Collider& collider, std::uint32_t index,
                                       std::vector<std::uint32_t> particles,
                                       const std::vector<glm::dvec3>& positions, double max_distance) {
  if (collider.type == Collider::Type::plane)
    return bad_argument(fmt::format("attach: collider {} is a plane, which has no frame to follow (attach "
                                    "to a sphere, capsule, box or mesh)",
                                    index));
  if (!std::isfinite(max_distance) || max_distance < 0.0)
    return bad_argument(fmt::format("attach: max_distance must be finite and >= 0, got {}", max_distance));
  Attachment a;
  a.collider = index;
  a.max_distance = max_distance;
  const glm::dvec3 centre = collider.centre();
  const glm::dmat3 to_body = glm::transpose(collider.rotation);
  for (const std::uint32_t p : particles) {
    if (p >= positions.size())
      return bad_argument(
          fmt::format("attach: particle {} is past the cloth's {} particles", p, positions.size()));
    a.offsets.push_back(to_body * (positions[p] - centre));
  }
  a.particles = std::move(particles);
  return a;
}

Result<std::vector<std::string>> check_self_collision(const SelfCollision& self,
                                                      const ParticleSystem& system) {
  std::vector<std::string> warnings;
  if (!self.enabled)
    return warnings;
  bool structural = false;
  for (const Spring& s : system.springs)
    structural = structural || s.kind == SpringKind::structural;
  double sum = 0.0, smallest = std::numeric_limits<double>::infinity();
  std::size_t n = 0;
  for (const Spring& s : system.springs)
    if ((!structural || s.kind == SpringKind::structural) && s.rest_length > 0.0) {
      sum += s.rest_length;
      smallest = std::min(smallest, s.rest_length);
      ++n;
    }
  if (n == 0)
    return warnings; // no spring lengths to compare with (free particles)
  const double mean = sum / double(n);
  if (self.thickness > 10.0 * mean)
    return bad_argument(
        fmt::format("self_collision.thickness {} m is more than 10 x the mean rest length of the "
                    "system's {} ({:.4g} m): every particle would touch most of the cloth; "
                    "use a thickness near the particle spacing",
                    self.thickness, structural ? "structural springs" : "springs", mean));
  const double circumradius = detail::largest_circumradius(system);
  if (self.thickness < 0.5 * smallest)
    warnings.push_back(fmt::format("self_collision.thickness {} m is below half the smallest rest length "
                                   "({:.4g} m): a triangle can pass between two particles; a thickness "
                                   "of at least {:.4g} m closes the gaps",
                                   self.thickness, smallest, 1.42 * mean));
  else if (self.thickness < circumradius) // particles only: a point crossing a triangle's middle is unseen
    warnings.push_back(fmt::format("self_collision.thickness {} m is below the largest circumradius of the "
                                   "cloth's triangles ({:.4g} m): a particle can cross another layer's "
                                   "triangle farther than the thickness from its corners; keep it above "
                                   "{:.4g} m (more where a contact stiffness lets pairs overlap)",
                                   self.thickness, circumradius, circumradius));
  return warnings;
}

Result<SimParams> with_collider_pose(SimParams params, std::size_t collider, const ColliderPose& pose) {
  if (collider >= params.colliders.size())
    return bad_argument(fmt::format("colliders[{}]: no such collider to pose, the cloth has {} collider{}",
                                    collider, params.colliders.size(),
                                    params.colliders.size() == 1 ? "" : "s"));
  VKCLOTH_TRY(pose.validate());
  params.colliders[collider] = params.colliders[collider].with_pose(pose);
  return params;
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
