// SPDX-License-Identifier: MIT
// vkcloth kernel: implicit Euler: a spring's block, the system's rows and the preconditioner
// (docs/model.md "Implicit Euler"); the block algebra is blocks.h.
// Part of the kernel that cloth_kernel.h gathers (the rules it states hold here: fixed order,
// `precise` results, real(...) literals). No include guard: the C++ bridge includes it once per precision.

// ---- Implicit Euler (docs/model.md "Implicit Euler") ------------------------------------------

KFN SpringBlock spring_block(vec3 u, real rest, real k) {
  SpringBlock s = zero_block();
  precise real len = sqrt(dot3(u, u));
  if (len > real(0)) {
    precise vec3 n = u / len;
    precise real r = rest / len;
    s = spring_block_n(n, r, k);
  }
  return s;
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
