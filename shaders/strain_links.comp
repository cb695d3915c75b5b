// SPDX-License-Identifier: MIT
#version 450
#extension GL_GOOGLE_include_directive : require
// Stretch control, Provot's sweep over one colour of strain links (CpuSolver::limit_stretch; the
// formulas: cloth_kernel.h provot_link, apply_correction). One invocation per link of the colour
// (pc.pad0: its first link, pc.pad1: its count; pc.stage: the sweep), of every instance of the
// batch. The links of a colour share no particle, so each invocation alone reads and writes its
// two particles' new positions (POS_OUT) and velocities (VEL); the colours follow each other
// with a barrier between them, as the CPU's loop over colours.
#include "vkcloth_shared.h"
#define VKCLOTH_PC_COPY
#include "common.glsl"
#include "strain_texel.glsl"

#ifdef VKCLOTH_TEXEL_VIEWS
layout(set = 1, binding = VKCLOTH_TEXEL_BINDING_STRAIN_LINKS) uniform usamplerBuffer links_texel;
StrainLink link_at(uint l) {
  const int t = 3 * int(l); // StrainLink as 3 R32UI texels
  return StrainLink(texelFetch(links_texel, t).x, texelFetch(links_texel, t + 1).x,
                    uintBitsToFloat(texelFetch(links_texel, t + 2).x));
}
#else
layout(std430, set = 0, binding = VKCLOTH_BINDING_STRAIN_LINKS) readonly buffer LinkBuf { StrainLink links[]; };
StrainLink link_at(uint l) { return links[l]; }
#endif

void main() {
  begin_instance();
  const uint k = particle_index(); // the link within its colour
  if (k >= pc.pad1 || (ip.stretch & VKCLOTH_STRETCH_PROVOT) == 0u || pc.stage >= ip.stretch_sweeps || frozen_now())
    return;
  const StrainLink link = link_at(pc.pad0 + k);
  const uint a = link.a, b = link.b;
  const float rest = link.rest_length;
  vec3 xa = pos_now(a), xb = pos_now(b);
  vec3 da, db;
  if (!provot_link(xa, xb, pinned_at(a), pinned_at(b), stretch_bound(rest, ip.max_strain), da, db))
    return; // within the bound: nothing moves
  vec3 va = vel_now(a), vb = vel_now(b);
  apply_correction(xa, va, da, ip.dt);
  apply_correction(xb, vb, db, ip.dt);
  pos_out[base + a] = vec4(xa, 1.0);
  pos_out[base + b] = vec4(xb, 1.0);
  vel[base + a] = vec4(va, 0.0);
  vel[base + b] = vec4(vb, 0.0);
}
