// SPDX-License-Identifier: MIT
#version 450
#extension GL_GOOGLE_include_directive : require
// Stretch control's per-particle passes (CpuSolver::limit_stretch), one invocation per particle:
// pc.stage 0, before Provot's sweeps: the particle's tethers in slot order (cloth_kernel.h
// tether_move, apply_correction; anchors are pinned, so no invocation writes what another
// reads); pc.stage 1, after the sweeps: the colliders' projection again (a correction may have
// pulled the particle into one).
#include "vkcloth_shared.h"
#include "common.glsl"

layout(std430, set = 0, binding = VKCLOTH_BINDING_POS_OUT) buffer PosOut {
  vec4 pos_out[];
};
layout(std430, set = 0, binding = VKCLOTH_BINDING_VEL) buffer VelBuf {
  vec4 vel[];
};
layout(std430, set = 0, binding = VKCLOTH_BINDING_TETHERS) readonly buffer TetherBuf {
  TetherSlot tethers[];
};

void main() {
  begin_instance();
  const uint p = particle_index();
  if (p >= pc.count || frozen() || ip.stretch == 0u || particle[p].pinned != 0u)
    return;
  const bool tether_pass = pc.stage == 0u;
  if (tether_pass ? (ip.stretch & VKCLOTH_STRETCH_TETHERS) == 0u : ip.collider_count == 0u)
    return;
  const uint g = base + p;
  vec3 x = pos_out[g].xyz;
  vec3 v = vel[g].xyz;
  if (tether_pass) {
    // Euclidean rest lengths first, geodesic ones after (pc.count * VKCLOTH_TETHERS_PER_PARTICLE slots each).
    const uint first =
        ((ip.stretch & VKCLOTH_STRETCH_GEODESIC) != 0u ? pc.count + p : p) * VKCLOTH_TETHERS_PER_PARTICLE;
    for (uint k = 0u; k < VKCLOTH_TETHERS_PER_PARTICLE; ++k) {
      const TetherSlot t = tethers[first + k];
      if (t.anchor == VKCLOTH_NO_TETHER)
        break;
      const vec3 d =
          tether_move(x, pos_out[base + t.anchor].xyz, stretch_bound(t.rest_length, ip.max_strain));
      apply_correction(x, v, d, ip.dt);
    }
  } else {
    for (uint c = 0u; c < ip.collider_count; ++c) {
      const Collider col = colliders[ip.collider_first + c];
      project_out(col.type, col.shape.xyz, col.shape.w, ip.eps, x, v);
    }
  }
  pos_out[g] = vec4(x, 1.0);
  vel[g] = vec4(v, 0.0);
}
