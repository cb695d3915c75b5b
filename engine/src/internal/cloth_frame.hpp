// SPDX-License-Identifier: MIT
// The cloth's frame over one substep (docs/model.md "Inertia and teleport"): whether it jumped (a
// teleport key of the frame collider's path, or the host's teleport), and how much of its motion
// carries the cloth (SimParams::inertia). Computed on the host, in double, the same for both
// backends (CpuSolver::step, the GPU batch's record), which apply it with the kernel's rigid_jump
// and carried_velocity.
#pragma once

#include <optional>

#include <glm/vec3.hpp>

#include "vkcloth/params.hpp"

namespace vkcloth::detail {

struct FrameStep {
  std::optional<RigidJump> jump; ///< before the substep: the whole cloth moves by it, unfelt
  bool carry = false;            ///< after the substep: carried_velocity applies (inertia < 1)
  glm::dvec3 dv{0.0};            ///< the frame's linear velocity change over the substep
  glm::dvec3 omega0{0.0}, omega1{0.0}, c0{0.0}, c1{0.0};
  double carry_linear = 0.0, carry_angular = 0.0; ///< 1 - inertia.linear, 1 - inertia.angular
};

/// A jump as the kernel's rigid_jump takes it: the rotation's rows and x' = R x + shift.
struct JumpRows {
  glm::dvec3 r0, r1, r2, shift;
};
JumpRows jump_rows(const RigidJump& jump);

/// `b` after `a`: x -> b.apply(a.apply(x)).
RigidJump then(const RigidJump& a, const RigidJump& b);

/// The cloth's frame as a collider (params.colliders[inertia.collider], or the host's frame as a
/// point with its pose and velocities; a default collider without a frame).
Collider frame_collider(const SimParams& params);
/// Whether two parameter sets name the same frame (the same collider, or both a host frame): a
/// solver keeps the frame as its last substep left it only while they do.
bool same_frame(const Inertia& a, const Inertia& b);
/// The host's frame (inertia.frame) advanced by `seconds` along its velocities (Collider::posed_at).
void advance_host_frame(SimParams& params, double seconds);

/// The substep of `params`' frame: `before` is its frame_collider as the last substep left it (so a
/// velocity the host set between steps is a change the cloth may not feel), `after` at the
/// substep's end (ignored without inertia); `host` a teleport the host asked for, applied first.
FrameStep frame_step(const SimParams& params, const Collider& before, const Collider& after,
                     const std::optional<RigidJump>& host);

} // namespace vkcloth::detail
