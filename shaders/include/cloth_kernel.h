// SPDX-License-Identifier: MIT
// The per-particle physics of vkcloth, written ONCE for both backends: the compute shaders
// include this file as GLSL (through common.glsl) and the CPU reference solver compiles it as
// C++ (through engine/src/core/kernel.hpp, with GLM, for float and for double), as Jolt's
// HairIntegrate.h is shared by its HLSL and its C++ solver. The equations: docs/model.md.
//
// Rules that keep CPU and GPU bit-identical (on lavapipe; a real GPU may round sqrt/division
// differently):
// - Every expression is written out in one fixed order, and every result lands in a `precise`
//   variable, so the shader compiler may neither reassociate nor fuse it into an FMA (the C++
//   side builds with -ffp-contract=off; `precise` is empty there).
// - Literals are `real(...)`: a bare 2.0 would be a double in C++.
// - Pure functions of values: no buffer (a mesh collider's hierarchy is read through the including
//   file's accessors), no loop over particles or colliders. Each caller
//   gathers its inputs its own way (texel fetches, std::vector) and loops itself.
//
// Provided by the including file: real, vec3, uint, KFN (function prefix: `inline` in C++),
// OUT(T) / INOUT(T) (out / inout parameters: T& in C++), precise, sqrt, abs, min, max, and
// all_finite(vec3) (no component is NaN or inf); for mesh colliders MESH_DATA_PARAM / MESH_DATA
// (the mesh buffers: a dummy uint in GLSL, whose buffers are global), mesh_node and mesh_triangle;
// floor; for self_collide (only where SELF_DATA_PARAM is defined) SELF_DATA_PARAM / SELF_DATA,
// self_range, self_entry and self_particle;
// VKCLOTH_COLLIDER_PRESENT(type): false only when no collider of that type can reach the caller
// (C++: always true; GLSL: a specialisation constant, so that the absent shapes' code is compiled
// out, since llvmpipe runs every branch of a non-uniform `if`). It changes no result.
// Constants: vkcloth_shared.h.
// No include guard: kernel.hpp includes this file once per precision, in two namespaces.

// ---- Vector helpers ----------------------------------------------------------------------------

// a.x b.x + a.y b.y + a.z b.z, left to right.
KFN precise real dot3(vec3 a, vec3 b) {
  precise real r = a.x * b.x + a.y * b.y;
  r = r + a.z * b.z;
  return r;
}

// cross(x, y) in glm::cross's order.
KFN precise vec3 cross3(vec3 x, vec3 y) {
  precise real cx = x.y * y.z - y.y * x.z;
  precise real cy = x.z * y.x - y.z * x.x;
  precise real cz = x.x * y.y - y.x * x.y;
  return vec3(cx, cy, cz);
}

// ---- Normals (docs/model.md "Wind") ------------------------------------------------------------

// One triangle of a particle's fan: sum += cross(x_a - x, x_b - x), twice the triangle's area
// along its normal, so the fan's sum is an area-weighted vertex normal.
KFN void add_fan_triangle(INOUT(vec3) sum, vec3 ea, vec3 eb) {
  precise vec3 t = sum + cross3(ea, eb);
  sum = t;
}

// A gather-list entry's part in its particle's fan (Edge::ring, VKCLOTH_RING_*), u its edge: the
// list walks the fan's triangles as chains of neighbours, so the normal reuses the springs' edges.
// `prev` and `first` carry the previous entry's edge and the chain's first between calls.
KFN void add_ring_term(INOUT(vec3) sum, INOUT(vec3) prev, INOUT(vec3) first, vec3 u, uint ring) {
  if ((ring & VKCLOTH_RING_START) != 0u)
    first = u;
  if ((ring & VKCLOTH_RING_PREV) != 0u)
    add_fan_triangle(sum, prev, u);
  if ((ring & VKCLOTH_RING_CLOSE) != 0u)
    add_fan_triangle(sum, u, first);
  prev = u;
}

// The unit normal of a fan sum; zero for a degenerate fan (and for particles without a surface).
KFN precise vec3 unit_or_zero(vec3 sum) {
  precise real len = sqrt(dot3(sum, sum));
  precise vec3 n = len > real(0) ? sum / len : vec3(real(0));
  return n;
}

// ---- Forces (docs/model.md "Springs", "Forces", "Wind") -------------------------

// Eq. 2, one spring of a particle towards its neighbour, u = x_q - x the edge between them:
// f += K (|u| - L0) u / |u|. A zero-length spring has no direction and adds nothing.
KFN void add_spring_edge(INOUT(vec3) f, vec3 u, real rest, real k) {
  precise real len = sqrt(dot3(u, u));
  if (len > real(0)) {
    precise vec3 t = f + u * (k * (len - rest) / len);
    f = t;
  }
}

KFN void add_spring(INOUT(vec3) f, vec3 x, vec3 xq, real rest, real k) {
  precise vec3 u = xq - x;
  add_spring_edge(f, u, rest, k);
}

// The springs' sum plus gravity m g, fluid damping -mu m v and (when `wind`) wind Kw <n, u> n.
KFN precise vec3 add_body_forces(vec3 springs, real m, vec3 v, vec3 gravity, real mu, bool wind, vec3 nrm,
                                 vec3 wind_dir, real kw) {
  precise vec3 f = springs + gravity * m;
  precise real mu_m = mu * m;
  f = f - v * mu_m;
  if (wind) {
    precise real kn = kw * dot3(nrm, wind_dir);
    f = f + nrm * kn;
  }
  return f;
}

// ---- Contacts (docs/model.md "Collisions") ----------------------------------------------------

// A collider as the kernel takes it, in the solver's precision, at its pose for this substep
// (the host advances moving colliders: vkcloth::Collider::posed_at). GLSL: common.glsl
// collider_shape(); C++: kernel.hpp kernel_shape().
struct ColliderShape {
  uint type; // VKCLOTH_COLLIDER_*
  vec3 a;    // plane: unit normal; sphere, box, mesh: centre (mesh: its origin); capsule: end a
  real b;    // plane: offset; sphere, capsule: radius; mesh: thickness
  vec3 c;    // capsule: end b; box: half extents
  vec3 ax;   // box, mesh: the body's axes in the world (columns of its rotation)
  vec3 ay;
  vec3 az;
  uint mesh_root; // mesh: its root node and first triangle in the mesh buffers
  uint mesh_tri0;
  bool moving;   // the surface moves: velocity, spin and pivot apply
  vec3 velocity; // linear velocity
  vec3 spin;     // angular velocity about pivot
  vec3 pivot;
  real mu_k; // Coulomb friction: kinetic and static coefficients (0, 0: frictionless)
  real mu_s;
};

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
KFN bool mesh_closest(MESH_DATA_PARAM, uint root, uint tri0, vec3 q, real reach, OUT(vec3) closest,
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
    precise vec3 n = len > real(0) ? r / len : vec3(real(0), real(0), real(1)); // at the centre: push up
    precise real d = len - s.b;
    distance = d;
    normal = n;
    return;
  }
  if (VKCLOTH_COLLIDER_PRESENT(VKCLOTH_COLLIDER_CAPSULE) && s.type == VKCLOTH_COLLIDER_CAPSULE) {
    precise vec3 axis = s.c - s.a;
    precise real len2 = dot3(axis, axis);
    precise real t = len2 > real(0) ? dot3(p - s.a, axis) / len2 : real(0);
    t = min(max(t, real(0)), real(1));
    precise vec3 r = p - (s.a + axis * t);
    precise real len = sqrt(dot3(r, r));
    precise vec3 n = len > real(0) ? r / len : vec3(real(0), real(0), real(1));
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
    precise vec3 sgn = vec3(q.x < real(0) ? real(-1) : real(1), q.y < real(0) ? real(-1) : real(1),
                            q.z < real(0) ? real(-1) : real(1));
    if (out_len > real(0)) { // outside: towards the nearest face, edge or corner
      precise vec3 nb = (out_part * sgn) / out_len;
      distance = out_len;
      normal = to_world_dir(s, nb);
      return;
    }
    // Inside: out through the nearest face.
    vec3 nb = vec3(sgn.x, real(0), real(0));
    precise real d = over.x;
    if (over.y > d) {
      d = over.y;
      nb = vec3(real(0), sgn.y, real(0));
    }
    if (over.z > d) {
      d = over.z;
      nb = vec3(real(0), real(0), sgn.z);
    }
    distance = d;
    normal = to_world_dir(s, nb);
    return;
  }
  // VKCLOTH_COLLIDER_MESH
  vec3 cp, tn;
  distance = reach;
  normal = vec3(real(0), real(0), real(1));
  if (!VKCLOTH_COLLIDER_PRESENT(VKCLOTH_COLLIDER_MESH) ||
      !mesh_closest(MESH_DATA, s.mesh_root, s.mesh_tri0, q, s.b + reach, cp, tn))
    return;
  precise vec3 r = q - cp;
  precise real len = sqrt(dot3(r, r));
  precise real side = dot3(to_body(s, p_side) - cp, tn) < real(0) ? real(-1) : real(1);
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
  precise vec3 nb = len > real(0) ? r / len : side_n;
  precise real d = len - s.b;
  distance = d;
  normal = to_world_dir(s, nb);
}

// Removes the part of `w` along n that points into the collider (<w, n> < 0); with `both`
// (Figure 12's variant) the outward part as well.
KFN void remove_inward(INOUT(vec3) w, vec3 n, bool both) {
  precise real wn = dot3(w, n);
  if (wn < real(0) || (both && wn != real(0))) {
    precise vec3 t = w - n * wn;
    w = t;
  }
}

// Contact filter of one collider: within the band (distance < 2 eps) velocity and force lose
// their parts pointing into the collider, so a hand lifting the cloth keeps its outward pull.
KFN void contact_filter(INOUT(vec3) v, INOUT(vec3) f, vec3 n, real distance, real band, bool both) {
  if (!(distance < band))
    return;
  remove_inward(v, n, both);
  remove_inward(f, n, both);
}

// Coulomb friction on the relative velocity w and the force f once their inward normal parts are
// gone; j: the normal impulse per unit mass of this substep (the inward velocity removed plus
// h / m times the inward force removed). The tangential velocity the substep would end with,
// slip = w_t + (h / m) f_t, is cancelled when |slip| <= mu_s j (static: w_t and f_t go) and
// otherwise shortened by mu_k j (kinetic: w_t and f_t scaled by the same factor).
KFN void coulomb_friction(INOUT(vec3) w, INOUT(vec3) f, vec3 n, real j, real mu_k, real mu_s, real h_over_m) {
  precise vec3 wt = w - n * dot3(w, n);
  precise vec3 ft = f - n * dot3(f, n);
  precise vec3 slip = wt + ft * h_over_m;
  precise real slip_len = sqrt(dot3(slip, slip));
  precise real hold = mu_s * j;
  precise real k = slip_len > hold ? mu_k * j / slip_len : real(1);
  precise vec3 nw = w - wt * k;
  precise vec3 nf = f - ft * k;
  w = nw;
  f = nf;
}

// The contact response of one collider for particle x with velocity v and force f (mass m,
// substep h: h_over_m = h / m): the report's filter relative to the collider's surface velocity,
// then friction. A still, frictionless collider is exactly contact_filter (the report's model).
KFN void contact_response(INOUT(vec3) v, INOUT(vec3) f, ColliderShape s, vec3 x, vec3 n, real distance,
                          real band, bool both, real h_over_m) {
  if (!s.moving && s.mu_s == real(0) && s.mu_k == real(0)) {
    contact_filter(v, f, n, distance, band, both);
    return;
  }
  if (!(distance < band))
    return;
  precise vec3 vs = s.moving ? surface_velocity(s, x) : vec3(real(0));
  precise vec3 w = v - vs;
  precise real wn = dot3(w, n), fn = dot3(f, n);
  remove_inward(w, n, both);
  remove_inward(f, n, both);
  precise real j = max(-wn, real(0)) + max(-fn, real(0)) * h_over_m;
  coulomb_friction(w, f, n, j, s.mu_k, s.mu_s, h_over_m);
  precise vec3 nv = w + vs;
  v = nv;
}

// Eq. 5 / eq. 6: a point inside a collider goes back to its surface + eps, and loses its
// inward velocity (relative to the surface's). p_side: where the particle came from (a mesh's side).
// A mesh is searched as far as the particle moved, so that one that crossed it within the step
// is found even when it ended farther than the thickness beyond.
KFN void project_out(MESH_DATA_PARAM, ColliderShape s, real eps, vec3 p_side, INOUT(vec3) x, INOUT(vec3) v) {
  real distance;
  vec3 n;
  precise vec3 moved = x - p_side;
  precise real reach = s.type == VKCLOTH_COLLIDER_MESH ? sqrt(dot3(moved, moved)) : real(0);
  collider_contact(MESH_DATA, s, x, p_side, reach, distance, n);
  if (!(distance < real(0)))
    return;
  if (s.type == VKCLOTH_COLLIDER_PLANE) {
    precise real back = eps - distance;
    precise vec3 t = x + n * back;
    x = t;
  } else if (s.type == VKCLOTH_COLLIDER_SPHERE) {
    precise real r = s.b + eps;
    precise vec3 t = s.a + n * r;
    x = t;
  } else {
    precise real back = eps - distance;
    precise vec3 t = x + n * back;
    x = t;
  }
  if (!s.moving) {
    remove_inward(v, n, false);
    return;
  }
  precise vec3 vs = surface_velocity(s, x);
  precise vec3 w = v - vs;
  remove_inward(w, n, false);
  precise vec3 nv = w + vs;
  v = nv;
}

// ---- Stretch control (docs/model.md "Stretch control") ----------------------------------------

// The longest a link of rest length `rest` may be: (1 + max_strain) rest.
KFN precise real stretch_bound(real rest, real max_strain) {
  precise real s = real(1) + max_strain;
  precise real b = rest * s;
  return b;
}

// Moves x by dx and gives v the velocity of that move (v += dx / h), so that the step's velocity
// stays the position change over the step.
KFN void apply_correction(INOUT(vec3) x, INOUT(vec3) v, vec3 dx, real h) {
  precise vec3 nx = x + dx;
  precise vec3 nv = v + dx / h;
  x = nx;
  v = nv;
}

// Provot (1995): a link (xa, xb) longer than `bound` is shortened to `bound`; its free ends share
// the correction (half each, all of it when the other end is pinned). da, db: the moves of a, b.
// Most links are within the bound: they cost a dot product and a compare, no square root, and
// return false (nothing moves).
KFN bool provot_link(vec3 xa, vec3 xb, bool pinned_a, bool pinned_b, real bound, OUT(vec3) da, OUT(vec3) db) {
  da = vec3(real(0));
  db = vec3(real(0));
  precise vec3 u = xb - xa;
  precise real len2 = dot3(u, u);
  precise real bound2 = bound * bound;
  if (!(len2 > bound2) || (pinned_a && pinned_b))
    return false;
  precise real len = sqrt(len2);
  precise real share = pinned_a || pinned_b ? real(1) : real(0.5);
  precise vec3 c = u * (share * (len - bound) / len); // along a -> b
  if (!pinned_a)
    da = c;
  if (!pinned_b)
    db = -c;
  return true;
}

// A tether (Kim, Chentanez and Mueller 2012): x farther than `bound` from its (pinned) anchor goes
// back onto the sphere of radius `bound` around it: d is the move. False (d = 0) when x is within.
KFN bool tether_move(vec3 x, vec3 anchor, real bound, OUT(vec3) d) {
  d = vec3(real(0));
  precise vec3 u = x - anchor;
  precise real len2 = dot3(u, u);
  precise real bound2 = bound * bound;
  if (!(len2 > bound2))
    return false;
  precise real len = sqrt(len2);
  precise vec3 m = u * ((bound - len) / len);
  d = m;
  return true;
}

// ---- Fast projection (docs/model.md "Stretch control") -----------------------------------------
// Goldenthal, Harmon, Fattal, Bercovier and Grinspun, "Efficient Simulation of Inextensible
// Cloth" (SIGGRAPH 2007): each Newton iteration solves (grad C W grad C^T) lambda = C over the
// links in the solve (CG in each backend's loop, these functions per link and per particle) and
// moves x -= W grad C^T lambda. W: the inverse masses (0 for pinned particles).

// Link (xa, xb) with bound B = (1 + s) L0: C = |u|^2 / B^2 - 1 (u = xb - xa), > 0 over the bound; g
// = dC/dxb = 2 u / B^2 (dC/dxa = -g).
KFN precise real projection_constraint(vec3 xa, vec3 xb, real bound, OUT(vec3) g) {
  precise vec3 u = xb - xa;
  precise real inv_b2 = real(1) / (bound * bound);
  precise real c = dot3(u, u) * inv_b2 - real(1);
  precise vec3 grad = u * (real(2) * inv_b2);
  g = grad;
  return c;
}

// The C below which every link's strain is within VKCLOTH_PROJECTION_TOLERANCE of max_strain:
// ((1 + s + tol) / (1 + s))^2 - 1.
KFN precise real projection_c_tolerance(real max_strain) {
  precise real b = real(1) + max_strain;
  precise real t = (b + real(VKCLOTH_PROJECTION_TOLERANCE)) / b;
  precise real c = t * t - real(1);
  return c;
}

// A link's Jacobi preconditioner 1 / A_ll (A_ll = (wa + wb) |g|^2), or 0 when it is not in this
// Newton iteration's solve: it is when over the bound or within the band below it, or when it was
// in the last iteration's with a positive multiplier (`kept`: it holds its neighbours back), and
// not held at both ends.
KFN precise real projection_inv_diag(real c, bool kept, vec3 g, real wa, real wb) {
  precise real w = wa + wb;
  precise real diag = w * dot3(g, g);
  precise real inv = real(0);
  if ((c > -real(VKCLOTH_PROJECTION_BAND) || kept) && diag > real(0))
    inv = real(1) / diag;
  return inv;
}

// The solve's right-hand side for a link: max(C, 0): a link over the bound goes back to it, one in
// the band keeps its length (to first order); 0 outside the solve.
KFN precise real projection_rhs(real c, real inv_diag) {
  precise real r = inv_diag > real(0) && c > real(0) ? c : real(0);
  return r;
}

// A particle's share of grad C^T s for one of its links (value s: a CG direction or a multiplier):
// u += s g at the link's end b, u -= s g at its end a.
KFN void projection_gather(INOUT(vec3) u, vec3 g, real s, bool end_b) {
  precise vec3 t = g * s;
  precise vec3 r = end_b ? u + t : u - t;
  u = r;
}

// A link's row of grad C W grad C^T s, from its ends' gathers ua, ub of s: g . (wb ub - wa ua).
KFN precise real projection_row(vec3 g, real wa, vec3 ua, real wb, vec3 ub, real inv_diag) {
  precise vec3 t = ub * wb - ua * wa;
  precise real q = inv_diag > real(0) ? dot3(g, t) : real(0);
  return q;
}

// One CG update of a link: lambda += alpha d, r -= alpha q; returns z = r / A_ll.
KFN precise real projection_cg_update(INOUT(real) lambda, INOUT(real) r, real d, real q, real alpha,
                                      real inv_diag) {
  precise real l = lambda + alpha * d;
  precise real nr = r - alpha * q;
  lambda = l;
  r = nr;
  precise real z = nr * inv_diag;
  return z;
}

// A particle's move from the gather u of the multipliers: dx = -w u.
KFN precise vec3 projection_move(vec3 u, real w) {
  precise vec3 dx = u * (-w);
  return dx;
}

// ---- Self-collision (docs/model.md "Self-collision") ------------------------------------------

// One coordinate of the spatial hash's cell of x: floor(x / cell), inv_cell = 1 / cell. Beyond
// +-1e9 cells (a diverged state, NaN) it is cell 0, so that the conversion to int is defined on both
// sides; the divergence check reports such a state.
KFN int self_cell(real x, real inv_cell) {
  precise real c = floor(x * inv_cell);
  if (!(c >= real(-1.0e9) && c <= real(1.0e9)))
    c = real(0);
  return int(c);
}

// A cell's key: its coordinates modulo 1024, 10 bits each (the grid repeats every 1024 cells: two
// cells of one key are 1024 cells apart, so only one of the 27 around a particle has a given key).
KFN uint self_key_of(int i, int j, int k) {
  return (uint(i) & 1023u) | ((uint(j) & 1023u) << 10u) | ((uint(k) & 1023u) << 20u);
}
KFN uint self_key(vec3 x, real inv_cell) {
  return self_key_of(self_cell(x.x, inv_cell), self_cell(x.y, inv_cell), self_cell(x.z, inv_cell));
}
// The key of the cell (di, dj, dk) away from `key`'s.
KFN uint self_key_step(uint key, int di, int dj, int dk) {
  return self_key_of(int(key & 1023u) + di, int((key >> 10u) & 1023u) + dj, int(key >> 20u) + dk);
}
// The hash-table bucket of a key (Teschner et al. 2003's primes on its three coordinates), wrapped
// to the table: mask = its size - 1, a power of two.
KFN uint self_bucket(uint key, uint mask) {
  return ((key & 1023u) * 73856093u ^ ((key >> 10u) & 1023u) * 19349663u ^ (key >> 20u) * 83492791u) & mask;
}

// 1 / m, or 0 for a pinned particle (it takes no share of a correction).
KFN precise real inverse_mass(real m, bool pinned) {
  precise real w = pinned ? real(0) : real(1) / m;
  return w;
}

// Whether x and xq (rest positions rx, rxq) are a self-collision pair: closer than the thickness
// now (and not at one point, which has no direction) but not that close at rest (the rest-position
// filter of NvCloth: neighbours joined by short springs never collide).
KFN bool self_pair(vec3 x, vec3 xq, vec3 rx, vec3 rxq, real thickness2) {
  precise vec3 u = x - xq;
  precise real d2 = dot3(u, u);
  precise vec3 r = rx - rxq;
  precise real r2 = dot3(r, r);
  return d2 < thickness2 && d2 > real(0) && !(r2 < thickness2);
}

// Adds p's part of one pair's response to dx (a move) and dv (a velocity change), p's share of
// each being its inverse-mass share w / (w + wq) (Bridson, Fedkiw and Anderson 2002, section 7:
// a position correction plus a velocity filter). Along n = (x - xq) / |x - xq| the pair moves
// apart to the thickness (the move changes no velocity: no bounce), and the normal relative
// velocity, where it approaches, is removed (inelastic); across n Coulomb friction takes up to mu
// times that removed speed off the relative tangential velocity (all of it within: static). A layer
// resting on another is held by friction mu g per unit mass, since gravity's approach per substep
// is g h.
KFN void self_contact(INOUT(vec3) dx, INOUT(vec3) dv, vec3 x, vec3 v, real w, vec3 xq, vec3 vq, real wq,
                      real thickness, real mu) {
  precise vec3 u = x - xq;
  precise real d = sqrt(dot3(u, u));
  precise vec3 n = u / d;
  precise real share = w / (w + wq);
  precise real depth = thickness - d;
  precise vec3 rv = v - vq;
  precise real vn = dot3(rv, n);
  precise real approach = max(-vn, real(0));
  precise vec3 vt = rv - n * vn;
  precise real slip = sqrt(dot3(vt, vt));
  precise real cap = mu * approach;
  precise real kept = slip > cap ? cap / slip : real(1); // the part of the slip friction removes
  precise vec3 mx = dx + n * (depth * share);
  precise vec3 mv = dv + n * (approach * share);
  mv = mv - vt * (kept * share);
  dx = mx;
  dv = mv;
}

#ifdef SELF_DATA_PARAM // the includer provides the table (C++: kernel.hpp; GLSL: self_collision.comp)
// Particle p's response (Jacobi: the mean of its pairs' responses, so that a particle pressed from
// many sides does not overshoot): every particle q of the 27 cells around p's, cell by cell in a
// fixed order, each cell's particles in increasing index (a bucket holds the particles of every
// cell hashed to it, in increasing index: those of other cells are skipped by their key).
// Provided by the including file: self_range(SELF_DATA, bucket, first, stop) (the bucket's entries
// of the sorted table), self_entry(SELF_DATA, i, q, key) (an entry's particle and the key of the
// cell it was sorted in), self_particle(SELF_DATA, q, x, v, w, rest). Both backends build the
// same table, so they sum the same pairs in the same order.
KFN void self_collide(SELF_DATA_PARAM, uint p, vec3 x, vec3 v, real w, vec3 rx, real thickness, real inv_cell,
                      uint mask, real mu, OUT(vec3) dx, OUT(vec3) dv) {
  precise real t2 = thickness * thickness;
  const uint own = self_key(x, inv_cell);
  precise vec3 sum_x = vec3(real(0));
  precise vec3 sum_v = vec3(real(0));
  uint pairs = 0u;
  for (int dk = -1; dk <= 1; ++dk)
    for (int dj = -1; dj <= 1; ++dj)
      for (int di = -1; di <= 1; ++di) {
        const uint key = self_key_step(own, di, dj, dk);
        uint first;
        uint stop;
        self_range(SELF_DATA, self_bucket(key, mask), first, stop);
        for (uint i = first; i < stop; ++i) {
          uint q;
          uint qkey;
          self_entry(SELF_DATA, i, q, qkey);
          if (qkey != key || q == p)
            continue;
          vec3 xq;
          vec3 vq;
          vec3 rq;
          real wq;
          self_particle(SELF_DATA, q, xq, vq, wq, rq);
          if (self_pair(x, xq, rx, rq, t2)) {
            self_contact(sum_x, sum_v, x, v, w, xq, vq, wq, thickness, mu);
            pairs += 1u;
          }
        }
      }
  precise real k = pairs > 0u ? real(1) / real(pairs) : real(0);
  precise vec3 mx = sum_x * k;
  precise vec3 mv = sum_v * k;
  dx = mx;
  dv = mv;
}
#endif

// Applies a self-collision pass's response to a particle.
KFN void self_apply(INOUT(vec3) x, INOUT(vec3) v, vec3 dx, vec3 dv) {
  precise vec3 nx = x + dx;
  precise vec3 nv = v + dv;
  x = nx;
  v = nv;
}

// ---- Integrators (docs/model.md "Integrators") ------------------------------------------------

// Eq. 3 (explicit: x with the old v) or semi-implicit Euler (x with the new v); a = F / m.
KFN void euler_update(bool semi, INOUT(vec3) x, INOUT(vec3) v, vec3 f, real m, real dt) {
  precise vec3 a = f / m;
  if (semi) {
    precise vec3 nv = v + a * dt;
    precise vec3 nx = x + nv * dt;
    v = nv;
    x = nx;
  } else {
    precise vec3 nx = x + v * dt;
    precise vec3 nv = v + a * dt;
    x = nx;
    v = nv;
  }
}

// RK4 stage s (0..3) is evaluated at y_s = y0 + c_s k_{s-1}, c = (0, dt/2, dt/2, dt).
KFN precise real rk4_c(uint stage, real dt) {
  precise real c = stage == 0u ? real(0) : (stage < 3u ? dt / real(2) : dt);
  return c;
}
KFN precise vec3 rk4_stage_point(vec3 y0, vec3 k_prev, real c) {
  precise vec3 y = y0 + k_prev * c;
  return y;
}
// The stage's derivative (k_pos, k_vel) = (v, F / m) after contacts; zero for a pinned particle.
KFN void rk4_derivative(bool pinned, vec3 v, vec3 f, real m, OUT(vec3) k_pos, OUT(vec3) k_vel) {
  k_pos = vec3(real(0));
  k_vel = vec3(real(0));
  if (!pinned) { // a pinned particle may have no mass
    precise vec3 a = f / m;
    k_pos = v;
    k_vel = a;
  }
}
// Running sum k1 + 2 k2 + 2 k3 + k4, one stage at a time (same order as summing at the end).
KFN precise vec3 rk4_accumulate(uint stage, vec3 sum, vec3 k) {
  precise vec3 s = stage == 0u ? k : (stage < 3u ? sum + k * real(2) : sum + k);
  return s;
}
// y1 = y0 + (dt / 6) (k1 + 2 k2 + 2 k3 + k4).
KFN precise vec3 rk4_finish(vec3 y0, vec3 sum, real dt_over_6) {
  precise vec3 y = y0 + sum * dt_over_6;
  return y;
}

// ---- Implicit Euler (docs/model.md "Implicit Euler") ------------------------------------------

// A spring's 3x3 stiffness block, symmetric: diag = (xx, yy, zz), off = (xy, xz, yz).
struct SpringBlock {
  vec3 diag;
  vec3 off;
};

// The positive semi-definite part of a spring's Jacobian: k along the spring, and the transverse
// tension term k max(0, 1 - L0 / |u|) across it (the compressive part is dropped).
KFN SpringBlock spring_block(vec3 u, real rest, real k) {
  SpringBlock s;
  s.diag = vec3(real(0));
  s.off = vec3(real(0));
  precise real len = sqrt(dot3(u, u));
  if (len > real(0)) {
    precise vec3 n = u / len;
    precise real c = k * max(real(0), real(1) - rest / len);
    precise real al = k - c;
    precise real xx = al * n.x * n.x + c, yy = al * n.y * n.y + c, zz = al * n.z * n.z + c;
    precise real xy = al * n.x * n.y, xz = al * n.x * n.z, yz = al * n.y * n.z;
    s.diag = vec3(xx, yy, zz);
    s.off = vec3(xy, xz, yz);
  }
  return s;
}

// K w for a symmetric block.
KFN precise vec3 apply_block(SpringBlock s, vec3 w) {
  precise real x = s.diag.x * w.x + s.off.x * w.y;
  x = x + s.off.y * w.z;
  precise real y = s.off.x * w.x + s.diag.y * w.y;
  y = y + s.off.z * w.z;
  precise real z = s.off.y * w.x + s.off.z * w.y;
  z = z + s.diag.z * w.z;
  return vec3(x, y, z);
}

// The implicit system A = (1 + h mu) M + h^2 K (K: the springs' blocks), row by row.
// Jacobi diagonal: (1 + h mu) m + h^2 times the sum of the blocks' diagonals.
KFN precise vec3 implicit_diagonal(real mu_h, real m, vec3 block_diagonals, real h2) {
  precise real mm = mu_h * m;
  precise vec3 d = vec3(mm) + block_diagonals * h2;
  return d;
}
// (A w)_p: the mass term plus h^2 times sum_q K_pq (w_p - w_q).
KFN precise vec3 implicit_row(vec3 w, real mu_h, real m, vec3 springs, real h2) {
  precise real mm = mu_h * m;
  precise vec3 q = w * mm + springs * h2;
  return q;
}
// Right-hand side h (f - h K v) (K v: the springs' sum of K_pq (v_p - v_q)).
KFN precise vec3 implicit_rhs(vec3 f, vec3 kv, real h) {
  precise vec3 r = (f - kv * h) * h;
  return r;
}

// Block-Jacobi preconditioner (docs/model.md "Implicit Euler"): P_p = A_pp, the particle's full
// 3x3 diagonal block (1 + h mu) m I + h^2 sum_q K_pq, inverted once per step.
KFN void add_block(INOUT(SpringBlock) sum, SpringBlock k) {
  precise vec3 d = sum.diag + k.diag;
  precise vec3 o = sum.off + k.off;
  sum.diag = d;
  sum.off = o;
}
KFN SpringBlock implicit_diagonal_block(real mu_h, real m, SpringBlock ksum, real h2) {
  SpringBlock a;
  a.diag = implicit_diagonal(mu_h, m, ksum.diag, h2);
  precise vec3 o = ksum.off * h2;
  a.off = o;
  return a;
}
// The inverse of a symmetric positive definite block: adjugate over determinant (A_pp is SPD:
// (1 + h mu) m > 0 plus a positive semi-definite sum, so det > 0).
KFN SpringBlock invert_block(SpringBlock a) {
  const real xx = a.diag.x, yy = a.diag.y, zz = a.diag.z;
  const real xy = a.off.x, xz = a.off.y, yz = a.off.z;
  precise real c_xx = yy * zz - yz * yz, c_yy = xx * zz - xz * xz, c_zz = xx * yy - xy * xy;
  precise real c_xy = xz * yz - xy * zz, c_xz = xy * yz - xz * yy, c_yz = xy * xz - xx * yz;
  precise real det = xx * c_xx + xy * c_xy;
  det = det + xz * c_xz;
  precise real inv = real(1) / det;
  SpringBlock r;
  precise vec3 d = vec3(c_xx, c_yy, c_zz) * inv;
  precise vec3 o = vec3(c_xy, c_xz, c_yz) * inv;
  r.diag = d;
  r.off = o;
  return r;
}
// |h m g|^2: a particle's share of the weight impulse, the scale CG's tolerance is relative to
// when it exceeds |S b| (near equilibrium b tends to zero: implicit_euler.hpp).
KFN precise real weight_impulse2(real h, real m, vec3 g) {
  precise real hm = h * m;
  precise real w = hm * hm * dot3(g, g);
  return w;
}
// The warm start's residual b - S A x0 (x0: the previous solve's dv).
KFN precise vec3 residual_of(vec3 b, vec3 ax) {
  precise vec3 r = b - ax;
  return r;
}

// ---- Divergence (docs/model.md "Divergence") -------------------------------------------

// A particle has diverged when a component of x or v is NaN or inf, or |x_i| > limit.
KFN bool diverged(vec3 x, vec3 v, real limit) {
  return !all_finite(x) || !all_finite(v) || abs(x.x) > limit || abs(x.y) > limit || abs(x.z) > limit;
}
