// SPDX-License-Identifier: MIT
#version 450
#extension GL_GOOGLE_include_directive : require
// vkcloth-builds: one (shaders/CMakeLists.txt)
// Implicit Euler passes (engine/src/core/implicit_euler.hpp for the method), one invocation per
// particle; PushConstants::stage selects the pass (VKCLOTH_IMPL_*). The reducing passes write one
// partial dot-product vec4 per workgroup (fixed-shape shared-memory tree), and the last workgroup
// to finish sums them in a fixed order (finish_reduction): deterministic, but not the CPU's
// sequential order; no dispatch of its own. VKCLOTH_IMPL_SOLVE instead runs many CG iterations in ONE workgroup (each
// invocation strides over the particles; workgroup barriers between the phases), for systems
// small enough that the dispatches of the per-iteration passes cost more than their work.
#define VKCLOTH_FRICTION_AFTER_SOLVE // force_body.glsl: friction once, in the FINISH pass
#include "kernel/layout/implicit_shared.h"
#define VKCLOTH_PUSH_STRUCT ImplicitPush
#include "common.glsl"
#include "force_body.glsl"

layout(std430, set = 0, binding = VKCLOTH_BINDING_FORCE_OUT) buffer ForceOut { vec4 force_out[]; }; // FORCE -> SYSTEM
layout(std430, set = 0, binding = VKCLOTH_BINDING_NORMAL) writeonly buffer NormalOut { vec4 normal_out[]; };
layout(std430, set = 0, binding = VKCLOTH_BINDING_POS_OUT) writeonly buffer PosOut { vec4 pos_out[]; };
layout(std430, set = 0, binding = VKCLOTH_BINDING_VEL) buffer VelBuf { vec4 vel[]; };
layout(std430, set = 0, binding = VKCLOTH_BINDING_IMPL_VF) buffer VfBuf { vec4 vf[]; };
layout(std430, set = 0, binding = VKCLOTH_BINDING_IMPL_KS) buffer KsBuf { vec4 ks[]; };
layout(std430, set = 0, binding = VKCLOTH_BINDING_IMPL_BLOCK_INV) buffer BlockInvBuf { vec4 block_inv[]; };
layout(std430, set = 0, binding = VKCLOTH_BINDING_IMPL_X) buffer XBuf { vec4 cx[]; };
layout(std430, set = 0, binding = VKCLOTH_BINDING_IMPL_R) buffer RBuf { vec4 cr[]; };
layout(std430, set = 0, binding = VKCLOTH_BINDING_IMPL_Z) buffer ZBuf { vec4 cz[]; };
layout(std430, set = 0, binding = VKCLOTH_BINDING_IMPL_D) coherent buffer DBuf { vec4 cd[]; }; // SOLVE: read by neighbours
layout(std430, set = 0, binding = VKCLOTH_BINDING_IMPL_Q) buffer QBuf { vec4 cq[]; };
// partials and cg: read and written across workgroups within one dispatch (finish_reduction).
layout(std430, set = 0, binding = VKCLOTH_BINDING_IMPL_PARTIALS) coherent buffer PartialBuf { vec4 partials[]; };
layout(std430, set = 0, binding = VKCLOTH_BINDING_IMPL_STATE) coherent buffer StateBuf { CgState cg; };
layout(std430, set = 0, binding = VKCLOTH_BINDING_IMPL_ARGS) writeonly buffer ArgBuf { CgArgs args; };

#include "finish.glsl"

shared vec4 red[VKCLOTH_WORKGROUP_SIZE];
shared bool last_to_arrive;

// Fixed-shape tree over the workgroup, the sum left in red[0]; every invocation must call it
// (uniform control flow).
void workgroup_tree(vec4 value) {
  const uint l = gl_LocalInvocationID.x;
  red[l] = value;
  barrier();
  for (uint s = VKCLOTH_WORKGROUP_SIZE / 2; s > 0u; s >>= 1) {
    if (l < s) {
      precise vec4 t = red[l] + red[l + s];
      red[l] = t;
    }
    barrier();
  }
}
void workgroup_partial(vec4 value) {
  workgroup_tree(value);
  if (gl_LocalInvocationID.x == 0u) partials[gl_WorkGroupID.y * gl_NumWorkGroups.x + gl_WorkGroupID.x] = red[0];
}
// The workgroup's sum, to every invocation (the last barrier: everyone has read red[0] before the
// next call overwrites it).
vec4 workgroup_sum(vec4 value) {
  workgroup_tree(value);
  const vec4 s = red[0];
  barrier();
  return s;
}

// The end of a reducing pass (uniform control flow): this workgroup's partial, then the arrival
// count; the last workgroup to arrive sums every partial in a fixed order (invocation l adds
// partials l, l + 64, ..., then the tree: the order the separate reduce pass had) and updates the
// CG scalars and the indirect arguments of the next passes (zero groups once done). Its partial
// write is made visible before its arrival (memoryBarrierBuffer), and the last one reads the
// others' after seeing every arrival; the others have read cg before arriving.
void finish_reduction(vec4 part, uint pass) {
  const uint l = gl_LocalInvocationID.x;
  const uint groups = gl_NumWorkGroups.x * gl_NumWorkGroups.y;
  workgroup_partial(part);
  if (l == 0u) {
    memoryBarrierBuffer();
    last_to_arrive = atomicAdd(cg.arrived, 1u) + 1u == groups;
  }
  barrier();
  if (!last_to_arrive) return; // uniform within the workgroup
  memoryBarrierBuffer();
  precise vec4 acc = vec4(0.0);
  for (uint i = l; i < groups; i += VKCLOTH_WORKGROUP_SIZE) acc = acc + partials[i];
  const vec4 sum = workgroup_sum(acc);
  if (l != 0u) return;
  const float tol2 = pc.tolerance2;
  bool done = cg.done != 0u;
  if (pass == VKCLOTH_IMPL_SYSTEM) {
    cg.rz = sum.x;
    cg.rr = sum.y;
    cg.ref2 = max(sum.z, sum.w); // max(|S b|^2, |S h M g|^2): implicit_euler.hpp
    cg.alpha = 0.0;
    cg.beta = 0.0;
    cg.iterations = 0u;
    cg.solves = cg.solves + 1u;
    done = sum.y <= tol2 * cg.ref2;
  } else if (pass == VKCLOTH_IMPL_MATVEC) {
    if (!(sum.x > 0.0))
      done = true; // an SPD A gives d.q <= 0 only at d = 0
    else
      cg.alpha = cg.rz / sum.x;
  } else { // VKCLOTH_IMPL_UPDATE
    cg.beta = sum.x / cg.rz;
    cg.rz = sum.x;
    cg.rr = sum.y;
    cg.iterations = cg.iterations + 1u;
    cg.total_iterations = cg.total_iterations + 1u;
    done = sum.y <= tol2 * cg.ref2 || cg.iterations >= pc.cg_max_iterations;
  }
  cg.done = done ? 1u : 0u;
  cg.arrived = 0u; // for the next reducing pass
  args.particle_x = done ? 0u : cg.groups_x;
  args.particle_y = done ? 0u : cg.groups_y;
  args.particle_z = done ? 0u : 1u;
}

// Edge e's stiffness block and particle p's P^-1, stored as two vec4: (xx yy zz xy), (xz yz 0 0).
SpringBlock unpack_block(vec4 a, vec4 b) {
  SpringBlock s;
  s.diag = a.xyz;
  s.off = vec3(a.w, b.x, b.y);
  return s;
}
SpringBlock block_at(uint e) { return unpack_block(ks[2u * e], ks[2u * e + 1u]); }
SpringBlock precond_at(uint p) { return unpack_block(block_inv[2u * p], block_inv[2u * p + 1u]); }
void store_precond(uint p, SpringBlock s) {
  block_inv[2u * p] = vec4(s.diag, s.off.x);
  block_inv[2u * p + 1u] = vec4(s.off.y, s.off.z, 0.0, 0.0);
}

// Particle p's contact axis (cloth_kernel.h contact_axis), as the FORCE pass stored it once per
// solve; zero for a pinned or free particle.
vec3 axis_of(uint p) { return vf[2u * pc.count + p].xyz; }

// q = S A d for particle p (zero for a pinned one).
vec3 matvec_row(uint p, bool pinned, float mu_h, float h2) {
  precise vec3 q = vec3(0.0);
  if (!pinned) {
    const vec3 dp = cd[p].xyz;
    precise vec3 s = vec3(0.0);
    const uint end = offsets[p + 1];
    for (uint e = offsets[p]; e < end; ++e) s = s + apply_block(block_at(e), dp - cd[edges[e].other].xyz);
    q = constrain_to(implicit_row(dp, mu_h, particle[p].mass, s, h2), axis_of(p));
  }
  return q;
}

// x += alpha d, r -= alpha q, z = P^-1 r for particle p; returns (r.z, r.r, 0, 0).
vec4 update_row(uint p, float alpha) {
  precise vec3 x = cx[p].xyz + cd[p].xyz * alpha;
  precise vec3 r = cr[p].xyz - cq[p].xyz * alpha;
  const vec3 z = constrain_to(apply_block(precond_at(p), r), axis_of(p));
  cx[p] = vec4(x, 0.0);
  cr[p] = vec4(r, 0.0);
  cz[p] = vec4(z, 0.0);
  return vec4(dot3(r, z), dot3(r, r), 0.0, 0.0);
}

// VKCLOTH_IMPL_SOLVE: up to pc.solve_budget CG iterations of implicit_euler.hpp in ONE workgroup,
// continuing from CgState (SYSTEM's reduction starts each solve). The host bounds pc.solve_budget so that
// no invocation runs more than ~30 000 loop iterations per dispatch: llvmpipe (Mesa 22.3) ends
// any loop after 65 535 iterations of an invocation, silently.
// The sums: each invocation adds its particles in order, then the fixed tree. Control flow is
// uniform (every invocation computes the same scalars from red[0]); the loop has one exit, at
// the top. cd is the only array read across particles (neighbours' d in the matvec): written,
// then memoryBarrierBuffer + barrier before it is read.
void solve_in_one_workgroup(float mu_h, float h2) {
  const uint l = gl_LocalInvocationID.x;
  const uint n = pc.count;
  const float tol2 = pc.tolerance2;
  if (cg.done != 0u) return; // uniform: converged (or nothing to solve)
  float rz = cg.rz, rr = cg.rr;
  const float ref2 = cg.ref2;
  uint it = cg.iterations;
  const uint it_start = it;
  bool done = rr <= tol2 * ref2 || it >= pc.cg_max_iterations;
  uint budget = pc.solve_budget;
  while (!done && budget > 0u) {
    precise float dq_l = 0.0;
    for (uint p = l; p < n; p += VKCLOTH_WORKGROUP_SIZE) {
      const vec3 q = matvec_row(p, particle[p].pinned != 0u, mu_h, h2);
      cq[p] = vec4(q, 0.0);
      dq_l = dq_l + dot3(cd[p].xyz, q);
    }
    const float dq = workgroup_sum(vec4(dq_l, 0.0, 0.0, 0.0)).x;
    const bool descends = dq > 0.0; // else stop, as the CPU does (an SPD A: only at d = 0)
    const float alpha = descends ? rz / dq : 0.0;
    precise vec4 upd = vec4(0.0);
    if (descends)
      for (uint p = l; p < n; p += VKCLOTH_WORKGROUP_SIZE) upd = upd + update_row(p, alpha);
    const vec4 sums = workgroup_sum(upd);
    if (descends) {
      const float beta = sums.x / rz;
      rz = sums.x;
      rr = sums.y;
      ++it;
      for (uint p = l; p < n; p += VKCLOTH_WORKGROUP_SIZE) {
        precise vec3 d = cz[p].xyz + cd[p].xyz * beta;
        cd[p] = vec4(d, 0.0);
      }
    }
    done = !descends || rr <= tol2 * ref2 || it >= pc.cg_max_iterations;
    --budget;
    memoryBarrierBuffer(); // the new d, before the neighbours' matvec reads it
    barrier();             // (and every read of cg above, before invocation 0 rewrites it)
  }
  if (l == 0u) { // after the loop's barriers: every invocation has read cg above
    cg.rz = rz;
    cg.rr = rr;
    cg.iterations = it;
    cg.total_iterations = cg.total_iterations + (it - it_start);
    cg.done = done ? 1u : 0u;
  }
}

void main() {
  begin_instance(); // always instance 0: implicit passes run batches of one
  const uint p = particle_index();
  const bool live = p < pc.count;
  // One pipeline per mode (ImplicitGpu; why: docs/performance.md "lavapipe (llvmpipe) notes").
  const uint mode = pass_stage();
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
    vf[pc.count + p] = vec4(contact_removed_force, 0.0); // friction's impulse in FINISH
    const vec3 axis = particle[p].pinned != 0u
                          ? vec3(0.0)
                          : contact_axis(vel[p].xyz - v, contact_removed_force, ip.dt / particle[p].mass);
    vf[2u * pc.count + p] = vec4(axis, 0.0); // the CG passes' constraint (axis_of)
    // The warm start within this solve's contact constraint (SYSTEM reads the neighbours' cx).
    if (cg.solves != 0u)
      cx[p] = vec4(constrain_to(cx[p].xyz, axis), 0.0);
    return;
  }
  if (mode == VKCLOTH_IMPL_SYSTEM) {
    vec4 part = vec4(0.0); // frozen: no solve (zero sums: done), but the reduction still runs
    if (live && !frozen()) {
      const vec3 x = pos_in[p].xyz;
      const vec3 vp = vf[p].xyz;
      const bool warm = cg.solves != 0u; // else x is not written yet: x0 = 0
      const vec3 x0 = warm ? cx[p].xyz : vec3(0.0);
      if (!warm) cx[p] = vec4(0.0); // neighbours read cx only when warm: no race
      precise vec3 lv = vec3(0.0);
      precise vec3 lx = vec3(0.0);
      SpringBlock ksum = zero_block();
      const uint end = offsets[p + 1];
      for (uint e = offsets[p]; e < end; ++e) {
        const Edge s = edges[e];
        const SpringBlock k = spring_block(pos_in[s.other].xyz - x, s.rest_length, s.stiffness);
        ks[2u * e] = vec4(k.diag, k.off.x);
        ks[2u * e + 1u] = vec4(k.off.y, k.off.z, 0.0, 0.0);
        lv = lv + apply_block(k, vp - vf[s.other].xyz);
        lx = lx + apply_block(k, x0 - (warm ? cx[s.other].xyz : vec3(0.0)));
        add_block(ksum, k);
      }
      if (pinned) {
        store_precond(p, zero_block());
        cr[p] = cz[p] = cd[p] = vec4(0.0);
      } else {
        const float m = particle[p].mass;
        const vec3 a = axis_of(p);
        const SpringBlock pinv = invert_block(implicit_diagonal_block(mu_h, m, ksum, h2));
        const vec3 b = constrain_to(implicit_rhs(force_out[p].xyz, lv, h), a);
        const vec3 r = constrain_to(residual_of(b, implicit_row(x0, mu_h, m, lx, h2)), a);
        const vec3 z = constrain_to(apply_block(pinv, r), a);
        store_precond(p, pinv);
        cr[p] = vec4(r, 0.0);
        cz[p] = vec4(z, 0.0);
        cd[p] = vec4(z, 0.0);
        part = vec4(dot3(r, z), dot3(r, r), dot3(b, b), weight_impulse2(h, m, ip.gravity_damping.xyz));
      }
    }
    finish_reduction(part, VKCLOTH_IMPL_SYSTEM);
    return;
  }
  if (mode == VKCLOTH_IMPL_MATVEC) {
    vec4 part = vec4(0.0);
    if (live) {
      const vec3 q = matvec_row(p, pinned, mu_h, h2);
      cq[p] = vec4(q, 0.0);
      part = vec4(dot3(cd[p].xyz, q), 0.0, 0.0, 0.0);
    }
    finish_reduction(part, VKCLOTH_IMPL_MATVEC);
    return;
  }
  if (mode == VKCLOTH_IMPL_SOLVE) {
    solve_in_one_workgroup(mu_h, h2); // frozen: SYSTEM's reduction left done = 1
    return;
  }
  if (mode == VKCLOTH_IMPL_UPDATE) {
    vec4 part = vec4(0.0);
    if (live) part = update_row(p, cg.alpha);
    finish_reduction(part, VKCLOTH_IMPL_UPDATE);
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
    finish(p, true, x0, x0, vel[p].xyz);
    return;
  }
  precise vec3 v = vf[p].xyz + cx[p].xyz;
  const bool both = (ip.flags & VKCLOTH_FLAG_CONTACT_BOTH) != 0u;
  const float h_over_m = h / particle[p].mass;
  // The contact response on the new velocity, friction too: its normal impulse counts the force
  // the FORCE pass's filter removed, what one collider takes of it not counted again by the next
  // (CPU: implicit_update).
  vec3 removed = vf[pc.count + p].xyz;
  for (uint c = 0u; c < ip.collider_count; ++c) {
    const ColliderShape s = collider_shape(c);
    float dist;
    vec3 n, deform;
    collider_contact(base + p, s, x0, x0, ip.band, dist, n, deform);
    contact_response(v, removed, s, x0, n, dist, ip.band, both, h_over_m, deform);
  }
  precise vec3 x = x0 + v * h;
  finish(p, false, x0, x, v);
}
