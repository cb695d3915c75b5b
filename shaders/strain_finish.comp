// SPDX-License-Identifier: MIT
#version 450
#extension GL_GOOGLE_include_directive : require
// vkcloth-builds: texel-and-storage workgroup-constant (shaders/CMakeLists.txt)
// Stretch control's per-particle passes (CpuSolver::limit_stretch), one invocation per particle:
// pc.stage 0, before Provot's sweeps: the particle's tethers in slot order (cloth_kernel.h
// tether_move, apply_correction; anchors are pinned, so no invocation writes what another
// reads); pc.stage 1, after the sweeps: the colliders' projection again (a correction may have
// pulled the particle into one); pc.stage 2, after self-collision (self_collision.comp): the same
// projection.
#include "kernel/layout/vkcloth_shared.h"
#define VKCLOTH_PC_COPY
#include "common.glsl"

// pos_out and vel (declared there), read_pos_out, read_velocity, read_particle, read_frozen,
// read_tether.
#define VKCLOTH_ACCESS_POS_OUT
#define VKCLOTH_ACCESS_PARTICLE
#define VKCLOTH_ACCESS_VEL_FLAGS
#define VKCLOTH_ACCESS_TETHERS
#include "buffer_access.glsl"

// One pipeline per stage (SC_STAGE; passes/finish.cpp): the tether pass has no
// collider code (docs/performance.md "lavapipe (llvmpipe) notes"); SC_COLLIDER_TYPES compiles out
// the shapes the batch lacks (all of them for the tethers).
void main() {
  begin_instance();
  const uint p = particle_index();
  if (p >= pc.count)
    return;
  const uint stage = pass_stage();
  const bool tether_pass = stage == 0u;
  // Stage 1 projects after stretch control, stage 2 after self-collision: each only where it ran.
  const bool ran = stage == 1u ? ip.stretch != 0u : (ip.flags & VKCLOTH_FLAG_SELF_COLLISION) != 0u;
  if ((tether_pass ? (ip.stretch & VKCLOTH_STRETCH_TETHERS) == 0u : ip.collider_count == 0u || !ran) ||
      read_particle(p).pinned != 0u || read_frozen())
    return;
  vec3 x = read_pos_out(p);
  vec3 v = read_velocity(p);
  bool moved = false;
  if (tether_pass) {
    // Euclidean rest lengths first, geodesic ones after (pc.count * VKCLOTH_TETHERS_PER_PARTICLE slots each).
    const uint first =
        ((ip.stretch & VKCLOTH_STRETCH_GEODESIC) != 0u ? pc.count + p : p) * VKCLOTH_TETHERS_PER_PARTICLE;
    for (uint k = 0u; k < VKCLOTH_TETHERS_PER_PARTICLE; ++k) {
      const TetherSlot t = read_tether(first + k);
      if (t.anchor == VKCLOTH_NO_TETHER) break;
      vec3 d;
      if (tether_move(x, read_pos_out(t.anchor), stretch_bound(t.rest_length, ip.max_strain), d)) {
        apply_correction(x, v, d, ip.dt);
        moved = true;
      }
    }
  } else {
    for (uint c = 0u; c < (SC_COLLIDERS ? ip.collider_count : 0u); ++c)
      project_out(base + p, collider_shape(c), ip.eps, x, x, v); // side: where the stretch control left it
    moved = true;
  }
  if (!moved) return;
  pos_out[base + p] = vec4(x, 1.0);
  vel[base + p] = vec4(v, 0.0);
}
