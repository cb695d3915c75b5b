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

// Mesh colliders: a search of the triangles' hierarchy per particle. A bridge that cannot run it (the
// CPU's SIMD lanes, which take no mesh collider) defines VKCLOTH_KERNEL_NO_MESH and its own mesh_contact.
#ifndef VKCLOTH_KERNEL_NO_MESH
// The closest point of triangle (a, b, c) to p (Ericson, Real-Time Collision Detection, 5.1.5).
KFN precise vec3 closest_on_triangle(vec3 p, vec3 a, vec3 b, vec3 c) {
  precise vec3 ab = b - a, ac = c - a, ap = p - a;
  precise real d1 = dot3(ab, ap), d2 = dot3(ac, ap);
  if (d1 <= real(0) && d2 <= real(0))
    return a;
  precise vec3 bp = p - b;
  precise real d3 = dot3(ab, bp), d4 = dot3(ac, bp);
  if (d3 >= real(0) && d4 <= d3)
    return b;
  precise real vc = d1 * d4 - d3 * d2;
  if (vc <= real(0) && d1 >= real(0) && d3 <= real(0)) {
    precise real v = d1 / (d1 - d3);
    precise vec3 q = a + ab * v;
    return q;
  }
  precise vec3 cp = p - c;
  precise real d5 = dot3(ab, cp), d6 = dot3(ac, cp);
  if (d6 >= real(0) && d5 <= d6)
    return c;
  precise real vb = d5 * d2 - d1 * d6;
  if (vb <= real(0) && d2 >= real(0) && d6 <= real(0)) {
    precise real w = d2 / (d2 - d6);
    precise vec3 q = a + ac * w;
    return q;
  }
  precise real va = d3 * d6 - d5 * d4;
  precise real e43 = d4 - d3, e56 = d5 - d6;
  if (va <= real(0) && e43 >= real(0) && e56 >= real(0)) {
    precise real w = e43 / (e43 + e56);
    precise vec3 q = b + (c - b) * w;
    return q;
  }
  precise real denom = real(1) / ((va + vb) + vc);
  precise real v = vb * denom, w = vc * denom;
  precise vec3 q = a + ab * v;
  q = q + ac * w;
  return q;
}

// The triangle of a mesh collider nearest to q (body frame) within `reach`: its closest point and
// unit normal. Walks the bounding-volume hierarchy depth first, nearer-or-equal boxes only, in
// a fixed order, so both backends pick the same triangle. The including file provides
// mesh_node(MESH_DATA, i, lo, first, hi, count) and mesh_triangle(MESH_DATA, i, a, b, c)
// (vkcloth::ColliderMesh's Node and Triangle); MESH_DATA_PARAM declares MESH_DATA.
#define VKCLOTH_MESH_STACK 32
KFN_NOINLINE bool mesh_closest(MESH_DATA_PARAM, uint root, uint tri0, vec3 q, real reach, OUT(vec3) closest,
                               OUT(vec3) normal) {
  closest = q;
  normal = vec3(real(0), real(0), real(1));
  precise real best = reach * reach;
  bool found = false;
  uint stack[VKCLOTH_MESH_STACK];
  uint top = 1u;
  stack[0] = 0u;
  while (top > 0u) {
    top = top - 1u;
    vec3 lo, hi;
    uint first, count;
    mesh_node(MESH_DATA, root + stack[top], lo, first, hi, count);
    precise vec3 out_lo = lo - q, out_hi = q - hi;
    precise vec3 gap = max(max(out_lo, out_hi), vec3(real(0)));
    if (dot3(gap, gap) > best)
      continue;
    if (count == 0u) { // the first child is walked first
      stack[top] = first + 1u;
      stack[top + 1u] = first;
      top = top + 2u;
      continue;
    }
    for (uint t = first; t < first + count; ++t) {
      vec3 ta, tb, tc;
      mesh_triangle(MESH_DATA, tri0 + t, ta, tb, tc);
      precise vec3 cp = closest_on_triangle(q, ta, tb, tc);
      precise vec3 d = q - cp;
      precise real d2 = dot3(d, d);
      if (d2 < best) {
        best = d2;
        closest = cp;
        normal = unit_or_zero(cross3(tb - ta, tc - ta));
        found = true;
      }
    }
  }
  return found;
}

// collider_contact for a mesh collider, q = p in its body frame (to_body).
KFN_NOINLINE void mesh_contact(MESH_DATA_PARAM, ColliderShape s, vec3 q, vec3 p_side, real reach,
                               OUT(real) distance, OUT(vec3) normal) {
  vec3 cp, tn;
  distance = reach;
  normal = vec3(real(0), real(0), real(1));
  if (!VKCLOTH_COLLIDER_PRESENT(VKCLOTH_COLLIDER_MESH) ||
      !mesh_closest(MESH_DATA, s.mesh_root, s.mesh_tri0, q, s.b + reach, cp, tn))
    return;
  precise vec3 r = q - cp;
  precise real len = sqrt(dot3(r, r));
  precise real side = select(dot3(to_body(s, p_side) - cp, tn) < real(0), real(-1), real(1));
  precise vec3 side_n = tn * side;
  precise real along = dot3(r, side_n);
  precise vec3 across = r - side_n * along; // beyond an edge: its offset in the triangle's plane
  if (along < real(0) && dot3(across, across) <= s.b * s.b) {
    // Crossed to the other side through the triangle (or within the shell of its edge): back out
    // on the side it came from.
    precise real d = along - s.b;
    distance = d;
    normal = to_world_dir(s, side_n);
    return;
  }
  precise vec3 nb = select(len > real(0), r / len, side_n);
  precise real d = len - s.b;
  distance = d;
  normal = to_world_dir(s, nb);
}
#endif // VKCLOTH_KERNEL_NO_MESH

// Signed distance of p to a collider's surface (negative inside; a mesh: to the shell `thickness`
// around its triangles) and the outward unit normal there. A mesh's side is the side of the
// nearest triangle that `p_side` is on (where the particle came from), so a particle that crossed
// a thin mesh within one step is still pushed back to its side (its distance: the depth below the
// triangle's plane plus the thickness). Farther than `reach` from a mesh's shell: distance = reach
// (no contact). Plane {n.p = offset}; sphere; capsule: the segment
// a-c swept by the radius; box: edges and corners included.
KFN void collider_contact(MESH_DATA_PARAM, ColliderShape s, vec3 p, vec3 p_side, real reach,
                          OUT(real) distance, OUT(vec3) normal) {
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
  mesh_contact(MESH_DATA, s, q, p_side, reach, distance, normal);
}
