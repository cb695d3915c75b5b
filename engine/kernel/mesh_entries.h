// SPDX-License-Identifier: MIT
// vkcloth kernel: the entries a mesh collider's search leaves beside a face's (docs/model.md
// "Mesh contact"): the ball from the clearances, an edge's hinge (mesh_edge_wedge) and a convex
// corner's fan (mesh_corner).
// Part of the kernel that cloth_kernel.h gathers (the rules it states hold here: fixed order,
// `precise` results, real(...) literals); mesh_contact.h includes it (a bridge without the search,
// VKCLOTH_KERNEL_NO_MESH, does not). No include guard: the C++ bridge includes it once per precision.

// The ball an entry at distance d1 may keep from its triangles' clearance (ColliderMesh::Triangle): a
// triangle reaching in front of the plane is at least `clear` from the face (edge), hence from q at
// distance d < clear / 2 farther than the face (edge) is. Capped, so that its square stays finite.
KFN precise real mesh_clear_radius(real clear, real d1, real guard) {
  precise real r = min(clear * real(0.5) - guard - d1, real(1e15));
  return r;
}

// Triangle (a, b, c) seen from its corner k (0: a): that corner f and the edge e0 -> e1 opposite it,
// in the triangle's counter-clockwise order.
KFN void corner_and_edge(uint k, vec3 a, vec3 b, vec3 c, OUT(vec3) f, OUT(vec3) e0, OUT(vec3) e1) {
  f = k == 0u ? a : (k == 1u ? b : c);
  e0 = k == 0u ? b : (k == 1u ? c : a);
  e1 = k == 0u ? c : (k == 1u ? a : b);
}

// An edge's two triangles (f1, e0, e1) and (f2, g0, g1) (the same edge e0 -> e1, the other way
// round in the second), each plane turned by s1, s2 (+1: its winding's front) to face away from the
// other triangle: the wedge W behind both planes holds both triangles. Whether q lies near their edge
// (within guard of it inside a face, or beyond it on both: the band that face entries leave) where
// the nearest point of W lies in one of the triangles: q's foot on the first's plane inside it, q in
// front; else the same on the second; else q beyond the edge on both, in front of both, its foot on
// the edge inside it. Only the outer borders keep a guard (on each side of an inner one the nearest
// point lies in a triangle). n1, n2: the triangles' unit normals (their winding's); the tests
// compared squared (inside_edge: no root, no division).
KFN bool mesh_hinge(vec3 q, vec3 f1, vec3 e0, vec3 e1, vec3 n1, real s1, vec3 f2, vec3 g0, vec3 g1, vec3 n2,
                    real s2, real guard) {
  precise real h1 = dot3(q - e0, n1) * s1, h2 = dot3(q - g0, n2) * s2;
  if (edge_side(q, n1, e0, e1) >= real(0))
    return !inside_edge(q, n1, e0, e1, real(1), guard) && h1 > guard &&
           inside_edge(q, n1, e1, f1, real(1), guard) && inside_edge(q, n1, f1, e0, real(1), guard);
  if (edge_side(q, n2, g0, g1) >= real(0))
    return !inside_edge(q, n2, g0, g1, real(1), guard) && h2 > guard &&
           inside_edge(q, n2, g1, f2, real(1), guard) && inside_edge(q, n2, f2, g0, real(1), guard);
  precise vec3 e = e1 - e0;
  precise real g2 = guard * guard * dot3(e, e);
  precise real from0 = dot3(q - e0, e), from1 = dot3(e1 - q, e);
  return from0 > real(0) && from0 * from0 > g2 && from1 > real(0) && from1 * from1 > g2 && h1 > real(0) &&
         h2 > real(0);
}

// An edge entry's hinge, where the search's nearest triangle t (a, b, c) shares an edge with t2 (its
// second, as near): the planes' turns (each away from the other triangle's far corner; flat: towards
// q), the entry's code (k + 3 k2 + 9 [s1 < 0] + 18 [s2 < 0], corner_and_edge), m1, m2 (the turned
// normals) and e0 (on both planes), and the triangles' clearance on the wedge's side. False where
// there is no such edge or the nearest point of the wedge to q lies in neither triangle (mesh_hinge).
KFN bool mesh_edge_wedge(MESH_DATA_PARAM, uint t, vec3 a, vec3 b, vec3 c, uint t2, vec3 q, real guard,
                         OUT(vec3) m1, OUT(vec3) m2, OUT(vec3) e0, OUT(uint) code, OUT(real) clear) {
  if (t2 == VKCLOTH_MESH_NONE || t2 >= 16777216u) // the entry holds t2 as a real: exact below 2^24
    return false;
  vec3 a2, b2, c2, f1, e1, f2, g0, g1;
  mesh_triangle(MESH_DATA, t2, a2, b2, c2);
  // t's corner opposite the shared edge (its other two are corners of t2), then t2's.
  uint k = 3u, k2 = 3u;
  for (uint i = 0u; i < 3u; ++i) {
    corner_and_edge(i, a, b, c, f1, e0, e1);
    if ((e0 == a2 || e0 == b2 || e0 == c2) && (e1 == a2 || e1 == b2 || e1 == c2))
      k = i;
  }
  if (k == 3u)
    return false;
  corner_and_edge(k, a, b, c, f1, e0, e1);
  for (uint i = 0u; i < 3u; ++i) {
    corner_and_edge(i, a2, b2, c2, f2, g0, g1);
    if (f2 != e0 && f2 != e1)
      k2 = i;
  }
  corner_and_edge(k2, a2, b2, c2, f2, g0, g1);
  precise vec3 n1 = unit_or_zero(cross3(e0 - f1, e1 - f1)), n2 = unit_or_zero(cross3(g0 - f2, g1 - f2));
  precise real h1 = dot3(n1, f2 - e0), h2 = dot3(n2, f1 - e0);
  precise real s1 = abs(h1) <= guard ? select(dot3(n1, q - e0) < real(0), real(-1), real(1))
                                     : select(h1 < real(0), real(1), real(-1));
  precise real s2 = abs(h2) <= guard ? select(dot3(n2, q - e0) < real(0), real(-1), real(1))
                                     : select(h2 < real(0), real(1), real(-1));
  if (!mesh_hinge(q, f1, e0, e1, n1, s1, f2, g0, g1, n2, s2, guard))
    return false;
  m1 = n1 * s1;
  m2 = n2 * s2;
  code = k + 3u * k2 + (s1 < real(0) ? 9u : 0u) + (s2 < real(0) ? 18u : 0u);
  real front1, back1, front2, back2;
  mesh_clearance(MESH_DATA, t, front1, back1);
  mesh_clearance(MESH_DATA, t2, front2, back2);
  clear = min(select(s1 > real(0), front1, back1), select(s2 > real(0), front2, back2));
  return true;
}

// ---- Corner entries: q nearest to a vertex v of the mesh --------------------------------------
// Whether q lies in the region of corner v of a triangle with the edge v -> w: (q - v).(w - v) <
// -guard |w - v| (compared squared: no root).
KFN bool corner_region(vec3 q, vec3 v, vec3 w, real guard) {
  precise vec3 e = w - v;
  precise real d = dot3(q - v, e);
  precise real g2 = guard * guard * dot3(e, e);
  return d < real(0) && d * d > g2;
}
// One step around vertex v: triangle `cur` (entered from `prev`), its corners next to v (w1, w2) and
// the triangle across its other edge at v (VKCLOTH_MESH_NONE at the mesh's border, or where cur has no
// corner at v). Edge j of a triangle lies opposite its corner j (ColliderMesh::neighbours).
KFN uint mesh_fan_next(MESH_DATA_PARAM, ColliderShape s, vec3 v, uint prev, uint cur, OUT(vec3) w1,
                       OUT(vec3) w2) {
  vec3 a, b, c, f;
  mesh_triangle(MESH_DATA, cur, a, b, c);
  const uint k = a == v ? 0u : (b == v ? 1u : (c == v ? 2u : 3u));
  corner_and_edge(k % 3u, a, b, c, f, w1, w2);
  const uint local = cur - s.mesh_tri0;
  uint n1 = mesh_neighbour(MESH_DATA, s.mesh_adj0, local, (k + 2u) % 3u); // across v -> w1
  uint n2 = mesh_neighbour(MESH_DATA, s.mesh_adj0, local, (k + 1u) % 3u); // across w2 -> v
  n1 = n1 >= 268435456u ? VKCLOTH_MESH_NONE : s.mesh_tri0 + n1;           // none (at most 2^28 triangles)
  n2 = n2 >= 268435456u ? VKCLOTH_MESH_NONE : s.mesh_tri0 + n2;
  return k == 3u ? VKCLOTH_MESH_NONE : (n1 != prev ? n1 : n2);
}
// A corner entry (corner k of triangle t, the mesh's vertex v): whether the fan of triangles around v
// closes (at most VKCLOTH_MESH_FAN) and q lies in v's region of each (corner_region): then each one is
// nearest to q at v, all at |q - v|, and the search takes the lowest index (`lowest`). With `shape`
// (the entry's making): also whether each triangle's plane has the whole fan behind it or on it
// (within guard: a convex vertex), where the cone behind all the planes is nearest at v too (q lies
// in its polar cone), and `clear`, the least clearance of the fan's triangles on q's side, which
// keeps every triangle reaching in front of a plane farther than v within the entry's ball.
#define VKCLOTH_MESH_FAN 16u
KFN bool mesh_corner(MESH_DATA_PARAM, ColliderShape s, uint t, uint k, vec3 q, real guard, bool shape,
                     OUT(uint) lowest, OUT(real) clear) {
  vec3 a, b, c, v, w1, w2;
  mesh_triangle(MESH_DATA, t, a, b, c);
  corner_and_edge(k, a, b, c, v, w1, w2);
  lowest = t;
  clear = real(1e15);
  uint prev = VKCLOTH_MESH_NONE, cur = t;
  bool inside = true;
  for (uint i = 0u; i < VKCLOTH_MESH_FAN && inside; ++i) {
    const uint next = mesh_fan_next(MESH_DATA, s, v, prev, cur, w1, w2);
    inside = next != VKCLOTH_MESH_NONE && corner_region(q, v, w1, guard) && corner_region(q, v, w2, guard);
    lowest = min(lowest, cur);
    if (shape && inside) { // cur's plane against every corner of the fan
      precise vec3 n = unit_or_zero(cross3(w1 - v, w2 - v));
      precise real ahead = real(0), behind = real(0);
      uint prev2 = VKCLOTH_MESH_NONE, cur2 = t;
      for (uint j = 0u; j < VKCLOTH_MESH_FAN && cur2 != VKCLOTH_MESH_NONE; ++j) {
        vec3 x1, x2;
        const uint next2 = mesh_fan_next(MESH_DATA, s, v, prev2, cur2, x1, x2);
        precise real h1 = dot3(n, x1 - v), h2 = dot3(n, x2 - v);
        ahead = max(ahead, max(h1, h2));
        behind = min(behind, min(h1, h2));
        prev2 = cur2;
        cur2 = next2 == t ? VKCLOTH_MESH_NONE : next2;
      }
      inside = ahead <= guard || behind >= -guard;
      real front, back;
      mesh_clearance(MESH_DATA, cur, front, back);
      clear = min(clear, ahead <= guard ? front : back);
    }
    prev = cur;
    cur = next;
    if (cur == t)
      return inside;
  }
  return false;
}
