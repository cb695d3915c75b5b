// SPDX-License-Identifier: MIT
#version 450
#extension GL_GOOGLE_include_directive : require
// Implicit Euler passes (engine/src/core/implicit_euler.hpp for the method), one invocation per
// particle; PushConstants::stage selects the pass (VKCLOTH_IMPL_*). The CG passes write one
// partial dot-product pair per workgroup (fixed-shape shared-memory tree, no atomics) that
// implicit_reduce.comp sums in a fixed order: deterministic, but not the CPU's sequential order.
#include "implicit_shared.h"
#include "common.glsl"
#include "force_body.glsl"

layout(std430, set = 0, binding = VKCLOTH_BINDING_FORCE_OUT) buffer ForceOut { vec4 force_out[]; }; // FORCE -> SYSTEM
layout(std430, set = 0, binding = VKCLOTH_BINDING_NORMAL) writeonly buffer NormalOut { vec4 normal_out[]; };
layout(std430, set = 0, binding = VKCLOTH_BINDING_POS_OUT) writeonly buffer PosOut { vec4 pos_out[]; };
layout(std430, set = 0, binding = VKCLOTH_BINDING_VEL) buffer VelBuf { vec4 vel[]; };
layout(std430, set = 0, binding = VKCLOTH_BINDING_IMPL_VF) buffer VfBuf { vec4 vf[]; };
layout(std430, set = 0, binding = VKCLOTH_BINDING_IMPL_KS) buffer KsBuf { vec4 ks[]; };
layout(std430, set = 0, binding = VKCLOTH_BINDING_IMPL_DIAG_INV) buffer DiagBuf { vec4 diag_inv[]; };
layout(std430, set = 0, binding = VKCLOTH_BINDING_IMPL_X) buffer XBuf { vec4 cx[]; };
layout(std430, set = 0, binding = VKCLOTH_BINDING_IMPL_R) buffer RBuf { vec4 cr[]; };
layout(std430, set = 0, binding = VKCLOTH_BINDING_IMPL_Z) buffer ZBuf { vec4 cz[]; };
layout(std430, set = 0, binding = VKCLOTH_BINDING_IMPL_D) buffer DBuf { vec4 cd[]; };
layout(std430, set = 0, binding = VKCLOTH_BINDING_IMPL_Q) buffer QBuf { vec4 cq[]; };
layout(std430, set = 0, binding = VKCLOTH_BINDING_IMPL_PARTIALS) writeonly buffer PartialBuf { vec2 partials[]; };
layout(std430, set = 0, binding = VKCLOTH_BINDING_IMPL_STATE) readonly buffer StateBuf { CgState cg; };

#include "finish.glsl"

shared vec2 red[VKCLOTH_WORKGROUP_SIZE];

// Fixed-shape tree over the workgroup; every invocation must call it (uniform control flow).
void workgroup_partial(vec2 value) {
  const uint l = gl_LocalInvocationID.x;
  red[l] = value;
  barrier();
  for (uint s = VKCLOTH_WORKGROUP_SIZE / 2; s > 0u; s >>= 1) {
    if (l < s) {
      precise vec2 t = red[l] + red[l + s];
      red[l] = t;
    }
    barrier();
  }
  if (l == 0u) partials[gl_WorkGroupID.y * gl_NumWorkGroups.x + gl_WorkGroupID.x] = red[0];
}

// Edge e's stiffness block, stored as two vec4: (xx yy zz xy), (xz yz 0 0).
SpringBlock block_at(uint e) {
  const vec4 a = ks[2u * e], b = ks[2u * e + 1u];
  SpringBlock s;
  s.diag = a.xyz;
  s.off = vec3(a.w, b.x, b.y);
  return s;
}

void main() {
  begin_instance(); // always instance 0: implicit passes run batches of one
  const uint p = particle_index();
  const bool live = p < pc.count;
  const uint mode = pc.stage;
  const float h = ip.dt;
  precise float mu_h = 1.0 + h * ip.gravity_damping.w;
  precise float h2 = h * h;
  const bool pinned = live && particle[p].pinned != 0u;

  if (mode == VKCLOTH_IMPL_FORCE) {
    if (!live || frozen()) return;
    vec3 v = vel[p].xyz;
    vec3 f, nrm;
    particle_force(p, v, f, nrm); // contact filtering included (not for pinned particles)
    force_out[p] = vec4(f, 0.0);
    normal_out[p] = normal_output(nrm);
    vf[p] = vec4(v, 0.0);
    return;
  }
  if (mode == VKCLOTH_IMPL_SYSTEM) {
    if (frozen()) return; // uniform
    vec2 part = vec2(0.0);
    if (live) {
      const vec3 x = pos_in[p].xyz;
      const vec3 vp = vf[p].xyz;
      precise vec3 lv = vec3(0.0);
      precise vec3 ksum = vec3(0.0);
      const uint end = offsets[p + 1];
      for (uint e = offsets[p]; e < end; ++e) {
        const Edge s = edges[e];
        const SpringBlock k = spring_block(pos_in[s.other].xyz - x, s.rest_length, s.stiffness);
        ks[2u * e] = vec4(k.diag, k.off.x);
        ks[2u * e + 1u] = vec4(k.off.y, k.off.z, 0.0, 0.0);
        lv = lv + apply_block(k, vp - vf[s.other].xyz);
        ksum = ksum + k.diag;
      }
      const vec3 diag = implicit_diagonal(mu_h, particle[p].mass, ksum, h2);
      cx[p] = vec4(0.0);
      if (pinned) {
        diag_inv[p] = cr[p] = cz[p] = cd[p] = vec4(0.0);
      } else {
        precise vec3 di = vec3(1.0) / diag;
        const vec3 r = implicit_rhs(force_out[p].xyz, lv, h);
        precise vec3 z = r * di;
        diag_inv[p] = vec4(di, 0.0);
        cr[p] = vec4(r, 0.0);
        cz[p] = vec4(z, 0.0);
        cd[p] = vec4(z, 0.0);
        part = vec2(dot3(r, z), dot3(r, r));
      }
    }
    workgroup_partial(part);
    return;
  }
  if (mode == VKCLOTH_IMPL_MATVEC) {
    vec2 part = vec2(0.0);
    if (live) {
      precise vec3 q = vec3(0.0);
      const vec3 dp = cd[p].xyz;
      if (!pinned) {
        precise vec3 s = vec3(0.0);
        const uint end = offsets[p + 1];
        for (uint e = offsets[p]; e < end; ++e) s = s + apply_block(block_at(e), dp - cd[edges[e].other].xyz);
        q = implicit_row(dp, mu_h, particle[p].mass, s, h2);
      }
      cq[p] = vec4(q, 0.0);
      part = vec2(dot3(dp, q), 0.0);
    }
    workgroup_partial(part);
    return;
  }
  if (mode == VKCLOTH_IMPL_UPDATE) {
    vec2 part = vec2(0.0);
    if (live) {
      const float alpha = cg.alpha;
      precise vec3 x = cx[p].xyz + cd[p].xyz * alpha;
      precise vec3 r = cr[p].xyz - cq[p].xyz * alpha;
      precise vec3 z = r * diag_inv[p].xyz;
      cx[p] = vec4(x, 0.0);
      cr[p] = vec4(r, 0.0);
      cz[p] = vec4(z, 0.0);
      part = vec2(dot3(r, z), dot3(r, r));
    }
    workgroup_partial(part);
    return;
  }
  if (!live) return;
  if (mode == VKCLOTH_IMPL_DIRECTION) {
    precise vec3 d = cz[p].xyz + cd[p].xyz * cg.beta;
    cd[p] = vec4(d, 0.0);
    return;
  }
  // VKCLOTH_IMPL_FINISH
  if (frozen()) {
    pos_out[p] = pos_in[p]; // keep the frozen state in the buffer that becomes current
    return;
  }
  const vec3 x0 = pos_in[p].xyz;
  if (pinned) {
    finish(p, true, x0, vel[p].xyz);
    return;
  }
  precise vec3 v = vf[p].xyz + cx[p].xyz;
  const bool both = (ip.flags & VKCLOTH_FLAG_CONTACT_BOTH) != 0u;
  for (uint c = 0u; c < ip.collider_count; ++c) { // the contact filter on the new velocity only
    float dist;
    vec3 n;
    collider_at(c, x0, dist, n);
    if (dist < ip.band) remove_inward(v, n, both);
  }
  precise vec3 x = x0 + v * h;
  finish(p, false, x, v);
}
