// SPDX-License-Identifier: MIT
// vkcloth kernel: implicit Euler: the spring blocks, the system's rows and the preconditioner
// (docs/model.md "Implicit Euler").
// Part of the kernel that cloth_kernel.h gathers (the rules it states hold here: fixed order,
// `precise` results, real(...) literals). No include guard: the C++ bridge includes it once per precision.

// ---- Implicit Euler (docs/model.md "Implicit Euler") ------------------------------------------

// A spring's 3x3 stiffness block, symmetric: diag = (xx, yy, zz), off = (xy, xz, yz).
struct SpringBlock {
  vec3 diag;
  vec3 off;
};

// The positive semi-definite part of a spring's Jacobian: k along the spring, and the transverse
// tension term k max(0, 1 - L0 / |u|) across it (the compressive part is dropped); n = u / |u|, the
// unit direction, and r = L0 / |u|, as the caller computes them (spring_block: by division;
// vbd_add_spring: from one reciprocal it shares with the force).
KFN SpringBlock spring_block_n(vec3 n, real r, real k) {
  SpringBlock s;
  precise real c = k * max(real(0), real(1) - r);
  precise real al = k - c;
  precise real xx = al * n.x * n.x + c, yy = al * n.y * n.y + c, zz = al * n.z * n.z + c;
  precise real xy = al * n.x * n.y, xz = al * n.x * n.z, yz = al * n.y * n.z;
  s.diag = vec3(xx, yy, zz);
  s.off = vec3(xy, xz, yz);
  return s;
}
KFN SpringBlock spring_block(vec3 u, real rest, real k) {
  SpringBlock s;
  s.diag = vec3(real(0));
  s.off = vec3(real(0));
  precise real len = sqrt(dot3(u, u));
  if (len > real(0)) {
    precise vec3 n = u / len;
    precise real r = rest / len;
    s = spring_block_n(n, r, k);
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
// Baraff-Witkin's filter for a particle in contact (docs/model.md "Implicit Euler"): the solve may
// not move it along the contact's normal, the axis of what the contact filter took from its v and
// F before the solve (`removed` = (v - v_filtered) + (h / m) (F - F_filtered), zero when the
// particle does not press on a collider). Without it the solve pulled a contact particle into the
// collider, its neighbours followed, and the projection afterwards flung them.
KFN precise vec3 contact_axis(vec3 removed_v, vec3 removed_f, real h_over_m) {
  precise vec3 r = removed_v + removed_f * h_over_m;
  return unit_or_zero(r);
}
// w without its part along the unit axis a (a = 0: w unchanged).
KFN precise vec3 constrain_to(vec3 w, vec3 a) {
  precise vec3 c = w - a * dot3(a, w);
  return c;
}
