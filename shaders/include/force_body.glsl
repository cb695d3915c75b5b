// The force evaluation of one particle (CpuSolver::normal_at, force_at, contact_at), shared by
// force.comp (two-pass layout) and fused.comp (one pass per Euler step): vertex normal from the
// grid neighbours, spring gather in SpringAdjacency order, gravity, damping -mu m v, wind
// Kw <n, u> n, then contact filtering. Reads POS_IN (all particles), OFFSETS, EDGES, PARTICLE.
#ifndef VKCLOTH_FORCE_BODY_GLSL
#define VKCLOTH_FORCE_BODY_GLSL

layout(std430, set = 0, binding = VKCLOTH_BINDING_POS_IN) readonly buffer PosIn { vec4 pos_in[]; };
layout(std430, set = 0, binding = VKCLOTH_BINDING_OFFSETS) readonly buffer OffsetBuf { uint offsets[]; };
layout(std430, set = 0, binding = VKCLOTH_BINDING_EDGES) readonly buffer EdgeBuf { Edge edges[]; };

// CpuSolver::normal_at for particle (i, j): fan right, up, left, down; area-weighted sum of the
// cross products of consecutive present edges, k = 0..3 in that order (the CPU's loop, unrolled:
// no local arrays, which llvmpipe would keep in memory with per-lane gathers).
vec3 grid_normal(uint p) {
  const uint nx = pc.nx;
  const uint i = p % nx, j = p / nx;
  const vec3 x = pos_in[p].xyz;
  const bool h0 = i + 1u < nx, h1 = j + 1u < pc.ny, h2 = i > 0u, h3 = j > 0u;
  precise vec3 e0 = vec3(0.0), e1 = vec3(0.0), e2 = vec3(0.0), e3 = vec3(0.0);
  if (h0) e0 = pos_in[p + 1u].xyz - x;
  if (h1) e1 = pos_in[p + nx].xyz - x;
  if (h2) e2 = pos_in[p - 1u].xyz - x;
  if (h3) e3 = pos_in[p - nx].xyz - x;
  precise vec3 sum = vec3(0.0);
  if (h0 && h1) sum = sum + cross3(e0, e1);
  if (h1 && h2) sum = sum + cross3(e1, e2);
  if (h2 && h3) sum = sum + cross3(e2, e3);
  if (h3 && h0) sum = sum + cross3(e3, e0);
  precise float len = sqrt(dot3(sum, sum));
  precise vec3 n = len > 0.0 ? sum / len : vec3(0.0);
  return n;
}

// Force on particle p after contacts (f), its velocity after contacts (v, in: the state velocity)
// and its unit normal (nrm).
void particle_force(uint p, inout vec3 v_io, out vec3 f_out, out vec3 nrm_out) {
  precise vec3 nrm = vec3(0.0);
  if ((pc.flags & VKCLOTH_FLAG_HAS_GRID) != 0u) nrm = grid_normal(p);

  const vec3 x = pos_in[p].xyz;
  precise vec3 f = vec3(0.0);
  const uint end = offsets[p + 1];
  for (uint e = offsets[p]; e < end; ++e) {
    const Edge s = edges[e];
    precise vec3 u = pos_in[s.other].xyz - x;
    precise float len = sqrt(dot3(u, u));
    if (len > 0.0) f = f + u * (s.stiffness * (len - s.rest_length) / len); // report eq. 2
  }
  const float m = particle[p].mass;
  f = f + pc.gravity_damping.xyz * m;
  precise float mu_m = pc.gravity_damping.w * m;
  precise vec3 v = v_io;
  f = f - v * mu_m;
  if ((pc.flags & VKCLOTH_FLAG_WIND) != 0u) {
    precise float kn = pc.wind.w * dot3(nrm, pc.wind.xyz);
    f = f + nrm * kn;
  }

  // Contacts: inside the 2 eps band, remove only the parts of v and F pointing into the collider.
  if (particle[p].pinned == 0u) {
    for (uint c = 0u; c < pc.collider_count; ++c) {
      float dist;
      vec3 n;
      collider_contact(c, x, dist, n);
      if (!(dist < pc.band)) continue;
      const bool both = (pc.flags & VKCLOTH_FLAG_CONTACT_BOTH) != 0u;
      precise float vn = dot3(v, n);
      if (vn < 0.0 || (both && vn != 0.0)) v = v - n * vn;
      precise float fn = dot3(f, n);
      if (fn < 0.0 || (both && fn != 0.0)) f = f - n * fn;
    }
  }

  f_out = f;
  v_io = v;
  nrm_out = nrm;
}

#endif
