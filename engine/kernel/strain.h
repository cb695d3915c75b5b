// SPDX-License-Identifier: MIT
// vkcloth kernel: stretch control: Provot links, tethers and the fast projection (docs/model.md
// "Stretch control").
// Part of the kernel that cloth_kernel.h gathers (the rules it states hold here: fixed order,
// `precise` results, real(...) literals). No include guard: the C++ bridge includes it once per precision.

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
