// SPDX-License-Identifier: MIT
// The force evaluation of one particle, shared by force.comp (two-pass layout), fused.comp (one
// pass per Euler step) and implicit.comp: vertex normal from the grid fan or from the gather
// lists' ring terms, spring gather in the topology's order, gravity, damping, wind, then contact
// filtering; each formula from cloth_kernel.h, which the CPU reference compiles too. Reads POS_IN
// (all particles), the particle constants and the gather lists through buffer_access.glsl
// (read_pos_in, read_particle, read_list_range, read_edge).
#ifndef VKCLOTH_FORCE_BODY_GLSL
#define VKCLOTH_FORCE_BODY_GLSL

layout(std430, set = 0, binding = VKCLOTH_BINDING_POS_IN) readonly buffer PosIn { vec4 pos_in[]; };

#define VKCLOTH_ACCESS_POS_IN
#define VKCLOTH_ACCESS_PARTICLE
#define VKCLOTH_ACCESS_LISTS
#include "buffer_access.glsl"

// Grid stencil (specialisation constants, set by the host when every interior particle's gather
// list is the same up to translation: GpuSolver detect_stencil, like CpuSolver::detect_stencil).
// Interior particles (2 <= i < nx-2, 2 <= j < ny-2) then sum their 12 springs from compile-time
// offsets and constants instead of the CSR lists: same terms in the same (CSR) order, same bits.
layout(constant_id = 0) const bool SC_STENCIL = false;
layout(constant_id = 1) const uint SC_NX = 1u;
layout(constant_id = 2) const uint SC_NY = 1u;
layout(constant_id = 3) const int SC_OFF0 = 0;
layout(constant_id = 4) const int SC_OFF1 = 0;
layout(constant_id = 5) const int SC_OFF2 = 0;
layout(constant_id = 6) const int SC_OFF3 = 0;
layout(constant_id = 7) const int SC_OFF4 = 0;
layout(constant_id = 8) const int SC_OFF5 = 0;
layout(constant_id = 9) const int SC_OFF6 = 0;
layout(constant_id = 10) const int SC_OFF7 = 0;
layout(constant_id = 11) const int SC_OFF8 = 0;
layout(constant_id = 12) const int SC_OFF9 = 0;
layout(constant_id = 13) const int SC_OFF10 = 0;
layout(constant_id = 14) const int SC_OFF11 = 0;
layout(constant_id = 15) const float SC_L0 = 0.0;
layout(constant_id = 16) const float SC_L1 = 0.0;
layout(constant_id = 17) const float SC_L2 = 0.0;
layout(constant_id = 18) const float SC_L3 = 0.0;
layout(constant_id = 19) const float SC_L4 = 0.0;
layout(constant_id = 20) const float SC_L5 = 0.0;
layout(constant_id = 21) const float SC_L6 = 0.0;
layout(constant_id = 22) const float SC_L7 = 0.0;
layout(constant_id = 23) const float SC_L8 = 0.0;
layout(constant_id = 24) const float SC_L9 = 0.0;
layout(constant_id = 25) const float SC_L10 = 0.0;
layout(constant_id = 26) const float SC_L11 = 0.0;
layout(constant_id = 27) const float SC_K0 = 0.0;
layout(constant_id = 28) const float SC_K1 = 0.0;
layout(constant_id = 29) const float SC_K2 = 0.0;
layout(constant_id = 30) const float SC_K3 = 0.0;
layout(constant_id = 31) const float SC_K4 = 0.0;
layout(constant_id = 32) const float SC_K5 = 0.0;
layout(constant_id = 33) const float SC_K6 = 0.0;
layout(constant_id = 34) const float SC_K7 = 0.0;
layout(constant_id = 35) const float SC_K8 = 0.0;
layout(constant_id = 36) const float SC_K9 = 0.0;
layout(constant_id = 37) const float SC_K10 = 0.0;
layout(constant_id = 38) const float SC_K11 = 0.0;
// Border particles too: every particle's gather list is the stencil's entries whose neighbour lies
// inside the grid, in stencil order (GpuSolver detect_stencil checks it). Then no particle takes
// the CSR loop (why: docs/performance.md "lavapipe (llvmpipe) notes").
layout(constant_id = 39) const bool SC_BORDER = false;
// The normal paths an instance of the batch may take: VKCLOTH_FLAG_HAS_GRID (the grid fan) and
// VKCLOTH_FLAG_RING_NORMALS (the gather lists' ring terms); the other one is compiled out (why:
// docs/performance.md "lavapipe (llvmpipe) notes"). The host sets it with the fused.comp and
// force.comp pipelines (SolverBatch::Normals); implicit.comp keeps the default, both.
layout(constant_id = 42) const uint SC_NORMAL_FLAGS = VKCLOTH_FLAG_HAS_GRID | VKCLOTH_FLAG_RING_NORMALS;
const bool SC_GRID_FAN = (SC_NORMAL_FLAGS & VKCLOTH_FLAG_HAS_GRID) != 0u;
const bool SC_RING = (SC_NORMAL_FLAGS & VKCLOTH_FLAG_RING_NORMALS) != 0u;

// Bit `bit` when stencil neighbour `off` of grid particle (i, j) lies inside the grid
// (off = dj nx + di with |di|, |dj| <= 2; compile-time constants after specialisation).
uint stencil_bit(uint i, uint j, int off, uint bit) {
  const int dj = (off + 2 * int(SC_NX) + 2) / int(SC_NX) - 2;
  const int di = off - dj * int(SC_NX);
  return uint(int(i) + di) < SC_NX && uint(int(j) + dj) < SC_NY ? bit : 0u;
}
uint stencil_present(uint i, uint j) {
  return stencil_bit(i, j, SC_OFF0, 1u) | stencil_bit(i, j, SC_OFF1, 2u) | stencil_bit(i, j, SC_OFF2, 4u) |
         stencil_bit(i, j, SC_OFF3, 8u) | stencil_bit(i, j, SC_OFF4, 16u) | stencil_bit(i, j, SC_OFF5, 32u) |
         stencil_bit(i, j, SC_OFF6, 64u) | stencil_bit(i, j, SC_OFF7, 128u) | stencil_bit(i, j, SC_OFF8, 256u) |
         stencil_bit(i, j, SC_OFF9, 512u) | stencil_bit(i, j, SC_OFF10, 1024u) | stencil_bit(i, j, SC_OFF11, 2048u);
}

// One spring term (cloth_kernel.h add_spring) towards this instance's particle q.
void spring_term(inout vec3 f, vec3 x, uint q, float rest, float k) {
  add_spring(f, x, read_pos_in(q), rest, k);
}

// The grid fan of particle (i, j): right, up, left, down; one triangle per consecutive present
// pair, k = 0..3 in that order, as the topology's fan lists give it to the CPU (unrolled, no local
// arrays: docs/performance.md "lavapipe (llvmpipe) notes").
vec3 grid_normal(uint p) {
  const uint nx = SC_STENCIL ? SC_NX : pc.nx; // a constant divisor when specialised
  const uint i = p % nx, j = p / nx;
  const vec3 x = read_pos_in(p);
  const bool h0 = i + 1u < nx, h1 = j + 1u < (SC_STENCIL ? SC_NY : pc.ny), h2 = i > 0u, h3 = j > 0u;
  precise vec3 e0 = vec3(0.0), e1 = vec3(0.0), e2 = vec3(0.0), e3 = vec3(0.0);
  if (h0) e0 = read_pos_in(p + 1u) - x;
  if (h1) e1 = read_pos_in(p + nx) - x;
  if (h2) e2 = read_pos_in(p - 1u) - x;
  if (h3) e3 = read_pos_in(p - nx) - x;
  vec3 sum = vec3(0.0);
  if (h0 && h1) add_fan_triangle(sum, e0, e1);
  if (h1 && h2) add_fan_triangle(sum, e1, e2);
  if (h2 && h3) add_fan_triangle(sum, e2, e3);
  if (h3 && h0) add_fan_triangle(sum, e3, e0);
  return unit_or_zero(sum);
}

// Particle p's unit normal alone: particle_force's, the same terms in the same order (the grid fan,
// or the ring terms of the gather list's fan entries), without its springs and contacts (vbd.comp's
// BEGIN, as the CPU's normal_at).
vec3 particle_normal(uint p) {
  if (SC_GRID_FAN && (ip.flags & VKCLOTH_FLAG_HAS_GRID) != 0u) return grid_normal(p);
  if (!SC_RING || (ip.flags & VKCLOTH_FLAG_RING_NORMALS) == 0u) return vec3(0.0);
  const vec3 x = read_pos_in(p);
  const uvec3 range = read_list_range(p);
  vec3 fan = vec3(0.0), prev = vec3(0.0), first = vec3(0.0);
  for (uint e = range.x; e < range.y; ++e) {
    const Edge s = read_edge(e);
    if (FAN_EXIT && s.ring == 0u) break;
    precise vec3 u = read_pos_in(s.other) - x;
    add_ring_term(fan, prev, first, u, s.ring);
  }
  return unit_or_zero(fan);
}

#ifdef VKCLOTH_FRICTION_AFTER_SOLVE
// implicit.comp: the force the contact filter removed from this particle (F - filtered F).
vec3 contact_removed_force = vec3(0.0);
#endif

// Force on particle p (index within the instance) after contacts (f), its velocity after contacts (v, in: the state velocity)
// and its unit normal (nrm).
void particle_force(uint p, inout vec3 v_io, out vec3 f_out, out vec3 nrm_out) {
  vec3 nrm = vec3(0.0);
  if (SC_GRID_FAN && (ip.flags & VKCLOTH_FLAG_HAS_GRID) != 0u) nrm = grid_normal(p);

  const vec3 x = read_pos_in(p);
  vec3 f = vec3(0.0);
  bool interior = false;
  uint has = 0xfffu; // bit k: stencil neighbour k exists (all of them inside)
  if (SC_STENCIL) {
    const uint i = p % SC_NX, j = p / SC_NX;
    interior = i >= 2u && i + 2u < SC_NX && j >= 2u && j + 2u < SC_NY;
    if (SC_BORDER) {
      interior = true;
      has = stencil_present(i, j);
    }
  }
  if (interior) {
    const int q = int(p);
    if ((has & 1u) != 0u) spring_term(f, x, uint(q + SC_OFF0), SC_L0, SC_K0);
    if ((has & 2u) != 0u) spring_term(f, x, uint(q + SC_OFF1), SC_L1, SC_K1);
    if ((has & 4u) != 0u) spring_term(f, x, uint(q + SC_OFF2), SC_L2, SC_K2);
    if ((has & 8u) != 0u) spring_term(f, x, uint(q + SC_OFF3), SC_L3, SC_K3);
    if ((has & 16u) != 0u) spring_term(f, x, uint(q + SC_OFF4), SC_L4, SC_K4);
    if ((has & 32u) != 0u) spring_term(f, x, uint(q + SC_OFF5), SC_L5, SC_K5);
    if ((has & 64u) != 0u) spring_term(f, x, uint(q + SC_OFF6), SC_L6, SC_K6);
    if ((has & 128u) != 0u) spring_term(f, x, uint(q + SC_OFF7), SC_L7, SC_K7);
    if ((has & 256u) != 0u) spring_term(f, x, uint(q + SC_OFF8), SC_L8, SC_K8);
    if ((has & 512u) != 0u) spring_term(f, x, uint(q + SC_OFF9), SC_L9, SC_K9);
    if ((has & 1024u) != 0u) spring_term(f, x, uint(q + SC_OFF10), SC_L10, SC_K10);
    if ((has & 2048u) != 0u) spring_term(f, x, uint(q + SC_OFF11), SC_L11, SC_K11);
  } else {
    // The springs' edges also make the normal (ClothTopology::ring_normals; CpuSolver::
    // normal_force_at, term for term). The fan's entries come first, each with ring bits: a first
    // loop takes them with their ring terms, a second the plain springs (two loops rather than one:
    // docs/performance.md "lavapipe (llvmpipe) notes"). FAN_EXIT: buffer_access.glsl.
    const bool ring = SC_RING && (ip.flags & VKCLOTH_FLAG_RING_NORMALS) != 0u;
    const uvec3 range = read_list_range(p);
    const uint end = range.z;
    uint e = range.x;
    if (ring) {
      vec3 fan = vec3(0.0), prev = vec3(0.0), first = vec3(0.0);
      for (; e < range.y; ++e) {
        const Edge s = read_edge(e);
        if (FAN_EXIT && s.ring == 0u) break;
        precise vec3 u = read_pos_in(s.other) - x;
        add_spring_edge(f, u, s.rest_length, s.stiffness);
        add_ring_term(fan, prev, first, u, s.ring);
      }
      nrm = unit_or_zero(fan);
    }
    for (; e < end; ++e) {
      const Edge s = read_edge(e);
      precise vec3 u = read_pos_in(s.other) - x;
      add_spring_edge(f, u, s.rest_length, s.stiffness);
    }
  }
  const float m = read_particle(p).mass;
  vec3 v = v_io;
  f = add_body_forces(f, m, v, ip.gravity_damping.xyz, ip.gravity_damping.w, (ip.flags & VKCLOTH_FLAG_WIND) != 0u,
                      nrm, ip.wind.xyz, ip.wind.w);

  // Contacts: inside the 2 eps band, remove only the parts of v and F pointing into the collider
  // (relative to its surface), then friction.
#ifdef VKCLOTH_FRICTION_AFTER_SOLVE
  const vec3 unfiltered = f;
#endif
  if (read_particle(p).pinned == 0u) {
    const bool both = (ip.flags & VKCLOTH_FLAG_CONTACT_BOTH) != 0u;
    precise float h_over_m = ip.dt / m;
    for (uint c = 0u; c < (SC_COLLIDERS ? ip.collider_count : 0u); ++c) {
      ColliderShape s = collider_shape(c);
#ifdef VKCLOTH_FRICTION_AFTER_SOLVE
      s.mu_k = 0.0; // implicit.comp: friction once, on the solved velocity (FINISH)
      s.mu_s = 0.0;
#endif
      float dist;
      vec3 n, deform;
      collider_contact(base + p, s, x, x, ip.band, dist, n, deform);
      contact_response(v, f, s, x, n, dist, ip.band, both, h_over_m, deform);
    }
  }
#ifdef VKCLOTH_FRICTION_AFTER_SOLVE
  contact_removed_force = unfiltered - f;
#endif

  f_out = f;
  v_io = v;
  nrm_out = nrm;
}

#endif
