// SPDX-License-Identifier: MIT
// vkcloth kernel: the contact response: the inward part removed (Figure 12), Coulomb friction and the
// projection out of a collider (docs/model.md "Collisions", "Friction").
// Part of the kernel that cloth_kernel.h gathers (the rules it states hold here: fixed order,
// `precise` results, real(...) literals). No include guard: the C++ bridge includes it once per precision.

// Removes the part of `w` along n that points into the collider (<w, n> < 0); with `both`
// (Figure 12's variant) the outward part as well.
KFN void remove_inward(INOUT(vec3) w, vec3 n, bool both) {
  precise real wn = dot3(w, n);
  VARYING(bool) remove = wn < real(0) || (both && wn != real(0));
  if (!maybe_any_particle(remove))
    return;
  precise vec3 t = w - n * wn;
  w = select(remove, t, w);
}

// Contact filter of one collider: within the band (distance < 2 eps) velocity and force lose
// their parts pointing into the collider, so a hand lifting the cloth keeps its outward pull.
KFN void contact_filter(INOUT(vec3) v, INOUT(vec3) f, vec3 n, real distance, real band, bool both) {
  VARYING(bool) in_band = distance < band;
  if (!any_particle(in_band))
    return;
  vec3 nv = v, nf = f;
  remove_inward(nv, n, both);
  remove_inward(nf, n, both);
  v = select(in_band, nv, v);
  f = select(in_band, nf, f);
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
  precise real k = select(slip_len > hold, mu_k * j / slip_len, real(1));
  precise vec3 nw = w - wt * k;
  precise vec3 nf = f - ft * k;
  w = nw;
  f = nf;
}

// The surface's velocity at x: the collider's rigid motion, plus a skinned mesh's `deform` there
// (collider_contact's).
KFN precise vec3 contact_surface_velocity(ColliderShape s, vec3 x, vec3 deform) {
  precise vec3 vs = s.moving ? surface_velocity(s, x) : vec3(real(0));
  if (deforming(s))
    vs = vs + deform;
  return vs;
}

// The contact response of one collider for particle x with velocity v and force f (mass m,
// substep h: h_over_m = h / m): the report's filter relative to the collider's surface velocity
// (`deform`: collider_contact's), then friction. A still, frictionless collider is exactly
// contact_filter (the report's model).
KFN void contact_response(INOUT(vec3) v, INOUT(vec3) f, ColliderShape s, vec3 x, vec3 n, real distance,
                          real band, bool both, real h_over_m, vec3 deform) {
  if (still_frictionless(s)) {
    contact_filter(v, f, n, distance, band, both);
    return;
  }
  VARYING(bool) in_band = distance < band;
  if (!any_particle(in_band))
    return;
  precise vec3 vs = contact_surface_velocity(s, x, deform);
  precise vec3 w = v - vs;
  vec3 g = f;
  precise real wn = dot3(w, n), fn = dot3(g, n);
  remove_inward(w, n, both);
  remove_inward(g, n, both);
  precise real j = max(-wn, real(0)) + max(-fn, real(0)) * h_over_m;
  coulomb_friction(w, g, n, j, s.mu_k, s.mu_s, h_over_m);
  precise vec3 nv = w + vs;
  v = select(in_band, nv, v);
  f = select(in_band, g, f);
}

// project_out once the collider's distance and normal at x are known: nothing unless distance < 0.
KFN void project_back(ColliderShape s, real eps, real distance, vec3 n, vec3 deform, INOUT(vec3) x,
                      INOUT(vec3) v) {
  VARYING(bool) inside = distance < real(0);
  if (!any_particle(inside))
    return;
  precise vec3 nx;
  if (s.type == VKCLOTH_COLLIDER_SPHERE) {
    precise real r = s.b + eps;
    nx = s.a + n * r;
  } else {
    precise real back = eps - distance;
    nx = x + n * back;
  }
  precise vec3 nv = v;
  if (!s.moving) {
    remove_inward(nv, n, false);
  } else {
    precise vec3 vs = contact_surface_velocity(s, nx, deform);
    precise vec3 w = v - vs;
    remove_inward(w, n, false);
    nv = w + vs;
  }
  x = select(inside, nx, x);
  v = select(inside, nv, v);
}

// Eq. 5 / eq. 6: a point inside a collider goes back to its surface + eps, and loses its
// inward velocity (relative to the surface's). p_side: where the particle came from (a mesh's side).
// A mesh is searched as far as the particle moved, so that one that crossed it within the step
// is found even when it ended farther than the thickness beyond.
KFN void project_out(MESH_DATA_PARAM, ColliderShape s, real eps, vec3 p_side, INOUT(vec3) x, INOUT(vec3) v) {
  real distance;
  vec3 n, deform;
  precise vec3 moved = x - p_side;
  precise real reach = s.type == VKCLOTH_COLLIDER_MESH ? sqrt(dot3(moved, moved)) : real(0);
  collider_contact(MESH_DATA, s, x, p_side, reach, distance, n, deform);
  project_back(s, eps, distance, n, deform, x, v);
}
