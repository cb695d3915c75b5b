// SPDX-License-Identifier: MIT
// vkcloth kernel: self-collision: the hash of cells and the pair repulsion (docs/model.md "Self-collision").
// Part of the kernel that cloth_kernel.h gathers (the rules it states hold here: fixed order,
// `precise` results, real(...) literals). No include guard: the C++ bridge includes it once per precision.

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

// Whether xq (rest rxq) may become p's pair before the neighbour list is built again: closer than
// `reach` (the thickness plus the skin) now and not closer than the thickness at rest (those never
// pair). Unlike self_pair, it keeps a particle at p's own point: it has no direction now, but may
// have one by the time the pair is tested.
KFN bool self_candidate(vec3 x, vec3 xq, vec3 rx, vec3 rxq, real reach2, real thickness2) {
  precise vec3 u = x - xq;
  precise real d2 = dot3(u, u);
  precise vec3 r = rx - rxq;
  precise real r2 = dot3(r, r);
  return d2 < reach2 && !(r2 < thickness2);
}

// Whether x has moved more than half the skin (half_skin2: its square) from xb, where the neighbour
// list was built (NaN: never built). While no particle has, a pair closer than the thickness was
// closer than the thickness plus the skin at the build, so it is in the list.
KFN bool self_moved(vec3 x, vec3 xb, real half_skin2) {
  precise vec3 u = x - xb;
  precise real d2 = dot3(u, u);
  return !(d2 <= half_skin2);
}

// One pair's contact energy in p's vertex step (vbd with a self-contact stiffness; docs/model.md
// "Self-collision"): (k / 2) (t - d)^2 for d = |x - xq| < t, a spring of rest length t and stiffness
// k that only pushes: its force k (t - d) away from xq and its stiffness block k n n^T (vbd_add_spring
// of a compressed spring keeps only the part along it). With friction mu > 0, Coulomb's law on the
// pair's slip over the step so far, s = the part of u - uq across n (u, uq: each particle's move
// from the step's start), with the normal force lambda = k (t - d): the force -c s and the stiffness
// c (I - n n^T), c = mu lambda / max(|s|, slip): a spring that holds a slip below `slip` (static)
// and a force mu lambda against a longer one (kinetic); IPC's lagged friction, as vbd's Gaia.
KFN void self_energy(INOUT(vec3) f, INOUT(SpringBlock) hessian, vec3 x, vec3 u, vec3 xq, vec3 uq,
                     real thickness, real k, real mu, real slip) {
  precise vec3 u_q = xq - x;
  precise real d = sqrt(dot3(u_q, u_q)); // > 0: self_pair
  vbd_add_spring_len(f, hessian, u_q, d, thickness, k);
  if (!(mu > real(0)))
    return;
  precise vec3 e = x - xq;
  precise vec3 n = e / d;
  precise real lambda = k * (thickness - d);
  precise vec3 r = u - uq;
  precise vec3 s = r - n * dot3(n, r);
  precise real c = mu * lambda / max(sqrt(dot3(s, s)), slip);
  precise vec3 t = f - s * c;
  SpringBlock b = tangent_block(n, c);
  precise vec3 bd = hessian.diag + b.diag;
  precise vec3 bo = hessian.off + b.off;
  f = t;
  hessian.diag = bd;
  hessian.off = bo;
}

// The mean of a particle's pair responses (Jacobi: a particle pressed from many sides does not overshoot).
KFN void self_mean(vec3 sum_x, vec3 sum_v, uint pairs, OUT(vec3) dx, OUT(vec3) dv) {
  precise real k = pairs > 0u ? real(1) / real(pairs) : real(0);
  precise vec3 mx = sum_x * k;
  precise vec3 mv = sum_v * k;
  dx = mx;
  dv = mv;
}

// The cells along one axis (offsets lo..hi from c's own, cells 1 / inv_cell wide) that can hold a
// point within half a cell of coordinate c: c's own and its neighbour on the side of the middle
// that c is on; both neighbours within 1 % of the middle, where rounding could decide (the margin
// holds for coordinates up to ~10^4 cells from the origin; the key repeats every 1024 anyway).
KFN void self_cell_span(real c, real inv_cell, OUT(int) lo, OUT(int) hi) {
  precise real u = c * inv_cell;
  precise real f = u - floor(u);
  lo = f <= real(0.51) ? -1 : 0;
  hi = f >= real(0.49) ? 1 : 0;
}

// What self_walk (and self_pairs) do with the particles they visit.
#define VKCLOTH_SELF_WALK_COLLIDE 0u // sums p's response to every pair (self_pair, self_contact)
#define VKCLOTH_SELF_WALK_GATHER 1u  // writes p's neighbour list (self_candidate, self_list_put)
#define VKCLOTH_SELF_WALK_ENERGY 2u  // adds every pair's contact energy to p's vertex step (self_energy)

#ifdef SELF_DATA_PARAM // the includer provides the table (C++: kernel.hpp; GLSL: self_collision.comp)
// Candidate q of p for `mode` (COLLIDE or ENERGY): when the two are a pair (self_pair; t2 the
// thickness squared), its part goes into sum_x, sum_v (COLLIDE: p's response) or sum_x, the force,
// and hessian (ENERGY: the contact energy, where v and q's self_velocity are the particles' moves
// since the step's start); returns 1 for a pair, else 0.
KFN uint self_visit(SELF_DATA_PARAM, uint q, uint mode, vec3 x, vec3 v, real w, vec3 rx, real t2,
                    real thickness, real mu, real k, real slip, INOUT(vec3) sum_x, INOUT(vec3) sum_v,
                    INOUT(SpringBlock) hessian) {
  vec3 xq;
  vec3 rq;
  real wq;
  self_particle(SELF_DATA, q, xq, wq, rq);
  if (!self_pair(x, xq, rx, rq, t2))
    return 0u;
  const vec3 vq = self_velocity(SELF_DATA, q); // read for a pair only
  if (mode == VKCLOTH_SELF_WALK_ENERGY)
    self_energy(sum_x, hessian, x, v, xq, vq, thickness, k, mu, slip);
  else
    self_contact(sum_x, sum_v, x, v, w, xq, vq, wq, thickness, mu);
  return 1u;
}

// The 27 cells around the cell of key `own`, cell by cell in a fixed order, each cell's particles in
// increasing index (a bucket holds the particles of every cell hashed to it, in increasing index:
// those of other cells are skipped by their key), for `mode` (VKCLOTH_SELF_WALK_*): COLLIDE adds p's
// response to every pair to sum_x, sum_v and returns the number of pairs; GATHER writes p's
// neighbour list (candidates within `reach2`) and returns its length (past the capacity it stops
// writing, and the count says the list overflowed); ENERGY adds the pairs' contact energy (stiffness
// `k`, friction `mu` with static slip `slip`) to f and hessian and returns the number of pairs (v and
// self_velocity's are then the particles' moves since the step's start).
// Provided by the including file: self_range(SELF_DATA, bucket, first, stop) (the bucket's entries
// of the sorted table), self_entry(SELF_DATA, i, q, key) (an entry's particle and the key of the
// cell it was sorted in), self_particle(SELF_DATA, q, x, w, rest), self_velocity(SELF_DATA, q) (read
// only for a pair, where the response needs it), self_entry_particle(SELF_DATA,
// i, q, x, rest) (entry i's particle q, as the table was built: a backend may keep them in table
// order), self_list_put(SELF_DATA, p, slot, q). Both backends build the same table, so they visit
// the same particles in the same order.
KFN uint self_walk(SELF_DATA_PARAM, uint p, uint own, uint mode, vec3 x, vec3 v, real w, vec3 rx,
                   real thickness, real reach2, real inv_cell, uint mask, real mu, real k, real slip,
                   INOUT(vec3) sum_x, INOUT(vec3) sum_v, INOUT(SpringBlock) hessian) {
  precise real t2 = thickness * thickness;
  uint found = 0u;
  // GATHER's cells are twice the reach: the 2 x 2 x 2 on x's side of its cell's middle hold every
  // candidate (self_cell_span); the other modes walk all 27.
  const bool octant = mode == VKCLOTH_SELF_WALK_GATHER;
  int i0 = -1, i1 = 1, j0 = -1, j1 = 1, k0 = -1, k1 = 1;
  if (octant) {
    self_cell_span(x.x, inv_cell, i0, i1);
    self_cell_span(x.y, inv_cell, j0, j1);
    self_cell_span(x.z, inv_cell, k0, k1);
  }
  for (int dk = k0; dk <= k1; ++dk)
    for (int dj = j0; dj <= j1; ++dj)
      for (int di = i0; di <= i1; ++di) {
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
          if (mode != VKCLOTH_SELF_WALK_GATHER) {
            found += self_visit(SELF_DATA, q, mode, x, v, w, rx, t2, thickness, mu, k, slip, sum_x, sum_v,
                                hessian);
            continue;
          }
          vec3 xq;
          vec3 rq;
          self_entry_particle(SELF_DATA, i, q, xq, rq); // right after the build: by entry
          if (self_candidate(x, xq, rx, rq, reach2, t2)) {
            if (found < uint(VKCLOTH_SELF_LIST_CAPACITY))
              self_list_put(SELF_DATA, p, found, q);
            found += 1u;
          }
        }
      }
  return found;
}

// Particle p's neighbour list (positions now, p at x; own: p's cell key in the table of cells
// 1 / inv_cell = twice the reach wide): its length (past the capacity: overflowed).
KFN uint self_gather(SELF_DATA_PARAM, uint p, uint own, vec3 x, vec3 rx, real thickness, real reach2,
                     real inv_cell, uint mask) {
  vec3 unused_x = vec3(real(0));
  vec3 unused_v = vec3(real(0));
  SpringBlock unused = zero_block();
  return self_walk(SELF_DATA, p, own, VKCLOTH_SELF_WALK_GATHER, x, vec3(real(0)), real(0), rx, thickness,
                   reach2, inv_cell, mask, real(0), real(0), real(0), unused_x, unused_v, unused);
}

// Particle p's response, every pair found by the walk around its cell now (no neighbour list).
KFN void self_collide(SELF_DATA_PARAM, uint p, vec3 x, vec3 v, real w, vec3 rx, real thickness, real inv_cell,
                      uint mask, real mu, OUT(vec3) dx, OUT(vec3) dv) {
  precise vec3 sum_x = vec3(real(0));
  precise vec3 sum_v = vec3(real(0));
  SpringBlock unused = zero_block();
  const uint pairs =
      self_walk(SELF_DATA, p, self_key(x, inv_cell), VKCLOTH_SELF_WALK_COLLIDE, x, v, w, rx, thickness,
                real(0), inv_cell, mask, mu, real(0), real(0), sum_x, sum_v, unused);
  self_mean(sum_x, sum_v, pairs, dx, dv);
}

// Every pair of p for `mode` (COLLIDE or ENERGY, as self_walk): from its neighbour list (`listed`
// entries, self_list_get(SELF_DATA, p, i)) in the list's order; a list that overflowed (listed >
// capacity) walks all 27 cells around its cell of the build instead (own: p's key then), which hold
// every particle the list would have (in the walk's order). Returns the number of pairs.
KFN uint self_pairs(SELF_DATA_PARAM, uint p, uint listed, uint own, uint mode, vec3 x, vec3 v, real w,
                    vec3 rx, real thickness, uint mask, real mu, real k, real slip, INOUT(vec3) sum_x,
                    INOUT(vec3) sum_v, INOUT(SpringBlock) hessian) {
  if (listed > uint(VKCLOTH_SELF_LIST_CAPACITY))
    return self_walk(SELF_DATA, p, own, mode, x, v, w, rx, thickness, real(0), real(0), mask, mu, k, slip,
                     sum_x, sum_v, hessian);
  precise real t2 = thickness * thickness;
  uint pairs = 0u;
  for (uint i = 0u; i < listed; ++i)
    pairs += self_visit(SELF_DATA, self_list_get(SELF_DATA, p, i), mode, x, v, w, rx, t2, thickness, mu, k,
                        slip, sum_x, sum_v, hessian);
  return pairs;
}

// Particle p's response from its neighbour list (self_pairs).
KFN void self_collide_listed(SELF_DATA_PARAM, uint p, uint listed, uint own, vec3 x, vec3 v, real w, vec3 rx,
                             real thickness, uint mask, real mu, OUT(vec3) dx, OUT(vec3) dv) {
  precise vec3 sum_x = vec3(real(0));
  precise vec3 sum_v = vec3(real(0));
  SpringBlock unused = zero_block();
  const uint pairs = self_pairs(SELF_DATA, p, listed, own, VKCLOTH_SELF_WALK_COLLIDE, x, v, w, rx, thickness,
                                mask, mu, real(0), real(0), sum_x, sum_v, unused);
  self_mean(sum_x, sum_v, pairs, dx, dv);
}

// Particle p's self-contact energy in its vertex step (vbd with a self-contact stiffness k > 0):
// its pairs (self_pairs) at the positions the sweep starts from (x: p's, self_particle: the
// others'; u and self_velocity's: the moves since the step's start, for the friction mu
// over a step of h), as f (the force) and hessian (the stiffness), which the step adds to its springs'.
KFN void self_energy_listed(SELF_DATA_PARAM, uint p, uint listed, uint own, vec3 x, vec3 u, vec3 rx,
                            real thickness, uint mask, real k, real mu, real h, OUT(vec3) f,
                            OUT(SpringBlock) hessian) {
  precise vec3 sum_f = vec3(real(0));
  vec3 unused_v = vec3(real(0));
  SpringBlock block = zero_block();
  precise real slip = real(VKCLOTH_SELF_FRICTION_SLIP_SPEED) * h;
  self_pairs(SELF_DATA, p, listed, own, VKCLOTH_SELF_WALK_ENERGY, x, u, real(0), rx, thickness, mask, mu, k,
             slip, sum_f, unused_v, block);
  f = sum_f;
  hessian = block;
}
#endif

// Applies a self-collision pass's response to a particle.
KFN void self_apply(INOUT(vec3) x, INOUT(vec3) v, vec3 dx, vec3 dv) {
  precise vec3 nx = x + dx;
  precise vec3 nv = v + dv;
  x = nx;
  v = nv;
}
