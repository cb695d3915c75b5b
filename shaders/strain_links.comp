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
#include "common.glsl"

layout(std430, set = 0, binding = VKCLOTH_BINDING_POS_OUT) buffer PosOut {
  vec4 pos_out[];
};
layout(std430, set = 0, binding = VKCLOTH_BINDING_VEL) buffer VelBuf {
  vec4 vel[];
};
layout(std430, set = 0, binding = VKCLOTH_BINDING_STRAIN_LINKS) readonly buffer LinkBuf {
  StrainLink links[];
};

void main() {
  begin_instance();
  const uint k = particle_index(); // the link within its colour
  if (k >= pc.pad1 || frozen() || (ip.stretch & VKCLOTH_STRETCH_PROVOT) == 0u ||
      pc.stage >= ip.stretch_sweeps)
    return;
  const StrainLink l = links[pc.pad0 + k];
  const uint ga = base + l.a, gb = base + l.b;
  vec3 xa = pos_out[ga].xyz, xb = pos_out[gb].xyz;
  vec3 va = vel[ga].xyz, vb = vel[gb].xyz;
  vec3 da, db;
  provot_link(xa, xb, particle[l.a].pinned != 0u, particle[l.b].pinned != 0u,
              stretch_bound(l.rest_length, ip.max_strain), da, db);
  apply_correction(xa, va, da, ip.dt);
  apply_correction(xb, vb, db, ip.dt);
  pos_out[ga] = vec4(xa, 1.0);
  pos_out[gb] = vec4(xb, 1.0);
  vel[ga] = vec4(va, 0.0);
  vel[gb] = vec4(vb, 0.0);
}
