// SPDX-License-Identifier: MIT
#include "internal/cloth_frame.hpp"

#include <glm/mat3x3.hpp>

namespace vkcloth::detail {

JumpRows jump_rows(const RigidJump& jump) {
  const glm::dmat3 rt = glm::transpose(jump.rotation); // its columns are the rows
  return {rt[0], rt[1], rt[2], jump.pivot + jump.translation - jump.rotation * jump.pivot};
}

RigidJump then(const RigidJump& a, const RigidJump& b) {
  RigidJump j;
  j.pivot = a.pivot;
  j.rotation = b.rotation * a.rotation;
  j.translation = b.apply(a.apply(a.pivot)) - a.pivot;
  return j;
}

Collider frame_collider(const SimParams& params) {
  if (params.inertia.collider)
    return params.colliders[*params.inertia.collider];
  if (!params.inertia.frame)
    return Collider{};
  const ColliderPose& f = *params.inertia.frame;
  Collider c = Collider::sphere(f.position, 0.0);
  c.rotation = f.rotation.value_or(glm::dmat3(1.0));
  c.linear_velocity = f.linear_velocity;
  c.angular_velocity = f.angular_velocity;
  return c;
}

bool same_frame(const Inertia& a, const Inertia& b) {
  return a.collider == b.collider && a.frame.has_value() == b.frame.has_value();
}

void advance_host_frame(SimParams& params, const double seconds) {
  if (!params.inertia.frame)
    return;
  const Collider c = frame_collider(params).posed_at(seconds);
  params.inertia.frame->position = c.centre();
  params.inertia.frame->rotation = c.rotation;
}

FrameStep frame_step(const SimParams& params, const Collider& before, const Collider& after,
                     const std::optional<RigidJump>& host) {
  FrameStep f;
  f.jump = host;
  if (!params.inertia.enabled())
    return f;
  glm::dvec3 c0 = before.centre(), v0 = before.linear_velocity, omega0 = before.angular_velocity;
  RigidJump keyed;
  double at = 0.0;
  if (before.path && before.path->jump_between(before.path_time, after.path_time, keyed, at)) {
    f.jump = f.jump ? then(*f.jump, keyed) : keyed;
    c0 = keyed.apply(c0); // the frame's start as the jump left it
    v0 = keyed.rotation * v0;
    omega0 = keyed.rotation * omega0;
  }
  f.carry_linear = 1.0 - params.inertia.linear;
  f.carry_angular = 1.0 - params.inertia.angular;
  f.carry = f.carry_linear > 0.0 || f.carry_angular > 0.0;
  f.dv = after.linear_velocity - v0;
  f.omega0 = omega0;
  f.omega1 = after.angular_velocity;
  f.c0 = c0;
  f.c1 = after.centre();
  return f;
}

} // namespace vkcloth::detail
