// SPDX-License-Identifier: MIT
#version 450
#extension GL_GOOGLE_include_directive : require
// vkcloth-builds: one workgroup-constant (shaders/CMakeLists.txt)
// Vertex block descent (Integrator::vbd), the phases of CpuSolver's vbd.cpp in the same order, each
// formula from cloth_kernel.h (vbd.h); one pipeline per phase (SC_STAGE, VKCLOTH_VBD_*):
//   BEGIN:  one invocation per particle: the normal at the substep's start (particle_normal, as the
//           CPU's normal_at), the inertia target y -> VEL_FILT, the first guess x0 + h v0
//           projected out of the colliders -> POS_OUT, no push yet -> STAGE_POS;
//   SOLVE:  one invocation per particle of one colour (VBD_ORDER[colour_first ..]): one Newton step
//           (springs, self-contact when VbdPush::contact, inertia, friction) from the neighbours' latest positions in
//           POS_OUT, projected; writes its own POS_OUT entry and its push. No two particles of a
//           colour share a spring, so no invocation reads what another writes;
//   FINISH: one invocation per particle: the last sweep's x; v = (x - x0) / h before the last
//           projection, less its inward part (the contact response without friction); projection
//           and divergence flags (finish.glsl), the net force.
// Reads POS_IN (= POS_BASE: positions[read], the start), VEL; writes POS_OUT, VEL, NORMAL, FORCE_OUT.
#include "kernel/layout/vkcloth_shared.h"
#define VKCLOTH_PUSH_STRUCT VbdPush
#include "common.glsl"
#include "force_body.glsl"

layout(std430, set = 0, binding = VKCLOTH_BINDING_FORCE_OUT) writeonly buffer ForceOut { vec4 force_out[]; };
layout(std430, set = 0, binding = VKCLOTH_BINDING_NORMAL) writeonly buffer NormalOut { vec4 normal_out[]; };
layout(std430, set = 0, binding = VKCLOTH_BINDING_POS_OUT) buffer PosOut { vec4 pos_out[]; };
layout(std430, set = 0, binding = VKCLOTH_BINDING_VEL) buffer VelBuf { vec4 vel[]; };
layout(std430, set = 0, binding = VKCLOTH_BINDING_VEL_FILT) buffer TargetBuf { vec4 target[]; };
layout(std430, set = 0, binding = VKCLOTH_BINDING_STAGE_POS) buffer PushBuf { vec4 push_of[]; };
layout(std430, set = 0, binding = VKCLOTH_BINDING_VBD_ORDER) readonly buffer OrderBuf { uint vbd_order[]; };
// Self-contact's force and stiffness block from the sweep's start (self_collision.comp CONTACT).
layout(std430, set = 0, binding = VKCLOTH_BINDING_ACC_POS) readonly buffer ContactF { vec4 contact_f[]; };
layout(std430, set = 0, binding = VKCLOTH_BINDING_ACC_VEL) readonly buffer ContactDiag { vec4 contact_diag[]; };
layout(std430, set = 0, binding = VKCLOTH_BINDING_STAGE_VEL) readonly buffer ContactOff { vec4 contact_off[]; };

#include "finish.glsl"

// Particle g's position projected out of every collider (side: where it started the substep).
vec3 projected(uint g, vec3 side, vec3 x) {
  vec3 v = vec3(0.0);
  for (uint c = 0u; c < (SC_COLLIDERS ? ip.collider_count : 0u); ++c)
    project_out(g, collider_shape(c), ip.eps, side, x, v);
  return x;
}

void begin(uint p, uint g, bool pinned) {
  const vec3 v0 = vel[g].xyz;
  const vec3 nrm = particle_normal(p);
  normal_out[g] = normal_output(nrm);
  const vec3 x0 = read_pos_in(p);
  const float m = read_particle(p).mass;
  const vec3 f_ext = add_body_forces(vec3(0.0), m, vec3(0.0), ip.gravity_damping.xyz, 0.0,
                                     (ip.flags & VKCLOTH_FLAG_WIND) != 0u, nrm, ip.wind.xyz, ip.wind.w);
  const vec3 y = pinned ? x0 : vbd_inertia_target(x0, v0, f_ext, m, ip.dt);
  target[g] = vec4(y, 0.0);
  const vec3 guess = vbd_first_guess(x0, v0, ip.dt);
  push_of[g] = vec4(0.0);
  pos_out[g] = vec4(pinned ? x0 : projected(g, x0, guess), 1.0);
}

void solve(uint p, uint g) {
  const vec3 x = pos_out[g].xyz;
  vec3 f = vec3(0.0);
  SpringBlock hessian = zero_block();
  const uvec3 range = read_list_range(p);
  for (uint e = range.x; e < range.z; ++e) {
    const Edge s = read_edge(e);
    vbd_add_spring(f, hessian, pos_out[base + s.other].xyz - x, s.rest_length, s.stiffness);
  }
  if (pc.contact != 0u) {
    SpringBlock hc;
    hc.diag = contact_diag[g].xyz;
    hc.off = contact_off[g].xyz;
    vbd_add_contact(f, hessian, contact_f[g].xyz, hc);
  }
  const vec3 x0 = read_pos_in(p);
  const float m = read_particle(p).mass;
  vec3 stepped = vbd_step(x, target[g].xyz, x0, f, hessian, m, ip.dt, ip.gravity_damping.w);
  const float inertia = vbd_inertia_weight(m, ip.dt, ip.gravity_damping.w);
  for (uint c = 0u; c < (SC_COLLIDERS ? ip.collider_count : 0u); ++c)
    vbd_friction(stepped, g, collider_shape(c), x, x0, hessian, inertia, ip.band, ip.dt);
  const vec3 x1 = projected(g, x0, stepped);
  push_of[g] = vec4(x1 - stepped, 0.0);
  pos_out[g] = vec4(x1, 1.0);
}

void finish_step(uint p, uint g, bool pinned) {
  const vec3 x0 = read_pos_in(p);
  const vec3 v0 = vel[g].xyz;
  if (pinned) {
    force_out[g] = vec4(0.0);
    finish(p, true, x0, x0, v0); // stays put with its velocity
    return;
  }
  const float m = read_particle(p).mass;
  const float h = ip.dt;
  const vec3 x = pos_out[g].xyz;
  vec3 v = vbd_velocity(x, push_of[g].xyz, x0, h);
  vec3 no_force = vec3(0.0);
  const bool both = (ip.flags & VKCLOTH_FLAG_CONTACT_BOTH) != 0u;
  precise float h_over_m = h / m;
  for (uint c = 0u; c < (SC_COLLIDERS ? ip.collider_count : 0u); ++c) {
    ColliderShape s = without_friction(collider_shape(c)); // friction acted in the sweeps
    float dist;
    vec3 n, deform;
    collider_contact(g, s, x, x, ip.band, dist, n, deform);
    contact_response(v, no_force, s, x, n, dist, ip.band, both, h_over_m, deform);
  }
  force_out[g] = vec4(vbd_net_force(v, v0, m, h), 0.0);
  finish(p, false, x0, x, v);
}

void main() {
  begin_instance();
  const uint stage = pass_stage();
  uint p = particle_index();
  if (stage == VKCLOTH_VBD_SOLVE) {
    if (p >= pc.colour_count) return;
    p = vbd_order[pc.colour_first + p];
  } else if (p >= pc.count) {
    return;
  }
  const uint g = base + p;
  const bool pinned = read_particle(p).pinned != 0u;
  const bool fr = frozen();
  if (stage == VKCLOTH_VBD_BEGIN) {
    if (fr) pos_out[g] = vec4(read_pos_in(p), 1.0);
    else begin(p, g, pinned);
  } else if (stage == VKCLOTH_VBD_SOLVE) {
    if (!pinned && !fr) solve(p, g);
  } else {
    finish_step(p, g, pinned || fr);
  }
}
