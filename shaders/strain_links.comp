// SPDX-License-Identifier: MIT
#version 450
#extension GL_GOOGLE_include_directive : require
// vkcloth-builds: texel-and-storage workgroup-constant (shaders/CMakeLists.txt)
// Stretch control, Provot's sweep over one colour of strain links (CpuSolver::limit_stretch; the
// formulas: cloth_kernel.h provot_link, apply_correction). One invocation per link of the colour
// (pc.link_first: its first link, pc.link_count: its count; pc.stage: the sweep), of every instance of the
// batch. The links of a colour share no particle, so each invocation alone reads and writes its
// two particles' new positions (POS_OUT) and velocities (VEL); the colours follow each other
// with a barrier between them, as the CPU's loop over colours.
#include "vkcloth_shared.h"
#define VKCLOTH_PC_COPY
#define VKCLOTH_PUSH_STRUCT StrainLinksPush
#include "common.glsl"

// pos_out and vel (declared there), read_pos_out, read_velocity, read_particle, read_frozen,
// read_strain_link.
#define VKCLOTH_ACCESS_POS_OUT
#define VKCLOTH_ACCESS_PARTICLE
#define VKCLOTH_ACCESS_VEL_FLAGS
#define VKCLOTH_ACCESS_STRAIN_LINKS
#include "buffer_access.glsl"

void main() {
  begin_instance();
  const uint k = particle_index(); // the link within its colour
  if (k >= pc.link_count || (ip.stretch & VKCLOTH_STRETCH_PROVOT) == 0u || pc.stage >= ip.stretch_sweeps ||
      read_frozen())
    return;
  const StrainLink link = read_strain_link(pc.link_first + k);
  const uint a = link.a, b = link.b;
  const float rest = link.rest_length;
  vec3 xa = read_pos_out(a), xb = read_pos_out(b);
  vec3 da, db;
  if (!provot_link(xa, xb, read_particle(a).pinned != 0u, read_particle(b).pinned != 0u,
                   stretch_bound(rest, ip.max_strain), da, db))
    return; // within the bound: nothing moves
  vec3 va = read_velocity(a), vb = read_velocity(b);
  apply_correction(xa, va, da, ip.dt);
  apply_correction(xb, vb, db, ip.dt);
  pos_out[base + a] = vec4(xa, 1.0);
  pos_out[base + b] = vec4(xb, 1.0);
  vel[base + a] = vec4(va, 0.0);
  vel[base + b] = vec4(vb, 0.0);
}
