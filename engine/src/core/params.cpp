// SPDX-License-Identifier: MIT
#include "vkcloth/params.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <fmt/format.h>

#include <glm/geometric.hpp>
#include <glm/gtc/matrix_transform.hpp>
#include <glm/gtc/quaternion.hpp>

#include "vkcloth/collider_mesh.hpp"

#include "argument_checks.hpp"

namespace vkcloth {
using detail::bad_argument;
using detail::finite;
using detail::str;
namespace {

bool positive(double x) {
  return std::isfinite(x) && x > 0.0;
}

// How far R is from an orthonormal right-handed frame (its columns; 0 for a rotation matrix).
double rotation_error(const glm::dmat3& r) {
  const glm::dmat3 e = glm::transpose(r) * r;
  double off = std::abs(glm::determinant(r) - 1.0);
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j)
      off = std::max(off, std::abs(e[i][j] - (i == j ? 1.0 : 0.0)));
  return off;
}

// A path's keys: at least one, t finite, >= 0 and strictly increasing, finite poses (the message
// names keyframes[k] and the value).
Result<void> check_keyframes(const std::vector<ColliderKeyframe>& keys) {
  if (keys.empty())
    return bad_argument("keyframes must hold at least one key, got none");
  for (std::size_t k = 0; k < keys.size(); ++k) {
    const ColliderKeyframe& key = keys[k];
    if (!std::isfinite(key.t) || key.t < 0.0)
      return bad_argument(fmt::format("keyframes[{}].t must be finite and >= 0, got {}", k, key.t));
    if (k > 0 && !(key.t > keys[k - 1].t))
      return bad_argument(
          fmt::format("keyframes[{}].t must be greater than keyframes[{}].t ({}): keys in time "
                      "order, got {}",
                      k, k - 1, keys[k - 1].t, key.t));
    if (!finite(key.translate))
      return bad_argument(
          fmt::format("keyframes[{}].translate must be finite, got {}", k, str(key.translate)));
    if (!finite(key.rotate_deg))
      return bad_argument(
          fmt::format("keyframes[{}].rotate_deg must be finite, got {}", k, str(key.rotate_deg)));
  }
  if (keys.front().teleport)
    return bad_argument(
        "keyframes[0].teleport: the first key has no pose to jump from (teleport a later key)");
  return {};
}

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

// One collider's fields (the message names `at`.field and the value); normalises a plane's normal.
Result<void> validate_collider(Collider& c, const std::string& at) {
  const auto vec = [&](const char* key, glm::dvec3 v) -> Result<void> {
    if (!finite(v))
      return bad_argument(fmt::format("{}.{} must be finite, got {}", at, key, str(v)));
    return {};
  };
  switch (c.type) {
  case Collider::Type::plane: {
    VKCLOTH_TRY(vec("normal", c.normal));
    const double len = glm::length(c.normal);
    if (!(len > 0.0))
      return bad_argument(fmt::format("{}.normal must be non-zero, got {}", at, str(c.normal)));
    c.normal /= len;
    if (!std::isfinite(c.offset))
      return bad_argument(fmt::format("{}.offset must be finite, got {}", at, c.offset));
    if (c.angular_velocity != glm::dvec3(0.0))
      return bad_argument(
          fmt::format("{}.angular_velocity: a plane cannot turn (it takes linear_velocity only), got {}", at,
                      str(c.angular_velocity)));
    break;
  }
  case Collider::Type::sphere:
    VKCLOTH_TRY(vec("center", c.center));
    if (!positive(c.radius))
      return bad_argument(fmt::format("{}.radius must be finite and > 0, got {}", at, c.radius));
    break;
  case Collider::Type::capsule:
    VKCLOTH_TRY(vec("a", c.a));
    VKCLOTH_TRY(vec("b", c.b));
    if (!positive(c.radius))
      return bad_argument(fmt::format("{}.radius must be finite and > 0, got {}", at, c.radius));
    break;
  case Collider::Type::box:
    VKCLOTH_TRY(vec("center", c.center));
    if (!positive(c.half_extents.x) || !positive(c.half_extents.y) || !positive(c.half_extents.z))
      return bad_argument(
          fmt::format("{}.half_extents must be finite and > 0, got {}", at, str(c.half_extents)));
    break;
  case Collider::Type::mesh:
    VKCLOTH_TRY(vec("center", c.center));
    if (!c.mesh)
      return bad_argument(fmt::format("{}: a mesh collider needs its mesh (ColliderMesh::create)", at));
    if (!positive(c.thickness))
      return bad_argument(fmt::format("{}.thickness must be finite and > 0, got {}", at, c.thickness));
    break;
  default:
    return bad_argument(fmt::format("{}.type is unknown ({})", at, std::uint32_t(c.type)));
  }
  for (int col = 0; col < 3; ++col)
    VKCLOTH_TRY(vec("rotation", c.rotation[col]));
  if (c.type == Collider::Type::box || c.type == Collider::Type::mesh) {
    const double off = rotation_error(c.rotation);
    if (!(off < 1e-6))
      return bad_argument(fmt::format(
          "{}.rotation must be a rotation matrix (orthonormal, determinant 1); it is off by {}", at, off));
  }
  if (!std::isfinite(c.friction) || c.friction < 0.0)
    return bad_argument(fmt::format("{}.friction must be finite and >= 0, got {}", at, c.friction));
  if (!std::isfinite(c.static_friction))
    return bad_argument(fmt::format("{}.static_friction must be finite, got {}", at, c.static_friction));
  if (c.static_friction >= 0.0 && c.static_friction < c.friction)
    return bad_argument(fmt::format("{}.static_friction must be >= friction ({}), got {}", at, c.friction,
                                    c.static_friction));
  VKCLOTH_TRY(vec("linear_velocity", c.linear_velocity));
  VKCLOTH_TRY(vec("angular_velocity", c.angular_velocity));
  if (c.path) // its keys, as with_keyframes checked them (a host may have built the path itself)
    if (auto keys = check_keyframes(c.path->keys); !keys)
      return bad_argument(fmt::format("{}.{}", at, keys.error().message));
  return {};
}

} // namespace

Collider Collider::plane(glm::dvec3 normal, double offset) {
  Collider c;
  c.type = Type::plane;
  c.normal = normal;
  c.offset = offset;
  return c;
}

Collider Collider::sphere(glm::dvec3 center, double radius) {
  Collider c;
  c.type = Type::sphere;
  c.center = center;
  c.radius = radius;
  return c;
}

Collider Collider::capsule(glm::dvec3 a, glm::dvec3 b, double radius) {
  Collider c;
  c.type = Type::capsule;
  c.a = a;
  c.b = b;
  c.radius = radius;
  return c;
}

Collider Collider::box(glm::dvec3 center, glm::dvec3 half_extents, glm::dmat3 rotation) {
  Collider c;
  c.type = Type::box;
  c.center = center;
  c.half_extents = half_extents;
  c.rotation = rotation;
  return c;
}

Collider Collider::triangle_mesh(std::shared_ptr<const ColliderMesh> mesh, glm::dvec3 origin,
                                 glm::dmat3 rotation, double thickness) {
  Collider c;
  c.type = Type::mesh;
  c.mesh = std::move(mesh);
  c.center = origin;
  c.rotation = rotation;
  c.thickness = thickness;
  return c;
}

glm::dmat3 Collider::rotation_from_degrees(glm::dvec3 degrees) {
  glm::dmat4 r(1.0);
  r = glm::rotate(r, glm::radians(degrees.z), glm::dvec3(0, 0, 1));
  r = glm::rotate(r, glm::radians(degrees.y), glm::dvec3(0, 1, 0));
  r = glm::rotate(r, glm::radians(degrees.x), glm::dvec3(1, 0, 0));
  return glm::dmat3(r);
}

glm::dvec3 Collider::centre() const {
  switch (type) {
  case Type::plane:
    return normal * offset;
  case Type::capsule:
    return (a + b) * 0.5;
  default:
    return center;
  }
}

namespace {
// The key of the last key at or before t (0 before the first).
std::size_t key_before(const std::vector<ColliderKeyframe>& keys, double t) {
  std::size_t k = 0;
  while (k + 1 < keys.size() && keys[k + 1].t <= t)
    ++k;
  return k;
}
} // namespace

void ColliderPath::pose(const double t, glm::dvec3& translate, glm::dmat3& rotation) const {
  const std::size_t k = key_before(keys, t);
  const ColliderKeyframe& k0 = keys[k];
  const glm::dmat3 r0 = Collider::rotation_from_degrees(k0.rotate_deg);
  // Held: before the first key, at a key, past the last, and until a teleport key's jump.
  if (k + 1 == keys.size() || t <= k0.t || keys[k + 1].teleport) {
    translate = k0.translate;
    rotation = r0;
    return;
  }
  const ColliderKeyframe& k1 = keys[k + 1];
  const double s = (t - k0.t) / (k1.t - k0.t);
  translate = k0.translate + (k1.translate - k0.translate) * s;
  const glm::dquat q0 = glm::quat_cast(r0),
                   q1 = glm::quat_cast(Collider::rotation_from_degrees(k1.rotate_deg));
  rotation = glm::mat3_cast(glm::slerp(q0, glm::dot(q0, q1) < 0.0 ? -q1 : q1, s)); // the shorter way
}

namespace {
// `base` turned by `turn` about its centre and moved by `shift` (a plane: about its point nearest
// the origin).
Collider moved(const Collider& base, const glm::dvec3 shift, const glm::dmat3& turn) {
  Collider c = base;
  const glm::dvec3 pivot = base.centre();
  if (base.type == Collider::Type::plane) { // turned about its point nearest the origin, then moved
    c.normal = turn * base.normal;
    c.offset = glm::dot(c.normal, pivot + shift);
    return c;
  }
  c.center = pivot + shift + turn * (base.center - pivot);
  c.a = pivot + shift + turn * (base.a - pivot);
  c.b = pivot + shift + turn * (base.b - pivot);
  c.rotation = turn * base.rotation;
  return c;
}
} // namespace

bool ColliderPath::jump_between(const double t0, const double t1, RigidJump& jump, double& at) const {
  for (std::size_t k = 1; k < keys.size(); ++k)
    if (keys[k].teleport && keys[k].t > t0 && keys[k].t <= t1) {
      glm::dvec3 shift0, shift1;
      glm::dmat3 turn0, turn1;
      pose(std::nextafter(keys[k].t, 0.0), shift0, turn0); // the pose held until the jump
      pose(keys[k].t, shift1, turn1);
      jump.pivot = base.centre() + shift0;
      jump.translation = shift1 - shift0;
      jump.rotation = turn1 * glm::transpose(turn0);
      at = keys[k].t;
      return true;
    }
  return false;
}

Collider ColliderPath::at(const double t) const {
  glm::dvec3 shift;
  glm::dmat3 turn;
  pose(t, shift, turn);
  return moved(base, shift, turn);
}

Result<Collider> Collider::with_keyframes(std::vector<ColliderKeyframe> keys) const {
  VKCLOTH_TRY(check_keyframes(keys));
  if (path)
    return bad_argument("keyframes: this collider follows keyframes already (give all its keys at once)");
  if (moving())
    return bad_argument(
        fmt::format("keyframes exclude linear_velocity and angular_velocity (the path gives the "
                    "velocity), got {} and {}",
                    str(linear_velocity), str(angular_velocity)));
  auto keyed = std::make_shared<ColliderPath>();
  keyed->keys = std::move(keys);
  keyed->base = *this;
  if (type == Type::plane) { // the poses turn and move a unit normal (validate_collider's normalisation)
    const double len = glm::length(normal);
    if (!(len > 0.0) || !finite(normal))
      return bad_argument(fmt::format("normal must be finite and non-zero, got {}", str(normal)));
    keyed->base.normal = normal / len;
  }
  Collider c = keyed->at(0.0);
  c.path = std::move(keyed);
  c.path_time = 0.0;
  return c;
}

Collider Collider::posed_at(double seconds) const {
  Collider c = *this;
  if (!moving() || seconds == 0.0)
    return c;
  if (path) { // the path's pose, and its motion over the advance as the velocities
    const double t1 = path_time + seconds;
    // Across a teleport key the motion starts after its jump (the jump is no velocity).
    RigidJump jump;
    double jumped_at = 0.0;
    const bool jumped = path->jump_between(path_time, t1, jump, jumped_at);
    const double from = jumped ? jumped_at : path_time;
    glm::dvec3 shift0, shift1;
    glm::dmat3 turn0, turn1;
    path->pose(from, shift0, turn0);
    path->pose(t1, shift1, turn1);
    c = moved(path->base, shift1, turn1);
    c.path = path;
    c.path_time = t1;
    if (t1 == from) { // the jump is the whole advance: at rest
      c.linear_velocity = c.angular_velocity = glm::dvec3(0.0);
      return c;
    }
    seconds = t1 - from;
    c.linear_velocity = (shift1 - shift0) / seconds;
    // The turn R1 R0^T (world frame, about the centre) as a rotation vector, by the quaternion's log
    // map: exact for small turns too, where w rounds to 1 (glm::axis then gives up and returns z).
    glm::dquat turn = glm::quat_cast(turn1 * glm::transpose(turn0));
    if (turn.w < 0.0)
      turn = -turn; // the same turn, by the angle in [0, pi]
    const glm::dvec3 im(turn.x, turn.y, turn.z);
    const double sin_half = glm::length(im);
    c.angular_velocity = type == Type::plane || sin_half == 0.0 // a plane takes linear velocity only
                             ? glm::dvec3(0.0)
                             : im * (2.0 * std::atan2(sin_half, turn.w) / sin_half / seconds);
    return c;
  }
  const glm::dvec3 shift = linear_velocity * seconds;
  if (type == Type::plane) { // a plane slides within itself: only its offset along n changes
    c.offset = offset + glm::dot(normal, shift);
    return c;
  }
  const glm::dvec3 pivot = centre();
  glm::dmat3 turn(1.0);
  const double angle = glm::length(angular_velocity) * seconds;
  if (angle != 0.0)
    turn = glm::dmat3(glm::rotate(glm::dmat4(1.0), angle, glm::normalize(angular_velocity)));
  c.center = pivot + shift + turn * (center - pivot);
  c.a = pivot + shift + turn * (a - pivot);
  c.b = pivot + shift + turn * (b - pivot);
  c.rotation = turn * rotation;
  return c;
}

Collider Collider::with_pose(const ColliderPose& pose) const {
  Collider c = *this;
  c.path = nullptr; // the host moves it now
  c.path_time = 0.0;
  c.linear_velocity = pose.linear_velocity;
  c.angular_velocity = pose.angular_velocity;
  switch (type) {
  case Type::plane:
    if (pose.rotation)
      c.normal = (*pose.rotation)[2];
    if (const double len = glm::length(c.normal); len > 0.0) // validate() normalises n, keeping the offset
      c.offset = glm::dot(c.normal, pose.position) / len;
    break;
  case Type::capsule: {
    const glm::dvec3 half = (b - a) * 0.5;
    const glm::dvec3 axis = pose.rotation ? (*pose.rotation)[2] * glm::length(half) : half;
    c.a = pose.position - axis;
    c.b = pose.position + axis;
    break;
  }
  default: // sphere, box, mesh
    c.center = pose.position;
    break;
  }
  if (pose.rotation && type != Type::plane) // every body keeps its frame (attachments follow it)
    c.rotation = *pose.rotation;
  return c;
}

Result<void> RigidJump::validate() const {
  if (!finite(pivot))
    return bad_argument("teleport: pivot must be finite, got " + str(pivot));
  if (!finite(translation))
    return bad_argument("teleport: translation must be finite, got " + str(translation));
  const double off = rotation_error(rotation);
  if (!(off < 1e-6))
    return bad_argument(fmt::format(
        "teleport: rotation must be a rotation matrix (orthonormal, determinant 1); it is off by {}", off));
  return {};
}

Result<void> ColliderPose::validate() const {
  if (!finite(position))
    return bad_argument("pose.position must be finite, got " + str(position));
  if (!finite(linear_velocity))
    return bad_argument("pose.linear_velocity must be finite, got " + str(linear_velocity));
  if (!finite(angular_velocity))
    return bad_argument("pose.angular_velocity must be finite, got " + str(angular_velocity));
  if (rotation) {
    const glm::dmat3& r = *rotation;
    for (int col = 0; col < 3; ++col)
      if (!finite(r[col]))
        return bad_argument(
            fmt::format("pose.rotation must be finite, got column {} = {}", col, str(r[col])));
    const double off = rotation_error(r);
    if (!(off < 1e-6))
      return bad_argument(fmt::format(
          "pose.rotation must be a rotation matrix (orthonormal, determinant 1); it is off by {}", off));
  }
  return {};
}

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
  for (Integrator i : {Integrator::explicit_euler, Integrator::semi_implicit_euler, Integrator::rk4,
                       Integrator::implicit_euler, Integrator::vbd})
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
  case StretchLimit::Method::projection:
    return "projection";
  }
  return "?";
}

std::optional<StretchLimit::Method> parse_stretch_method(std::string_view name) {
  using M = StretchLimit::Method;
  for (M m : {M::off, M::tethers, M::provot, M::both, M::projection})
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
  if (!finite(wind.direction))
    return bad_argument("wind.direction must be finite, got " + str(wind.direction));
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
  if (stretch_limit.iterations < 1 || stretch_limit.iterations > 100)
    return bad_argument(
        fmt::format("stretch_limit.iterations must be in 1..100, got {}", stretch_limit.iterations));
  for (std::size_t k = 0; k < colliders.size(); ++k)
    VKCLOTH_TRY(validate_collider(colliders[k], fmt::format("colliders[{}]", k)));
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
  if (self.thickness < 0.5 * smallest)
    warnings.push_back(fmt::format("self_collision.thickness {} m is below half the smallest rest length "
                                   "({:.4g} m): a triangle can pass between two particles; a thickness "
                                   "of at least {:.4g} m closes the gaps",
                                   self.thickness, smallest, 1.42 * mean));
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
