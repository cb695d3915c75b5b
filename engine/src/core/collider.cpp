// SPDX-License-Identifier: MIT
// Colliders: the factories, their keyframed paths (poses between keys, teleports), a host's poses, and
// the checks that name a bad field and its value (docs/scene-format.md "colliders").
#include "vkcloth/params.hpp"

#include <algorithm>
#include <cmath>
#include <fmt/format.h>

#include <glm/geometric.hpp>
#include <glm/gtc/matrix_transform.hpp>
#include <glm/gtc/quaternion.hpp>

#include "vkcloth/collider_mesh.hpp"

#include "internal/argument_checks.hpp"

namespace vkcloth {
using detail::bad_argument;
using detail::finite;
using detail::str;
namespace {

bool positive(double x) {
  return detail::in_range(x) && x > 0.0;
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

} // namespace

namespace detail {

// One collider's fields (the message names `at`.field and the value); normalises a plane's normal.
Result<void> validate_collider(Collider& c, const std::string& at) {
  const auto vec = [&](const char* key, glm::dvec3 v) -> Result<void> {
    if (!detail::in_range(v))
      return bad_argument(fmt::format("{}.{} must be finite and within +-1e30, got {}", at, key, str(v)));
    return {};
  };
  switch (c.type) {
  case Collider::Type::plane: {
    VKCLOTH_TRY(vec("normal", c.normal));
    const double len = glm::length(c.normal);
    if (!(len > 0.0))
      return bad_argument(fmt::format("{}.normal must be non-zero, got {}", at, str(c.normal)));
    c.normal /= len;
    if (!detail::in_range(c.offset))
      return bad_argument(fmt::format("{}.offset must be finite and within +-1e30, got {}", at, c.offset));
    if (c.angular_velocity != glm::dvec3(0.0))
      return bad_argument(
          fmt::format("{}.angular_velocity: a plane cannot turn (it takes linear_velocity only), got {}", at,
                      str(c.angular_velocity)));
    break;
  }
  case Collider::Type::sphere:
    VKCLOTH_TRY(vec("center", c.center));
    if (!positive(c.radius))
      return bad_argument(
          fmt::format("{}.radius must be finite, > 0 and at most 1e30, got {}", at, c.radius));
    break;
  case Collider::Type::capsule:
    VKCLOTH_TRY(vec("a", c.a));
    VKCLOTH_TRY(vec("b", c.b));
    if (!positive(c.radius))
      return bad_argument(
          fmt::format("{}.radius must be finite, > 0 and at most 1e30, got {}", at, c.radius));
    break;
  case Collider::Type::box:
    VKCLOTH_TRY(vec("center", c.center));
    if (!positive(c.half_extents.x) || !positive(c.half_extents.y) || !positive(c.half_extents.z))
      return bad_argument(fmt::format("{}.half_extents must be finite, > 0 and at most 1e30, got {}", at,
                                      str(c.half_extents)));
    break;
  case Collider::Type::mesh:
    VKCLOTH_TRY(vec("center", c.center));
    if (!c.mesh)
      return bad_argument(fmt::format("{}: a mesh collider needs its mesh (ColliderMesh::create)", at));
    if (!positive(c.thickness))
      return bad_argument(
          fmt::format("{}.thickness must be finite, > 0 and at most 1e30, got {}", at, c.thickness));
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

} // namespace detail

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

} // namespace vkcloth
