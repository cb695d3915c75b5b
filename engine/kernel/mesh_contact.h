// SPDX-License-Identifier: MIT
// vkcloth kernel: a mesh collider's contact (docs/model.md "Mesh contact"): the per-particle search
// entries, the search of the triangles' hierarchy, and mesh_contact, which collider_contact calls.
// Part of the kernel that cloth_kernel.h gathers (the rules it states hold here: fixed order,
// `precise` results, real(...) literals); contacts.h includes it after to_body / to_world_dir. No
// include guard: the C++ bridge includes it once per precision.

// ---- Mesh colliders (docs/model.md "Mesh contact") ------------------------------------------
// A particle's contact with a mesh collider comes from the nearest triangle. A search of the
// triangles' hierarchy finds it; each particle keeps what its last search found (an entry per
// particle and mesh collider, on both backends), which answers the queries that follow while the
// particle stays within the entry's bounds: the same triangle as the search, by the same formula.

// A particle's entry for one mesh collider (body frame), read and written through the including
// file's mesh_cache_load / mesh_cache_store(MESH_DATA, slot, n, tri, centre, radius):
// - face (n != 0): triangle `tri` (unit normal n, turned towards q's side) holds the nearest point of
//   the mesh inside its face for every q in front of it whose projection lies inside the face
//   (inside_face) and with |q - centre| < radius (no other triangle comes as near);
// - edge (n.z = 2): the nearest point of the mesh lies in triangle `tri` or triangle n.x, which share
//   an edge (their corners opposite it and their planes' turns: n.y, mesh_edge_wedge's code), for
//   every q near that edge in its hinge (mesh_hinge) with |q - centre| < radius;
// - corner (n.z = 3): the nearest point of the mesh is corner k = n.x of triangle `tri`, a vertex whose
//   fan of triangles closes around it, convex, for every q in its region with |q - centre| < radius
//   (mesh_corner);
// - empty (n = 0): no triangle nearer to q than radius - |q - centre| (radius <= 0: nothing), the
//   nearest at `centre` being `tri`.
// The rounding of the distances in float at q's scale (guard) shrinks every bound.
// An edge or a corner entry's mark: n.z = 2 or 3 (a unit normal's z is at most 1).
KFN VARYING(bool) mesh_edge_or_corner_entry(vec3 n) {
  return n.z > real(1.5);
}
KFN precise real mesh_guard(vec3 q) {
  precise real g = real(0.000003814697265625) * (real(1) + max(max(abs(q.x), abs(q.y)), abs(q.z))); // 2^-18
  return g;
}

// Which side of the edge a -> b of a triangle (unit normal n, counter-clockwise) q's projection on
// its plane lies: |b - a| times its distance to the edge's line, positive inside, negative beyond.
KFN precise real edge_side(vec3 q, vec3 n, vec3 a, vec3 b) {
  precise real d = dot3(cross3(n, b - a), q - a);
  return d;
}
// The distance itself (edge_side / |b - a|).
KFN precise real edge_margin(vec3 q, vec3 n, vec3 a, vec3 b) {
  precise vec3 e = b - a;
  precise real m = edge_side(q, n, a, b) / sqrt(dot3(e, e));
  return m;
}
// Whether q's projection on the plane of triangle (a, b, c) (unit normal n, either side) lies inside
// it by more than guard from each edge's line: (n x e) . (q - a) > guard |e|, turned by the side n is
// on and compared squared (no root, no division).
KFN VARYING(bool) inside_edge(vec3 q, vec3 n, vec3 a, vec3 b, real turn, real guard) {
  precise vec3 e = b - a;
  precise real d = edge_side(q, n, a, b) * turn;
  precise real g2 = guard * guard * dot3(e, e);
  return d > real(0) && d * d > g2;
}
KFN VARYING(bool) inside_face(vec3 q, vec3 n, vec3 a, vec3 b, vec3 c, real guard) {
  precise real turn = select(dot3(n, cross3(b - a, c - a)) < real(0), real(-1), real(1));
  // Each test first, then their && (GLSL branches around a call on the right of &&).
  VARYING(bool) ab = inside_edge(q, n, a, b, turn, guard);
  VARYING(bool) bc = inside_edge(q, n, b, c, turn, guard);
  VARYING(bool) ca = inside_edge(q, n, c, a, turn, guard);
  return ab && bc && ca;
}

// The entry (n, centre, radius; a face's triangle a, b, c) answers a query at q (body frame) that
// reaches reach_total (the thickness + reach).
KFN VARYING(bool)
    mesh_cache_hit(vec3 n, vec3 centre, real radius, vec3 a, vec3 b, vec3 c, vec3 q, real reach_total) {
  precise vec3 d = q - centre;
  precise real d2 = dot3(d, d);
  VARYING(bool) face = dot3(n, n) > real(0);
  precise real r = select(face, radius, radius - reach_total);
  VARYING(bool) within = r > real(0) && d2 < r * r;
  precise real guard = mesh_guard(q);
  VARYING(bool) inside = inside_face(q, n, a, b, c, guard);
  VARYING(bool) on_face = dot3(q - a, n) > guard && inside;
  VARYING(bool) own_test = mesh_edge_or_corner_entry(n); // mesh_contact's own (scalar) test
  return within && (!face || on_face) && !own_test;
}

// collider_contact for a mesh from a face entry (the nearest point of the mesh to q lies inside the
// face of unit normal n through corner a) or an empty one (nothing within reach): the particle's
// height over the plane on the side p_side is on, less the thickness; the face's normal towards that
// side. Farther than the thickness + reach: distance = reach (no contact).
KFN void mesh_face_contact(ColliderShape s, vec3 n, vec3 a, vec3 q, vec3 p_side, real reach,
                           OUT(real) distance, OUT(vec3) normal) {
  precise real offset = dot3(a, n);
  precise real h = dot3(q, n) - offset;
  precise real h_side = dot3(to_body(s, p_side), n) - offset;
  precise real side = select(h_side < real(0), real(-1), real(1));
  precise real reach_total = s.b + reach;
  VARYING(bool) found = dot3(n, n) > real(0) && h * h < reach_total * reach_total;
  precise real d = h * side - s.b;
  distance = select(found, d, reach);
  normal = select(found, to_world_dir(s, n * side), vec3(real(0), real(0), real(1)));
}

// A skinned mesh's surface velocity at point p of triangle (a, b, c) whose corners move at va, vb, vc
// (barycentric interpolation, Ericson 3.4; a degenerate triangle: their mean), in the world.
KFN precise vec3 triangle_velocity(ColliderShape s, vec3 p, vec3 a, vec3 b, vec3 c, vec3 va, vec3 vb,
                                   vec3 vc) {
  precise vec3 e0 = b - a, e1 = c - a, e2 = p - a;
  precise real d00 = dot3(e0, e0), d01 = dot3(e0, e1), d11 = dot3(e1, e1);
  precise real d20 = dot3(e2, e0), d21 = dot3(e2, e1);
  precise real denom = d00 * d11 - d01 * d01;
  VARYING(bool) proper = denom > real(0);
  precise real safe = select(proper, denom, real(1));
  precise real v = select(proper, (d11 * d20 - d01 * d21) / safe, real(1) / real(3));
  precise real w = select(proper, (d00 * d21 - d01 * d20) / safe, real(1) / real(3));
  precise vec3 vel = va * (real(1) - v - w) + vb * v;
  vel = vel + vc * w;
  return to_world_dir(s, vel);
}

// The search of the hierarchy and the entry it leaves. A bridge that cannot run it (the CPU's SIMD
// lanes, which call the scalar mesh_contact lane by lane where their entries miss) defines
// VKCLOTH_KERNEL_NO_MESH.
#ifndef VKCLOTH_KERNEL_NO_MESH
#include "mesh_search.h"  // closest_on_triangle, mesh_nearest, mesh_triangle_answer
#include "mesh_entries.h" // mesh_clear_radius, mesh_edge_wedge, mesh_corner

// mesh_contact's passes, each called once. Pass 1's triangles: the entry's face (an edge entry's:
// its triangle on q's side of their edge; ba, bb, bc on entry: a face entry's corners) as base, and
// the triangle across the edge of it that q went farthest beyond as cand.
KFN void mesh_neighbourhood(MESH_DATA_PARAM, ColliderShape s, uint t, uint t2, uint code, bool edge, vec3 q,
                            OUT(uint) base, INOUT(vec3) ba, INOUT(vec3) bb, INOUT(vec3) bc, OUT(uint) cand) {
  base = t;
  if (edge) {
    vec3 x1, e0, e1;
    mesh_triangle(MESH_DATA, t, ba, bb, bc);
    corner_and_edge(code % 3u, ba, bb, bc, x1, e0, e1);
    if (edge_margin(q, unit_or_zero(cross3(e0 - x1, e1 - x1)), e0, e1) < real(0)) {
      base = t2;
      mesh_triangle(MESH_DATA, base, ba, bb, bc);
    }
  }
  precise vec3 tn = unit_or_zero(cross3(bb - ba, bc - ba));
  precise real m0 = edge_margin(q, tn, bb, bc), m1 = edge_margin(q, tn, bc, ba),
               m2 = edge_margin(q, tn, ba, bb);
  const uint e = m0 <= min(m1, m2) ? 0u : (m1 <= m2 ? 1u : 2u);
  const uint local = mesh_neighbour(MESH_DATA, s.mesh_adj0, base - s.mesh_tri0, e);
  cand = local >= 268435456u ? VKCLOTH_MESH_NONE : s.mesh_tri0 + local; // none (at most 2^28 triangles)
}

// Pass 2, the search: the nearest triangle base (ba, bb, bc) at squared distance gap (returned) and
// the edge's other one, cand (the search's second). The walk starts bounded by the entry's triangle t (radius
// > 0), which is at least as far as the nearest: it finds the same triangle as an unbounded walk (the same
// order; no box holding it is cut).
KFN real mesh_search(MESH_DATA_PARAM, ColliderShape s, uint t, real radius, vec3 q, real guard,
                     OUT(uint) base, OUT(vec3) ba, OUT(vec3) bb, OUT(vec3) bc, OUT(uint) cand) {
  precise real start = real(1e18);
  if (radius > real(0)) {
    vec3 a, b, c;
    mesh_triangle(MESH_DATA, t, a, b, c);
    start = sqrt(triangle_gap2(q, a, b, c)) * real(1.0009765625) + guard; // 1 + 2^-10: never below its own
  }
  precise real gap = mesh_nearest(MESH_DATA, s.mesh_root, s.mesh_tri0, q, start, VKCLOTH_MESH_NONE,
                                  VKCLOTH_MESH_NONE, vec3(real(0)), real(0), vec3(real(0)), real(0), real(-1),
                                  real(1.001953125), base, cand); // 1 + 2^-9: an edge's other triangle
  if (base == VKCLOTH_MESH_NONE) { // q 1e18 m or more away (or not finite): the first triangle, far
    base = s.mesh_tri0;
    mesh_triangle(MESH_DATA, base, ba, bb, bc);
    gap = triangle_gap2(q, ba, bb, bc);
    return gap;
  }
  mesh_triangle(MESH_DATA, base, ba, bb, bc);
  return gap;
}

// A face entry's test: q inside triangle f0's face, else f1's (VKCLOTH_MESH_NONE: none), and, without
// a search, in front by more than guard and within twice the reach: its corners a, b, c, the normal
// m turned to q's side, its clearance on that side and q's height d1 (after a search: kept).
KFN bool mesh_face(MESH_DATA_PARAM, bool searched, uint f0, uint f1, vec3 q, real guard, real reach_total,
                   OUT(uint) at, OUT(vec3) a, OUT(vec3) b, OUT(vec3) c, OUT(vec3) m, OUT(real) clear,
                   INOUT(real) d1) {
  bool is_face = false;
  for (uint i = 0u; i < 2u && !is_face; ++i) {
    const uint f = i == 0u ? f0 : f1;
    if (f == VKCLOTH_MESH_NONE)
      continue;
    mesh_triangle(MESH_DATA, f, a, b, c);
    precise vec3 tn = unit_or_zero(cross3(b - a, c - a));
    precise real h = dot3(q - a, tn);
    if (inside_face(q, tn, a, b, c, guard) &&
        (searched || (abs(h) > guard && abs(h) < real(2) * reach_total))) {
      is_face = true;
      at = f;
      m = tn * select(h < real(0), real(-1), real(1));
      real front, back;
      mesh_clearance(MESH_DATA, f, front, back);
      clear = select(h < real(0), back, front);
      d1 = select(searched, d1, abs(h));
    }
  }
  return is_face;
}

// The nearer of triangles base and cand by the search's measure (ties: the lower index): at, its
// corners a, b, c and its squared distance, returned.
KFN real mesh_nearer_of(MESH_DATA_PARAM, uint base, uint cand, vec3 q, OUT(uint) at, OUT(vec3) a, OUT(vec3) b,
                        OUT(vec3) c) {
  precise real gap = real(0);
  at = base;
  for (uint i = 0u; i < 2u; ++i) {
    const uint ti = i == 0u ? base : cand;
    vec3 ta, tb, tc;
    mesh_triangle(MESH_DATA, ti, ta, tb, tc);
    precise real gi = triangle_gap2(q, ta, tb, tc);
    if (i == 0u || nearer(gi, ti, gap, at)) {
      gap = gi;
      at = ti;
      a = ta;
      b = tb;
      c = tc;
    }
  }
  return gap;
}

// collider_contact for a mesh collider, q = p in its body frame (to_body). The particle's entry
// answers where it can. Where it no longer does, a face or an edge entry first moves to the
// triangles next to it without a search (the edge q went farthest beyond, as an edge and as a face,
// then its own face; an edge entry: the same from its triangle on q's side), where their clearance
// keeps a ball (a rigid mesh): the entry the search would certify there (the same triangles, the
// same formulas). Otherwise the search answers and leaves a new entry (slot:
// ColliderShape::mesh_cache; the bridge adds the particle): a corner, face or edge entry where the
// nearest point lies at a convex corner, inside a face or by an edge within twice the reach, else an
// empty one. Each formula has one call site (the GPU inlines them).
// A skinned mesh: `deform`, the surface's velocity at the nearest point from its corners' (zero otherwise).
KFN_NOINLINE void mesh_contact(MESH_DATA_PARAM, ColliderShape s, vec3 q, vec3 p_side, real reach,
                               OUT(real) distance, OUT(vec3) normal, OUT(vec3) deform) {
  distance = reach;
  normal = vec3(real(0), real(0), real(1));
  deform = vec3(real(0));
  if (!VKCLOTH_COLLIDER_PRESENT(VKCLOTH_COLLIDER_MESH))
    return;
  precise real reach_total = s.b + reach;
  vec3 n, centre, a, b, c;
  uint t;
  real radius;
  mesh_cache_load(MESH_DATA, s.mesh_cache, n, t, centre, radius);
  const bool corner = n.z > real(2.5);
  const bool edge = mesh_edge_or_corner_entry(n) && !corner;
  const bool face = !edge && !corner && dot3(n, n) > real(0);
  const uint t2 = edge ? uint(n.x) : VKCLOTH_MESH_NONE;
  a = b = c = vec3(real(0));
  if (face)
    mesh_triangle(MESH_DATA, t, a, b, c);
  // The answer: 1: the face formula (plane m through a of triangle at: a, b, c); 2: the general
  // formula (triangle at: a, b, c, at squared distance gap); 0: none yet.
  uint answer = // an edge or corner entry: its own test (pass 0); empty: m = 0, none
      !edge && !corner && mesh_cache_hit(n, centre, radius, a, b, c, q, reach_total) ? 1u : 0u;
  uint at = t;
  vec3 m = n;
  precise real gap = real(0);
  precise real guard = mesh_guard(q);
  // Pass 0: an edge or a corner entry's own test. 1: the entry's neighbourhood, without a search. 2:
  // the search. Each tries a corner (triangle base's corner k, its fan), a face (f0, else f1, q inside)
  // and an edge (triangles base and cand: its hinge), in that order; each formula has one call site.
  for (uint pass = edge || corner ? 0u : (face ? 1u : 2u); pass < 3u && answer == 0u; ++pass) {
    uint base = t, cand = VKCLOTH_MESH_NONE, f0 = VKCLOTH_MESH_NONE, f1 = VKCLOTH_MESH_NONE, k = 3u;
    precise real d1 = real(0);
    bool near = true;
    vec3 ba, bb, bc;
    if (pass == 0u) {
      precise vec3 d = q - centre;
      if (!(radius > real(0) && dot3(d, d) < radius * radius))
        continue;
      mesh_triangle(MESH_DATA, t, ba, bb, bc);
      cand = t2;
      k = corner ? uint(n.x) : 3u;
    } else if (pass == 1u) {
      ba = a;
      bb = b;
      bc = c;
      mesh_neighbourhood(MESH_DATA, s, t, t2, edge ? uint(n.y) : 0u, edge, q, base, ba, bb, bc, cand);
      f0 = cand;
      f1 = base;
    } else {
      gap = mesh_search(MESH_DATA, s, t, radius, q, guard, base, ba, bb, bc, cand);
      at = base;
      d1 = sqrt(gap);
      near = d1 < real(2) * reach_total;
      f0 = base;
      if (near) { // the nearest point at a corner of base: its fan
        precise vec3 cp = closest_on_triangle(q, ba, bb, bc);
        k = cp == ba ? 0u : (cp == bb ? 1u : (cp == bc ? 2u : 3u));
      }
    }
    precise vec3 m1 = vec3(real(0)), m2 = m1, e0 = m1; // set by the face or the edge that answers
    uint code = 0u;
    real clear = real(0);
    // A corner: its fan closes, convex, q in its region (the search's: also its clearance's ball).
    bool is_corner = false;
    if (k < 3u) {
      uint lowest;
      is_corner = mesh_corner(MESH_DATA, s, base, k, q, guard, pass == 2u, lowest, clear) &&
                  (pass == 0u || lowest == base);
      cand = is_corner ? lowest : cand;
    }
    // A face: q inside it (mesh_face).
    bool is_face = false;
    if (pass > 0u && near && !is_corner) {
      is_face = mesh_face(MESH_DATA, pass == 2u, f0, f1, q, guard, reach_total, at, a, b, c, m1, clear, d1);
      if (is_face) {
        m2 = m1;
        e0 = a;
      }
    }
    // An edge: its hinge (mesh_edge_wedge; an edge entry's own: the same edge, planes and code).
    bool is_edge = false;
    if (!is_corner && !is_face && near && cand != VKCLOTH_MESH_NONE)
      is_edge = mesh_edge_wedge(MESH_DATA, base, ba, bb, bc, cand, q, guard, m1, m2, e0, code, clear) &&
                (pass != 0u || code == uint(n.y));
    if (pass == 0u && !is_corner && !is_edge)
      continue;
    // A corner or an edge answers with the nearer of its two triangles (a corner: base = cand, its
    // fan's lowest) by the search's measure (ties: the lower index); the face formula where q lies
    // inside its face (the rule after the passes).
    if (is_corner || is_edge) {
      gap = mesh_nearer_of(MESH_DATA, base, cand, q, at, a, b, c);
      d1 = sqrt(gap);
      is_edge = is_edge && (pass != 1u || d1 < real(2) * reach_total);
    }
    if (pass == 0u) {
      answer = 2u;
    } else if (is_corner || is_edge || is_face) {
      // The ball: no triangle reaching in front of the plane(s) comes as near as the face, the edge or
      // the corner (their clearance; else, after a search, one 8 reaches beyond d1: each triangle
      // moves at most as far as q; one wholly behind is never nearer than the face or the edge while q
      // is in front of the face and inside it, or in the edge's hinge: mesh_hinge).
      precise real ball = mesh_clear_radius(clear, d1, guard);
      if (pass == 2u && !is_corner && ball < real(2) * reach_total) {
        uint unused, unused2;
        precise real next = mesh_nearest(MESH_DATA, s.mesh_root, s.mesh_tri0, q, d1 + real(8) * reach_total,
                                         base, is_edge ? cand : base, m1, dot3(m1, e0), m2, dot3(m2, e0),
                                         guard, real(1), unused, unused2);
        ball = max(ball, (sqrt(next) - d1) * real(0.5) - guard);
      }
      if (is_face && (ball > real(0) || pass == 2u)) {
        mesh_cache_store(MESH_DATA, s.mesh_cache, m1, at, q, ball);
        m = m1;
        answer = 1u;
      } else if ((is_edge || is_corner) && ball > real(0)) {
        const vec3 entry = is_edge ? vec3(real(cand), real(code), real(2)) : vec3(real(k), real(0), real(3));
        mesh_cache_store(MESH_DATA, s.mesh_cache, entry, base, q, ball);
        answer = 2u;
      }
    }
    if (pass == 2u &&
        answer == 0u) { // far, ...: an empty entry, no triangle nearer than d1 (base: the next walk's start)
      mesh_cache_store(MESH_DATA, s.mesh_cache, vec3(real(0)), base, q, d1 - guard);
      at = base;
      a = ba;
      b = bb;
      c = bc;
      answer = 2u;
    }
  }
  // The search's rule for every answer: a nearest point inside the face (near) takes the face formula.
  if (answer == 2u && sqrt(gap) < real(2) * reach_total) {
    precise vec3 tn = unit_or_zero(cross3(b - a, c - a));
    if (inside_face(q, tn, a, b, c, guard)) {
      m = tn * select(dot3(q - a, tn) < real(0), real(-1), real(1));
      answer = 1u;
    }
  }
  if (answer == 1u) {
    mesh_face_contact(s, m, a, q, p_side, reach, distance, normal);
    mesh_deformation(MESH_DATA, s, at, q - m * (dot3(q, m) - dot3(a, m)), a, b, c, deform);
  }
  if (answer == 2u)
    mesh_triangle_answer(MESH_DATA, s, at, a, b, c, gap, q, p_side, reach, distance, normal, deform);
}
#endif // VKCLOTH_KERNEL_NO_MESH
