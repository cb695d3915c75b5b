// SPDX-License-Identifier: MIT
// vkcloth kernel: explicit integrators (Euler, semi-implicit Euler, RK4) and the divergence check
// (docs/model.md "Integrators", "Divergence").
// Part of the kernel that cloth_kernel.h gathers (the rules it states hold here: fixed order,
// `precise` results, real(...) literals). No include guard: the C++ bridge includes it once per precision.

// ---- Integrators (docs/model.md "Integrators") ------------------------------------------------

// Eq. 3 (explicit: x with the old v) or semi-implicit Euler (x with the new v); a = F / m.
KFN void euler_update(bool semi, INOUT(vec3) x, INOUT(vec3) v, vec3 f, real m, real dt) {
  precise vec3 a = f / m;
  if (semi) {
    precise vec3 nv = v + a * dt;
    precise vec3 nx = x + nv * dt;
    v = nv;
    x = nx;
  } else {
    precise vec3 nx = x + v * dt;
    precise vec3 nv = v + a * dt;
    x = nx;
    v = nv;
  }
}

// RK4 stage s (0..3) is evaluated at y_s = y0 + c_s k_{s-1}, c = (0, dt/2, dt/2, dt).
KFN precise real rk4_c(uint stage, real dt) {
  precise real c = stage == 0u ? real(0) : (stage < 3u ? dt / real(2) : dt);
  return c;
}
KFN precise vec3 rk4_stage_point(vec3 y0, vec3 k_prev, real c) {
  precise vec3 y = y0 + k_prev * c;
  return y;
}
// The stage's derivative (k_pos, k_vel) = (v, F / m) after contacts; zero for a pinned particle.
KFN void rk4_derivative(VARYING(bool) pinned, vec3 v, vec3 f, real m, OUT(vec3) k_pos, OUT(vec3) k_vel) {
  precise vec3 a = f / m; // a pinned particle may have no mass: its a is not used
  k_pos = select(pinned, vec3(real(0)), v);
  k_vel = select(pinned, vec3(real(0)), a);
}
// Running sum k1 + 2 k2 + 2 k3 + k4, one stage at a time (same order as summing at the end).
KFN precise vec3 rk4_accumulate(uint stage, vec3 sum, vec3 k) {
  precise vec3 s = stage == 0u ? k : (stage < 3u ? sum + k * real(2) : sum + k);
  return s;
}
// y1 = y0 + (dt / 6) (k1 + 2 k2 + 2 k3 + k4).
KFN precise vec3 rk4_finish(vec3 y0, vec3 sum, real dt_over_6) {
  precise vec3 y = y0 + sum * dt_over_6;
  return y;
}

// ---- Divergence (docs/model.md "Divergence") -------------------------------------------

// A particle has diverged when a component of x or v is NaN or inf, or |x_i| > limit.
KFN VARYING(bool) diverged(vec3 x, vec3 v, real limit) {
  return !all_finite(x) || !all_finite(v) || abs(x.x) > limit || abs(x.y) > limit || abs(x.z) > limit;
}
