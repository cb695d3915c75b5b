// SPDX-License-Identifier: MIT
// vkcloth kernel: normals, springs and body forces (docs/model.md "Springs", "Forces", "Wind").
// Part of the kernel that cloth_kernel.h gathers (the rules it states hold here: fixed order,
// `precise` results, real(...) literals). No include guard: the C++ bridge includes it once per precision.

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
KFN void add_ring_term(INOUT(vec3) sum, INOUT(vec3) prev, INOUT(vec3) first, vec3 u, VARYING(uint) ring) {
  first = select((ring & VKCLOTH_RING_START) != 0u, u, first);
  VARYING(bool) with_prev = (ring & VKCLOTH_RING_PREV) != 0u;
  if (maybe_any_particle(with_prev)) {
    vec3 t = sum;
    add_fan_triangle(t, prev, u);
    sum = select(with_prev, t, sum);
  }
  VARYING(bool) close = (ring & VKCLOTH_RING_CLOSE) != 0u;
  if (maybe_any_particle(close)) {
    vec3 t = sum;
    add_fan_triangle(t, u, first);
    sum = select(close, t, sum);
  }
  prev = u;
}

// The unit normal of a fan sum; zero for a degenerate fan (and for particles without a surface).
KFN precise vec3 unit_or_zero(vec3 sum) {
  precise real len = sqrt(dot3(sum, sum));
  precise vec3 n = select(len > real(0), sum / len, vec3(real(0)));
  return n;
}

// ---- Forces (docs/model.md "Springs", "Forces", "Wind") -------------------------

// Eq. 2, one spring of a particle towards its neighbour, u = x_q - x the edge between them:
// f += K (|u| - L0) u / |u|. A zero-length spring has no direction and adds nothing.
KFN void add_spring_edge(INOUT(vec3) f, vec3 u, real rest, real k) {
  precise real len = sqrt(dot3(u, u));
  VARYING(bool) has_length = len > real(0);
  if (!maybe_any_particle(has_length))
    return;
  precise vec3 t = f + u * (k * (len - rest) / len);
  f = select(has_length, t, f);
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
