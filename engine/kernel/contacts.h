// SPDX-License-Identifier: MIT
// vkcloth kernel: colliders: one distance / normal function per shape (docs/model.md "Collisions"); the
// shape as the kernel takes it: shapes.h.
// Part of the kernel that cloth_kernel.h gathers (the rules it states hold here: fixed order,
// `precise` results, real(...) literals). No include guard: the C++ bridge includes it once per precision.

// ---- Contacts (docs/model.md "Collisions") ----------------------------------------------------

// The velocity of the collider's surface at p.
KFN precise vec3 surface_velocity(ColliderShape s, vec3 p) {
  precise vec3 v = s.velocity + cross3(s.spin, p - s.pivot);
  return v;
}

// p in the body frame of a box or mesh (R^T (p - centre)), and a body-frame direction back in the world.
KFN precise vec3 to_body(ColliderShape s, vec3 p) {
  precise vec3 r = p - s.a;
  return vec3(dot3(s.ax, r), dot3(s.ay, r), dot3(s.az, r));
}
KFN precise vec3 to_world_dir(ColliderShape s, vec3 d) {
  precise vec3 w = s.ax * d.x + s.ay * d.y;
  w = w + s.az * d.z;
  return w;
}

#include "mesh_contact.h" // a mesh collider's contact: mesh_contact

// Signed distance of p to a collider's surface (negative inside; a mesh: to the shell `thickness`
// around its triangles) and the outward unit normal there. A mesh's side is the side of the
// nearest triangle that `p_side` is on (where the particle came from), so a particle that crossed
// a thin mesh within one step is still pushed back to its side (its distance: the depth below the
// triangle's plane plus the thickness). Farther than `reach` from a mesh's shell: distance = reach
// (no contact). Plane {n.p = offset}; sphere; capsule: the segment
// a-c swept by the radius; box: edges and corners included. `deform`: a skinned mesh's surface
// velocity at the nearest point beyond its rigid motion (zero for every other collider).
KFN void collider_contact(MESH_DATA_PARAM, ColliderShape s, vec3 p, vec3 p_side, real reach,
                          OUT(real) distance, OUT(vec3) normal, OUT(vec3) deform) {
  deform = vec3(real(0));
  if (VKCLOTH_COLLIDER_PRESENT(VKCLOTH_COLLIDER_PLANE) && s.type == VKCLOTH_COLLIDER_PLANE) {
    precise real d = dot3(s.a, p) - s.b;
    distance = d;
    normal = s.a;
    return;
  }
  if (VKCLOTH_COLLIDER_PRESENT(VKCLOTH_COLLIDER_SPHERE) && s.type == VKCLOTH_COLLIDER_SPHERE) {
    precise vec3 r = p - s.a;
    precise real len = sqrt(dot3(r, r));
    precise vec3 n =
        select(len > real(0), r / len, vec3(real(0), real(0), real(1))); // at the centre: push up
    precise real d = len - s.b;
    distance = d;
    normal = n;
    return;
  }
  if (VKCLOTH_COLLIDER_PRESENT(VKCLOTH_COLLIDER_CAPSULE) && s.type == VKCLOTH_COLLIDER_CAPSULE) {
    precise vec3 axis = s.c - s.a;
    precise real len2 = dot3(axis, axis);
    precise real t = select(len2 > real(0), dot3(p - s.a, axis) / len2, real(0));
    t = min(max(t, real(0)), real(1));
    precise vec3 r = p - (s.a + axis * t);
    precise real len = sqrt(dot3(r, r));
    precise vec3 n = select(len > real(0), r / len, vec3(real(0), real(0), real(1)));
    precise real d = len - s.b;
    distance = d;
    normal = n;
    return;
  }
  precise vec3 q = to_body(s, p);
  if (VKCLOTH_COLLIDER_PRESENT(VKCLOTH_COLLIDER_BOX) && s.type == VKCLOTH_COLLIDER_BOX) {
    precise vec3 over = abs(q) - s.c; // > 0 along the axes where q is beyond a face
    precise vec3 out_part = max(over, vec3(real(0)));
    precise real out_len = sqrt(dot3(out_part, out_part));
    precise vec3 sgn =
        vec3(select(q.x < real(0), real(-1), real(1)), select(q.y < real(0), real(-1), real(1)),
             select(q.z < real(0), real(-1), real(1)));
    // Outside (out_len > 0): towards the nearest face, edge or corner.
    precise vec3 nb_out = (out_part * sgn) / out_len;
    VARYING(bool) outside = out_len > real(0);
    if (!any_particle(!outside)) {
      distance = out_len;
      normal = to_world_dir(s, nb_out);
      return;
    }
    // Inside: out through the nearest face (x, then y if deeper, then z if deeper still).
    VARYING(bool) y_deeper = over.y > over.x;
    precise real d = select(y_deeper, over.y, over.x);
    vec3 nb = select(y_deeper, vec3(real(0), sgn.y, real(0)), vec3(sgn.x, real(0), real(0)));
    VARYING(bool) z_deeper = over.z > d;
    d = select(z_deeper, over.z, d);
    nb = select(z_deeper, vec3(real(0), real(0), sgn.z), nb);
    distance = select(outside, out_len, d);
    normal = to_world_dir(s, select(outside, nb_out, nb));
    return;
  }
  // VKCLOTH_COLLIDER_MESH
  mesh_contact(MESH_DATA, s, q, p_side, reach, distance, normal, deform);
}
