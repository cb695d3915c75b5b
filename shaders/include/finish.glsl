// SPDX-License-Identifier: MIT
// The end of a step for one particle (CpuSolver: project, then the divergence check), shared by
// integrate.comp, fused.comp and implicit.comp. Expects `pos_out` (POS_OUT) and `vel` (VEL) to be
// declared.
#ifndef VKCLOTH_FINISH_GLSL
#define VKCLOTH_FINISH_GLSL

// Projects particle p of this instance out of every collider (cloth_kernel.h project_out; `side`:
// its position at the start of the step, a mesh's side), writes the new state and flags a
// divergence (the step and the smallest bad particle).
void finish(uint p, bool pinned, vec3 side, vec3 x_in, vec3 v_in) {
  vec3 x = x_in;
  vec3 v = v_in;
  if (!pinned) {
    for (uint c = 0u; c < (SC_COLLIDERS ? ip.collider_count : 0u); ++c)
      project_out(base + p, collider_shape(c), ip.eps, side, x, v);
  }
  pos_out[base + p] = vec4(x, 1.0);
  vel[base + p] = vec4(v, 0.0);
  if (diverged(x, v, ip.limit)) {
    atomicOr(flags[inst].diverged, 1u);
    atomicMin(flags[inst].first_bad_step, pc.step);
    atomicMin(flags[inst].bad_particle, p); // the particle index within the instance
  }
}

#endif
