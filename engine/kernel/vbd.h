// SPDX-License-Identifier: MIT
// vkcloth kernel: implicit Euler by vertex block descent (Chen, Liu, Yang, Yuksel, SIGGRAPH 2024):
// the inertia target, the first guess, one vertex's Newton step, and the velocity, position and
// net force a substep leaves (docs/model.md "Vertex block descent").
// Part of the kernel that cloth_kernel.h gathers (the rules it states hold here: fixed order,
// `precise` results, real(...) literals). No include guard: the C++ bridge includes it once per precision.

// ---- Vertex block descent (docs/model.md "Vertex block descent") --------------------------------

// The inertia target y = x0 + h v0 + (h^2 / m) f_ext: where the particle would go with its velocity
// and the forces that do not depend on the solve (gravity and wind at the step's start).
KFN precise vec3 vbd_inertia_target(vec3 x0, vec3 v0, vec3 f_ext, real m, real h) {
  precise real h2_m = h * h / m;
  precise vec3 y = x0 + v0 * h;
  y = y + f_ext * h2_m;
  return y;
}

// One spring's part in a vertex's step, u = x_q - x: its force, eq. 2 as K (|u| - L0) n with the
// unit direction n (add_spring_edge keeps the explicit step's rounding, u K (|u| - L0) / |u|), and
// its stiffness block (spring_block_n: the positive semi-definite part of the Hessian), from one
// length and one reciprocal. A zero-length spring adds nothing. len: |u|, as the caller computed it
// (vbd_add_spring computes it; self_energy shares it with its friction).
KFN void vbd_add_spring_len(INOUT(vec3) f, INOUT(SpringBlock) hessian, vec3 u, real len, real rest, real k) {
  VARYING(bool) has_length = len > real(0);
  if (!maybe_any_particle(has_length))
    return;
  precise real inv = real(1) / len;
  precise vec3 n = u * inv;
  precise real r = rest * inv;
  precise vec3 t = f + n * (k * (len - rest));
  SpringBlock b = spring_block_n(n, r, k);
  precise vec3 d = hessian.diag + b.diag;
  precise vec3 o = hessian.off + b.off;
  f = select(has_length, t, f);
  hessian.diag = select(has_length, d, hessian.diag);
  hessian.off = select(has_length, o, hessian.off);
}

// The same, |u| computed here.
KFN void vbd_add_spring(INOUT(vec3) f, INOUT(SpringBlock) hessian, vec3 u, real rest, real k) {
  precise real len = sqrt(dot3(u, u));
  vbd_add_spring_len(f, hessian, u, len, rest, k);
}

// Self-contact's part in a vertex's step (self_energy_listed's force fc and stiffness hc, from the
// sweep's start), added after its springs'.
KFN void vbd_add_contact(INOUT(vec3) f, INOUT(SpringBlock) hessian, vec3 fc, SpringBlock hc) {
  precise vec3 t = f + fc;
  precise vec3 d = hessian.diag + hc.diag;
  precise vec3 o = hessian.off + hc.off;
  f = t;
  hessian.diag = d;
  hessian.off = o;
}

// The inertia's (and damping's) stiffness in a vertex's Hessian, (1 + h mu) m / h^2 as vbd_step adds it.
KFN precise real vbd_inertia_weight(real m, real h, real mu) {
  precise real m_h2 = m / (h * h);
  precise real mu_m_h = mu * m / h;
  return m_h2 + mu_m_h;
}

// Coulomb friction of one collider in a vertex's step (docs/model.md "Vertex block descent"): Coulomb's
// law on the step's quadratic model, applied to the stepped position before the projection. Within
// the contact band (at x, where the sweep found the particle; its normal n), the step's move over
// the substep u = stepped - x0 (relative to the surface) has an inward part, which the contact stops:
// its normal force is lambda = n^T H n max(-u.n, 0) (H: the springs' block plus the inertia weight).
// Undoing the tangential part u_t takes the force F_t = (H u_t)_t: it is undone when |F_t| <= mu_s
// lambda (static), and otherwise shortened by mu_k lambda / |F_t| (kinetic), as coulomb_friction
// shortens a velocity.
KFN void vbd_friction(INOUT(vec3) stepped, MESH_DATA_PARAM, ColliderShape s, vec3 x, vec3 x0,
                      SpringBlock hessian, real inertia, real band, real h) {
  if (!has_friction(s))
    return;
  real distance;
  vec3 n, deform;
  collider_contact(MESH_DATA, s, x, x, band, distance, n, deform);
  precise vec3 vs = contact_surface_velocity(s, x, deform);
  precise vec3 u = (stepped - x0) - vs * h;
  precise real un = dot3(u, n);
  VARYING(bool) touching = distance < band && un < real(0);
  if (!any_particle(touching))
    return;
  precise real lambda = (dot3(n, apply_block(hessian, n)) + inertia) * -un;
  precise vec3 ut = u - n * un;
  precise vec3 hold = apply_block(hessian, ut) + ut * inertia;
  precise vec3 ft = hold - n * dot3(hold, n);
  precise real ft_len = sqrt(dot3(ft, ft));
  precise real k =
      select(ft_len > real(s.mu_s) * lambda, min(real(s.mu_k) * lambda / ft_len, real(1)), real(1));
  precise vec3 nx = stepped - ut * k;
  stepped = select(touching, nx, stepped);
}

// One vertex's Newton step on its part of implicit Euler's variational energy
//   G(x) = m / (2 h^2) |x - y|^2 + mu m / (2 h) |x - x0|^2 + sum of its springs' energies
// (the second term is the fluid damping -mu m v with v = (x - x0) / h): the gradient
// g = m / h^2 (x - y) + (mu m / h) (x - x0) - f (f: the springs' force at x) and the Hessian
// H = (1 + h mu) m / h^2 I + sum K_s, positive definite (K_s positive semi-definite); x - H^-1 g.
KFN precise vec3 vbd_step(vec3 x, vec3 y, vec3 x0, vec3 f, SpringBlock hessian, real m, real h, real mu) {
  precise real m_h2 = m / (h * h);
  precise real mu_m_h = mu * m / h;
  precise vec3 g = (x - y) * m_h2 + (x - x0) * mu_m_h;
  g = g - f;
  SpringBlock a;
  precise vec3 d = hessian.diag + vec3(vbd_inertia_weight(m, h, mu));
  a.diag = d;
  a.off = hessian.off;
  precise vec3 nx = x - apply_block(invert_block(a), g);
  return nx;
}

// After the iterations the particle stays where the last sweep left it, x, and takes the velocity
// the step implies, v = (x - x0) / h, from x before the colliders' projection (x - push): the
// projection's move is not a velocity (it would throw the particle off the collider); the contact
// response then removes v's inward part (without friction, which acted inside the sweeps).
KFN precise vec3 vbd_velocity(vec3 x, vec3 push, vec3 x0, real h) {
  precise vec3 free_x = x - push;
  precise vec3 v = (free_x - x0) / h;
  return v;
}

// The net force of the step, m (v - v0) / h (what a host observes as the particle's force).
KFN precise vec3 vbd_net_force(vec3 v, vec3 v0, real m, real h) {
  precise vec3 f = (v - v0) * (m / h);
  return f;
}

// The first guess, x0 + h v0: the particle carried by its velocity (the paper's "inertia" start,
// section 3.7), without the step's acceleration. Few sweeps stay near the guess; one that adds
// gravity (the inertia target y, or the paper's adaptive h^2 a~ along it) lets a hanging cloth fall
// a little further each step and bounce ever harder (docs/model.md "Vertex block descent").
KFN precise vec3 vbd_first_guess(vec3 x0, vec3 v0, real h) {
  precise vec3 x = x0 + v0 * h;
  return x;
}
