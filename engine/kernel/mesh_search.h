// SPDX-License-Identifier: MIT
// vkcloth kernel: a mesh collider's search (docs/model.md "Mesh contact"): the nearest
// triangle of the hierarchy (mesh_nearest) and the general contact with a triangle (triangle_contact,
// mesh_triangle_answer).
// Part of the kernel that cloth_kernel.h gathers (the rules it states hold here: fixed order,
// `precise` results, real(...) literals); mesh_contact.h includes it (a bridge without the search,
// VKCLOTH_KERNEL_NO_MESH, does not). No include guard: the C++ bridge includes it once per precision.

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

// The squared distance from q to triangle (a, b, c): the search's measure, the entries' too.
KFN precise real triangle_gap2(vec3 q, vec3 a, vec3 b, vec3 c) {
  precise vec3 d = q - closest_on_triangle(q, a, b, c);
  precise real d2 = dot3(d, d);
  return d2;
}

// The triangle of a mesh collider nearest to q (body frame) within `reach` (its index in `nearest`,
// VKCLOTH_MESH_NONE: none; its squared distance returned, reach^2: none), among those other than
// `skip` and `skip2` that reach in front of the plane {x: m.x = offset} or of {x: m2.x = offset2} by
// more than `tol` (m = m2 = 0, tol < 0: all). `second`: the next nearest, where its squared distance
// is within `slack` times the nearest's (an edge's other triangle; else VKCLOTH_MESH_NONE). Equally
// near ones: the lowest index first, so the answer is a function of q alone (an entry reproduces
// it). Walks the bounding-volume hierarchy depth first, the nearer child first, boxes no farther
// than slack times the nearest so far only. The including file provides
// mesh_node(MESH_DATA, i, lo, first, hi, count) and mesh_triangle(MESH_DATA, i, a, b, c)
// (vkcloth::ColliderMesh's Node and Triangle); MESH_DATA_PARAM declares MESH_DATA.
#define VKCLOTH_MESH_STACK 32
KFN precise real box_gap2(vec3 lo, vec3 hi, vec3 q) {
  precise vec3 gap = max(max(lo - q, q - hi), vec3(real(0)));
  return dot3(gap, gap);
}
KFN precise real box_ahead(vec3 lo, vec3 hi, vec3 m, real offset) {
  precise real ahead = dot3(m, (lo + hi) * real(0.5)) + dot3(abs(m), (hi - lo) * real(0.5)) - offset;
  return ahead;
}
KFN precise real triangle_ahead(vec3 a, vec3 b, vec3 c, vec3 m, real offset) {
  precise real ahead = max(max(dot3(m, a), dot3(m, b)), dot3(m, c)) - offset;
  return ahead;
}
// Whether (d2, i) comes before (best, at) (VKCLOTH_MESH_NONE: nothing yet, within best only).
KFN bool nearer(real d2, uint i, real best, uint at) {
  return d2 < best || (d2 == best && at != VKCLOTH_MESH_NONE && i < at);
}
KFN_NOINLINE real mesh_nearest(MESH_DATA_PARAM, uint root, uint tri0, vec3 q, real reach, uint skip,
                               uint skip2, vec3 m, real offset, vec3 m2, real offset2, real tol, real slack,
                               OUT(uint) nearest, OUT(uint) second) {
  nearest = VKCLOTH_MESH_NONE;
  second = VKCLOTH_MESH_NONE;
  precise real best = reach * reach;
  precise real best2 = best;
  const bool planes = tol >= real(0);
  // The stack holds nodes with their boxes' squared gaps to q (measured with their parent's).
  uint stack[VKCLOTH_MESH_STACK];
  real stack_gap[VKCLOTH_MESH_STACK];
  uint top = 1u;
  stack[0] = 0u;
  stack_gap[0] = real(0);
  while (top > 0u) {
    top = top - 1u;
    if (stack_gap[top] > best * slack) // too far
      continue;
    vec3 lo, hi;
    uint first, count;
    mesh_node(MESH_DATA, root + stack[top], lo, first, hi, count);
    if (planes && box_ahead(lo, hi, m, offset) <= tol && box_ahead(lo, hi, m2, offset2) <= tol)
      continue;        // wholly behind both planes
    if (count == 0u) { // the nearer child is walked first (the first one on a tie)
      vec3 lo1, hi1;
      uint f1, c1;
      mesh_node(MESH_DATA, root + first, lo, f1, hi, c1);
      mesh_node(MESH_DATA, root + first + 1u, lo1, f1, hi1, c1);
      precise real g0 = box_gap2(lo, hi, q), g1 = box_gap2(lo1, hi1, q);
      const bool swap = g1 < g0;
      stack[top] = swap ? first : first + 1u;
      stack_gap[top] = swap ? g0 : g1;
      stack[top + 1u] = swap ? first + 1u : first;
      stack_gap[top + 1u] = swap ? g1 : g0;
      top = top + 2u;
      continue;
    }
    for (uint t = first; t < first + count; ++t) {
      vec3 ta, tb, tc;
      const uint i = tri0 + t;
      mesh_triangle(MESH_DATA, i, ta, tb, tc);
      if (i == skip || i == skip2 ||
          (planes && triangle_ahead(ta, tb, tc, m, offset) <= tol &&
           triangle_ahead(ta, tb, tc, m2, offset2) <= tol))
        continue;
      precise real d2 = triangle_gap2(q, ta, tb, tc);
      if (nearer(d2, i, best, nearest)) {
        best2 = best;
        second = nearest;
        best = d2;
        nearest = i;
      } else if (nearer(d2, i, best2, second)) {
        best2 = d2;
        second = i;
      }
    }
  }
  if (best2 > best * slack)
    second = VKCLOTH_MESH_NONE;
  return best;
}

// The contact with triangle (a, b, c), the nearest to q: the general case (an edge, a corner, or a particle
// that crossed through the triangle).
KFN void triangle_contact(ColliderShape s, vec3 a, vec3 b, vec3 c, vec3 q, vec3 p_side, OUT(real) distance,
                          OUT(vec3) normal) {
  precise vec3 tn = unit_or_zero(cross3(b - a, c - a));
  precise vec3 cp = closest_on_triangle(q, a, b, c);
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

// A skinned mesh's surface velocity at point p of its triangle t (a, b, c); zero for a rigid mesh. The
// including file provides mesh_velocity(MESH_DATA, i, va, vb, vc) (ColliderMesh::triangle_velocities).
KFN void mesh_deformation(MESH_DATA_PARAM, ColliderShape s, uint t, vec3 p, vec3 a, vec3 b, vec3 c,
                          OUT(vec3) deform) {
  deform = vec3(real(0));
  if (!deforming(s))
    return;
  vec3 va, vb, vc;
  mesh_velocity(MESH_DATA, s.mesh_vel0 + (t - s.mesh_tri0), va, vb, vc);
  deform = triangle_velocity(s, p, a, b, c, va, vb, vc);
}

// The answer of the nearest triangle t (a, b, c) at squared distance gap2 by the general formula
// (nothing beyond the thickness + reach).
KFN void mesh_triangle_answer(MESH_DATA_PARAM, ColliderShape s, uint t, vec3 a, vec3 b, vec3 c, real gap2,
                              vec3 q, vec3 p_side, real reach, OUT(real) distance, OUT(vec3) normal,
                              OUT(vec3) deform) {
  distance = reach;
  normal = vec3(real(0), real(0), real(1));
  deform = vec3(real(0));
  precise real reach_total = s.b + reach;
  if (gap2 < reach_total * reach_total) {
    triangle_contact(s, a, b, c, q, p_side, distance, normal);
    mesh_deformation(MESH_DATA, s, t, closest_on_triangle(q, a, b, c), a, b, c, deform);
  }
}
