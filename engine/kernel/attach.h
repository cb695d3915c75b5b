// SPDX-License-Identifier: MIT
// Attachments and motion constraints (docs/model.md "Attachments"): a particle with a target (a
// point that moves with a collider or with the host's animation). A pinned particle is put on its
// target before each substep (drive_pinned); a free one is brought back within its reach after
// the substep (hold_within: NvCloth's motion constraint, Unity's max distance).
// Part of the kernel that cloth_kernel.h gathers (the rules it states hold here: fixed order,
// precise results). Not run on SIMD lanes: one loop over the targets, in list order.

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
