#version 450
#extension GL_GOOGLE_include_directive : require
// Force pass, one invocation per particle (CpuSolver::compute_normals, compute_forces and
// apply_contacts for one particle): vertex normal from the grid neighbours, spring gather in
// SpringAdjacency order, gravity, damping -mu m v, wind Kw <n, u> n, then contact filtering.
// Reads POS_IN (all particles) and VEL_IN (own); writes FORCE_OUT, VEL_FILT, NORMAL (own).
#include "vkcloth_shared.h"
#include "common.glsl"

layout(std430, set = 0, binding = VKCLOTH_BINDING_POS_IN) readonly buffer PosIn { vec4 pos_in[]; };
layout(std430, set = 0, binding = VKCLOTH_BINDING_VEL_IN) readonly buffer VelIn { vec4 vel_in[]; };
layout(std430, set = 0, binding = VKCLOTH_BINDING_FORCE_OUT) writeonly buffer ForceOut { vec4 force_out[]; };
layout(std430, set = 0, binding = VKCLOTH_BINDING_VEL_FILT) writeonly buffer VelFilt { vec4 vel_filt[]; };
layout(std430, set = 0, binding = VKCLOTH_BINDING_NORMAL) writeonly buffer NormalOut { vec4 normal_out[]; };
layout(std430, set = 0, binding = VKCLOTH_BINDING_OFFSETS) readonly buffer OffsetBuf { uint offsets[]; };
layout(std430, set = 0, binding = VKCLOTH_BINDING_EDGES) readonly buffer EdgeBuf { Edge edges[]; };

// CpuSolver::compute_normals for particle (i, j): fan right, up, left, down; area-weighted sum.
vec3 grid_normal(uint p) {
  const int nx = int(pc.nx), ny = int(pc.ny);
  const int i = int(p % pc.nx), j = int(p / pc.nx);
  const vec3 x = pos_in[p].xyz;
  bool has[4] = bool[4](i + 1 < nx, j + 1 < ny, i > 0, j > 0);
  precise vec3 e[4] = vec3[4](vec3(0.0), vec3(0.0), vec3(0.0), vec3(0.0));
  if (has[0]) e[0] = pos_in[j * nx + i + 1].xyz - x;
  if (has[1]) e[1] = pos_in[(j + 1) * nx + i].xyz - x;
  if (has[2]) e[2] = pos_in[j * nx + i - 1].xyz - x;
  if (has[3]) e[3] = pos_in[(j - 1) * nx + i].xyz - x;
  precise vec3 sum = vec3(0.0);
  for (int k = 0; k < 4; ++k)
    if (has[k] && has[(k + 1) & 3]) sum = sum + cross3(e[k], e[(k + 1) & 3]);
  precise float len = sqrt(dot3(sum, sum));
  precise vec3 n = len > 0.0 ? sum / len : vec3(0.0);
  return n;
}

void main() {
  const uint p = particle_index();
  if (p >= pc.count || frozen()) return;

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
  precise vec3 v = vel_in[p].xyz;
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
      precise float vn = dot3(v, n);
      if (vn < 0.0) v = v - n * vn;
      precise float fn = dot3(f, n);
      if (fn < 0.0) f = f - n * fn;
    }
  }

  force_out[p] = vec4(f, 0.0);
  vel_filt[p] = vec4(v, 0.0);
  normal_out[p] = vec4(nrm, 0.0);
}
