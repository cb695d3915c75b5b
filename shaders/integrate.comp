// SPDX-License-Identifier: MIT
#version 450
#extension GL_GOOGLE_include_directive : require
// vkcloth-builds: texel-and-storage workgroup-constant (shaders/CMakeLists.txt)
// Integration pass, one invocation per particle (the CPU reference's update after the forces,
// then projection and the divergence check; formulas from cloth_kernel.h). Euler: one pass per
// step. RK4: one pass per stage;
// stages 0..2 write the next stage's (STAGE_POS, STAGE_VEL) and the running sums, stage 3
// writes the new state. Reads FORCE_OUT, VEL_FILT (own), POS_BASE, VEL; writes POS_OUT, VEL.
#include "kernel/layout/vkcloth_shared.h"
#define VKCLOTH_PC_COPY
#include "common.glsl"

layout(std430, set = 0, binding = VKCLOTH_BINDING_FORCE_OUT) readonly buffer ForceIn { vec4 force_in[]; };
layout(std430, set = 0, binding = VKCLOTH_BINDING_VEL_FILT) readonly buffer VelFilt { vec4 vel_filt[]; };
layout(std430, set = 0, binding = VKCLOTH_BINDING_POS_BASE) readonly buffer PosBase { vec4 pos_base[]; };
layout(std430, set = 0, binding = VKCLOTH_BINDING_POS_OUT) writeonly buffer PosOut { vec4 pos_out[]; };
layout(std430, set = 0, binding = VKCLOTH_BINDING_VEL) buffer VelBuf { vec4 vel[]; };
layout(std430, set = 0, binding = VKCLOTH_BINDING_STAGE_POS) writeonly buffer StagePos { vec4 stage_pos[]; };
layout(std430, set = 0, binding = VKCLOTH_BINDING_STAGE_VEL) writeonly buffer StageVel { vec4 stage_vel[]; };
layout(std430, set = 0, binding = VKCLOTH_BINDING_ACC_POS) buffer AccPos { vec4 acc_pos[]; };
layout(std430, set = 0, binding = VKCLOTH_BINDING_ACC_VEL) buffer AccVel { vec4 acc_vel[]; };

#include "finish.glsl"

void main() {
  begin_instance();
  const uint p = particle_index();
  if (p >= pc.count) return;
  const uint g = base + p; // this particle's entry in the state buffers
  const bool last = ip.integrator != VKCLOTH_INTEGRATOR_RK4 || pc.stage == 3u;
  if (frozen()) {
    if (last) pos_out[g] = pos_base[g]; // keep the frozen state in the buffer that becomes current
    return;
  }
  const bool pinned = particle[p].pinned != 0u;
  const float m = particle[p].mass;
  const vec3 x0 = pos_base[g].xyz; // positions at the start of the step
  const vec3 f = force_in[g].xyz;
  const vec3 vf = vel_filt[g].xyz;

  if (ip.integrator != VKCLOTH_INTEGRATOR_RK4) {
    vec3 x = x0;
    vec3 v = vf;
    if (!pinned) euler_update(ip.integrator == VKCLOTH_INTEGRATOR_SEMI_IMPLICIT_EULER, x, v, f, m, ip.dt);
    finish(p, pinned, x0, x, v);
    return;
  }

  // RK4 stage k: its derivative (cloth_kernel.h rk4_derivative).
  vec3 kp, kv;
  rk4_derivative(pinned, vf, f, m, kp, kv);
  const vec3 sp = rk4_accumulate(pc.stage, pc.stage == 0u ? vec3(0.0) : acc_pos[g].xyz, kp);
  const vec3 sv = rk4_accumulate(pc.stage, pc.stage == 0u ? vec3(0.0) : acc_vel[g].xyz, kv);
  const vec3 v0 = vel[g].xyz;
  if (pc.stage < 3u) { // the running sums and the next stage's point y0 + c_{k+1} k_k
    const float c_next = rk4_c(pc.stage + 1u, ip.dt);
    acc_pos[g] = vec4(sp, 0.0);
    acc_vel[g] = vec4(sv, 0.0);
    stage_pos[g] = vec4(rk4_stage_point(x0, kp, c_next), 1.0);
    stage_vel[g] = vec4(rk4_stage_point(v0, kv, c_next), 0.0);
    return;
  }
  vec3 x = x0;
  vec3 v = v0;
  if (!pinned) {
    x = rk4_finish(x0, sp, ip.w6);
    v = rk4_finish(v0, sv, ip.w6);
  }
  finish(p, pinned, x0, x, v);
}
