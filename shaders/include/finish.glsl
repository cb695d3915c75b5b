// The end of a step for one particle (CpuSolver::project_at, then check_finite), shared by
// integrate.comp and fused.comp. Expects `pos_out` (POS_OUT) and `vel` (VEL) to be declared.
#ifndef VKCLOTH_FINISH_GLSL
#define VKCLOTH_FINISH_GLSL

bool is_finite(vec3 v) {
  const uvec3 bits = floatBitsToUint(v) & 0x7f800000u; // exponent all ones: inf or NaN
  return all(notEqual(bits, uvec3(0x7f800000u)));
}

// CpuSolver::project for particle p of this instance, then check_finite; writes the new state.
void finish(uint p, bool pinned, vec3 x_in, vec3 v_in) {
  precise vec3 x = x_in;
  precise vec3 v = v_in;
  if (!pinned) {
    for (uint c = 0u; c < (SC_COLLIDERS ? ip.collider_count : 0u); ++c) {
      float dist;
      vec3 n;
      collider_contact(c, x, dist, n);
      if (!(dist < 0.0)) continue;
      const Collider col = colliders[ip.collider_first + c];
      if (col.type == VKCLOTH_COLLIDER_PLANE) {
        precise float back = ip.eps - dist;
        x = x + n * back; // report eq. 5: back to z_s + eps
      } else {
        precise float r = col.shape.w + ip.eps;
        x = col.shape.xyz + n * r; // report eq. 6
      }
      precise float vn = dot3(v, n);
      if (vn < 0.0) v = v - n * vn;
    }
  }
  pos_out[base + p] = vec4(x, 1.0);
  vel[base + p] = vec4(v, 0.0);
  const vec3 ax = abs(x);
  if (!is_finite(x) || !is_finite(v) || ax.x > ip.limit || ax.y > ip.limit || ax.z > ip.limit) {
    atomicOr(flags[inst].diverged, 1u);
    atomicMin(flags[inst].first_bad_step, pc.step);
    atomicMin(flags[inst].bad_particle, p); // the particle index within the instance
  }
}

#endif
