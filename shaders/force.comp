// SPDX-License-Identifier: MIT
#version 450
#extension GL_GOOGLE_include_directive : require
// vkcloth-builds: texel-and-storage workgroup-constant (shaders/CMakeLists.txt)
// Force pass of the two-pass layout, one invocation per particle (CpuSolver::normal_at, force_at
// and contact_at for one particle; the body is in force_body.glsl, shared with fused.comp).
// Reads POS_IN (all particles) and VEL_IN (own); writes FORCE_OUT, VEL_FILT, NORMAL (own).
#include "kernel/layout/vkcloth_shared.h"
#define VKCLOTH_PC_COPY
#include "common.glsl"
#include "force_body.glsl"

layout(std430, set = 0, binding = VKCLOTH_BINDING_VEL_IN) readonly buffer VelIn { vec4 vel_in[]; };
layout(std430, set = 0, binding = VKCLOTH_BINDING_FORCE_OUT) writeonly buffer ForceOut { vec4 force_out[]; };
layout(std430, set = 0, binding = VKCLOTH_BINDING_VEL_FILT) writeonly buffer VelFilt { vec4 vel_filt[]; };
layout(std430, set = 0, binding = VKCLOTH_BINDING_NORMAL) writeonly buffer NormalOut { vec4 normal_out[]; };

void main() {
  begin_instance();
  const uint p = particle_index();
  if (p >= pc.count || frozen()) return;
  const uint g = base + p; // this particle's entry in the state buffers
  vec3 v = vel_in[g].xyz;
  vec3 f, nrm;
  particle_force(p, v, f, nrm);
  force_out[g] = vec4(f, 0.0);
  vel_filt[g] = vec4(v, 0.0);
  normal_out[g] = normal_output(nrm);
}
