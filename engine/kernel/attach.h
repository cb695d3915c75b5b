// SPDX-License-Identifier: MIT
// Attachments and motion constraints (docs/model.md "Attachments and motion constraints"): a
// particle with a target (a point that moves with a collider or with the host's animation). A
// pinned particle is put on its target before each substep (drive_pinned); a free one is brought
// back within its reach after the substep (hold_within: NvCloth's motion constraint, Unity's max
// distance). And the cloth's frame (docs/model.md "Inertia and teleport"): its jumps (rigid_jump)
// and the share of its motion the cloth does not feel (carried_velocity).
// Part of the kernel that cloth_kernel.h gathers (the rules it states hold here: fixed order,
// precise results). Not run on SIMD lanes: one loop over the targets, or the particles, in order.

// A pinned particle on its target at the substep's end, moving with the target's velocity.
KFN void drive_pinned(vec3 target, vec3 target_velocity, OUT(vec3) x, OUT(vec3) v) {
  x = target;
  v = target_velocity;
}

// A free particle farther than `reach` from its target comes back onto the sphere of that radius
// around it, and its velocity relative to the target loses its outward part; reach 0 puts it on
// the target with the target's velocity. False (nothing changed) when it is within reach.
KFN bool hold_within(vec3 target, vec3 target_velocity, real reach, INOUT(vec3) x, INOUT(vec3) v) {
  precise vec3 d = x - target;
  precise real len2 = dot3(d, d);
  precise real reach2 = reach * reach;
  if (!(len2 > reach2))
    return false;
  if (!(reach > real(0))) {
    x = target;
    v = target_velocity;
    return true;
  }
  precise real len = sqrt(len2);
  precise vec3 n = d / len;
  precise vec3 back = n * reach;
  x = target + back;
  precise vec3 relative = v - target_velocity;
  precise real outward = dot3(relative, n);
  if (outward > real(0)) {
    precise vec3 cut = n * outward;
    v = v - cut;
  }
  return true;
}

// ---- The cloth's frame (docs/model.md "Inertia and teleport") ----------------------------------

// A rigid jump of a particle (a teleport of the cloth's frame): x -> (r0.x, r1.x, r2.x) + shift, v
// turned the same way (r0, r1, r2: the rotation's rows).
KFN void rigid_jump(vec3 r0, vec3 r1, vec3 r2, vec3 shift, INOUT(vec3) x, INOUT(vec3) v) {
  precise vec3 turned = vec3(dot3(r0, x), dot3(r1, x), dot3(r2, x));
  x = turned + shift;
  v = vec3(dot3(r0, v), dot3(r1, v), dot3(r2, v));
}

// The velocity change that carries a particle with its frame over a substep, for the share of the
// frame's motion the cloth does not feel (carry = 1 - inertia): the frame's linear velocity change
// dv, and the change of its rotation's velocity field along the particle's move, from x0 (the
// substep's start, frame centre c0 turning at omega0) to x1 (its end, c1, omega1), which holds the
// angular acceleration and the centrifugal and Coriolis parts.
KFN vec3 carried_velocity(vec3 x0, vec3 x1, vec3 dv, vec3 omega0, vec3 omega1, vec3 c0, vec3 c1,
                          real carry_linear, real carry_angular) {
  precise vec3 spin = cross3(omega1, x1 - c1) - cross3(omega0, x0 - c0);
  precise vec3 linear = dv * carry_linear;
  precise vec3 angular = spin * carry_angular;
  return linear + angular;
}
