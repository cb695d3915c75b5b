// SPDX-License-Identifier: MIT
#version 450
#extension GL_GOOGLE_include_directive : require
// vkcloth-builds: one workgroup-constant (shaders/CMakeLists.txt)
// Attachments and motion constraints (CpuSolver drive_targets / hold_targets; the formulas:
// cloth_kernel.h attach.h drive_pinned, hold_within). One invocation per entry of the instance's
// targets (TARGETS[inst * count ..], the first pc.target_count uploaded before each substep; no
// particle has two), so each
// writes only its own particle. SC_STAGE VKCLOTH_TARGETS_DRIVE, before the substep's update:
// pinned particles onto their targets in positions[read] (POS_BASE) with the target's velocity.
// VKCLOTH_TARGETS_HOLD, after the substep's last pass: free particles back within reach in
// positions[write] (POS_OUT).
#include "vkcloth_shared.h"
#define VKCLOTH_PUSH_STRUCT TargetsPush
#include "common.glsl"

layout(std430, set = 0, binding = VKCLOTH_BINDING_POS_BASE) buffer PosBase { vec4 pos_base[]; };
layout(std430, set = 0, binding = VKCLOTH_BINDING_POS_OUT) buffer PosOut { vec4 pos_out[]; };
layout(std430, set = 0, binding = VKCLOTH_BINDING_VEL) buffer VelBuf { vec4 vel[]; };
layout(std430, set = 0, binding = VKCLOTH_BINDING_TARGETS) readonly buffer TargetBuf { Target targets[]; };

void main() {
  begin_instance();
  const uint k = particle_index();
  if (k >= pc.target_count || frozen())
    return;
  const Target t = targets[base + k];
  if (t.particle == VKCLOTH_NO_TARGET)
    return;
  const uint g = base + t.particle;
  const bool pinned = particle[t.particle].pinned != 0u;
  const vec3 target = vec3(t.px, t.py, t.pz);
  const vec3 target_velocity = vec3(t.vx, t.vy, t.vz);
  if (pass_stage() == VKCLOTH_TARGETS_DRIVE) {
    if (!pinned)
      return;
    vec3 x, v;
    drive_pinned(target, target_velocity, x, v);
    pos_base[g] = vec4(x, 1.0);
    vel[g] = vec4(v, 0.0);
  } else {
    if (pinned)
      return;
    vec3 x = pos_out[g].xyz, v = vel[g].xyz;
    if (hold_within(target, target_velocity, t.reach, x, v)) {
      pos_out[g] = vec4(x, 1.0);
      vel[g] = vec4(v, 0.0);
    }
  }
}
