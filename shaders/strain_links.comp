// SPDX-License-Identifier: MIT
#version 450
#extension GL_GOOGLE_include_directive : require
// vkcloth-builds: texel-and-storage workgroup-constant (shaders/CMakeLists.txt)
// Stretch control, Provot's sweep over one colour of strain links (CpuSolver::limit_stretch; the
// formulas: cloth_kernel.h provot_link, apply_correction). One invocation per link of the colour
// (pc.link_first: its first link, pc.link_count: its count; pc.stage: the sweep), of every instance of the
// batch. The links of a colour share no particle, so each invocation alone reads and writes its
// two particles' new positions (POS_OUT) and velocities (VEL); the colours follow each other
// with a barrier between them, as the CPU's loop over colours. In chain order
// (VKCLOTH_STRETCH_CHAINS, pc.chain_links > 0): one invocation per chain of a family (a grid's rows,
// or its columns), which projects the chain's links one after the other, forward then back; the
// chains of a family share no particle.
#include "kernel/layout/vkcloth_shared.h"
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

// Provot's correction of link l (the CPU's `project`): nothing when it is within its bound (its
// velocities are then not read). Along a chain, the particle the previous link shared with this one
// comes from `carried` (its id, position and, when that link moved it, velocity): what this
// invocation wrote is not visible through the texel views before the next dispatch. A link that
// does not move leaves as `carried` a particle this pass has not yet written (the chain's next one),
// so its velocity can then come from memory. It leaves in `carried` the particle this link shares
// with the next (forward: b, back: a).
uint carried = 0xffffffffu;
vec3 carried_x, carried_v;
bool carried_moved = false;
vec3 velocity_of(uint q) { return q == carried && carried_moved ? carried_v : read_velocity(q); }
void project_link(uint l, bool backward) {
  const StrainLink link = read_strain_link(l);
  const uint a = link.a, b = link.b;
  vec3 xa = a == carried ? carried_x : read_pos_out(a), xb = b == carried ? carried_x : read_pos_out(b);
  vec3 da, db, va, vb;
  const bool moves = provot_link(xa, xb, read_particle(a).pinned != 0u, read_particle(b).pinned != 0u,
                                 stretch_bound(link.rest_length, ip.max_strain), da, db);
  if (moves) {
    va = velocity_of(a);
    vb = velocity_of(b);
    apply_correction(xa, va, da, ip.dt);
    apply_correction(xb, vb, db, ip.dt);
    pos_out[base + a] = vec4(xa, 1.0);
    pos_out[base + b] = vec4(xb, 1.0);
    vel[base + a] = vec4(va, 0.0);
    vel[base + b] = vec4(vb, 0.0);
  }
  carried = backward ? a : b;
  carried_x = backward ? xa : xb;
  carried_v = backward ? va : vb;
  carried_moved = moves;
}

void main() {
  begin_instance();
  const uint k = particle_index(); // the link within its colour, or the chain within its family
  const uint links = pc.chain_links & ~VKCLOTH_CHAIN_BACKWARD;
  if (k >= pc.link_count || (ip.stretch & VKCLOTH_STRETCH_PROVOT) == 0u || pc.stage >= ip.stretch_sweeps ||
      ((ip.stretch & VKCLOTH_STRETCH_CHAINS) != 0u) != (links > 0u) || read_frozen())
    return;
  if (links == 0u) {
    project_link(pc.link_first + k, false);
    return;
  }
  // A chain forward, or (the next dispatch, after a barrier) back.
  const uint first = pc.link_first + k * links;
  if ((pc.chain_links & VKCLOTH_CHAIN_BACKWARD) == 0u)
    for (uint i = 0u; i < links; ++i)
      project_link(first + i, false);
  else
    for (uint i = links; i-- > 0u;)
      project_link(first + i, true);
}
