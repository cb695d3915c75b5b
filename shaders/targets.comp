// SPDX-License-Identifier: MIT
#version 450
#extension GL_GOOGLE_include_directive : require
// vkcloth-builds: one workgroup-constant (shaders/CMakeLists.txt)
// Attachments and motion constraints (CpuSolver drive_targets / hold_targets; the formulas:
// cloth_kernel.h attach.h drive_pinned, hold_within). One invocation per entry of the instance's
// targets (TARGETS[inst * count ..], the first pc.target_count uploaded before each substep; no
// particle has two), so each writes only its own particle. SC_STAGE VKCLOTH_TARGETS_DRIVE, before
// the substep's update:
// pinned particles onto their targets in positions[read] (POS_BASE) with the target's velocity.
// VKCLOTH_TARGETS_HOLD, after the substep's last pass: free particles back within reach in
// positions[write] (POS_OUT). The cloth's frame (docs/model.md "Inertia and teleport"), one
// invocation per particle, FRAMES[inst] uploaded before the substep: VKCLOTH_FRAME_JUMP, first,
// every particle moved by the frame's jump in positions[read]; VKCLOTH_FRAME_CARRY, last, free
// particles carried with the frame (from positions[read] to positions[write]).
#include "kernel/layout/vkcloth_shared.h"
#define VKCLOTH_PUSH_STRUCT TargetsPush
#include "common.glsl"

layout(std430, set = 0, binding = VKCLOTH_BINDING_POS_BASE) buffer PosBase { vec4 pos_base[]; };
layout(std430, set = 0, binding = VKCLOTH_BINDING_POS_OUT) buffer PosOut { vec4 pos_out[]; };
layout(std430, set = 0, binding = VKCLOTH_BINDING_VEL) buffer VelBuf { vec4 vel[]; };
layout(std430, set = 0, binding = VKCLOTH_BINDING_TARGETS) readonly buffer TargetBuf { Target targets[]; };
layout(std430, set = 0, binding = VKCLOTH_BINDING_FRAMES) readonly buffer FrameBuf { FrameMotion frames[]; };

void frame_pass(uint stage) {
  const uint p = particle_index();
  if (p >= pc.count || frozen())
    return;
  const FrameMotion f = frames[inst];
  const uint g = base + p;
  if (stage == VKCLOTH_FRAME_JUMP) {
    if (f.jump == 0u)
      return;
    vec3 x = pos_base[g].xyz, v = vel[g].xyz;
    rigid_jump(f.row0.xyz, f.row1.xyz, f.row2.xyz, vec3(f.row0.w, f.row1.w, f.row2.w), x, v);
    pos_base[g] = vec4(x, 1.0);
    vel[g] = vec4(v, 0.0);
    return;
  }
  if (f.carry == 0u || particle[p].pinned != 0u)
    return;
  const vec3 carried = carried_velocity(pos_base[g].xyz, pos_out[g].xyz, f.dv.xyz, f.omega0.xyz, f.omega1.xyz,
                                        f.c0.xyz, f.c1.xyz, f.dv.w, f.omega0.w);
  vel[g] = vec4(vel[g].xyz + carried, 0.0);
}

void main() {
  begin_instance();
  if (pass_stage() >= VKCLOTH_FRAME_JUMP) {
    frame_pass(pass_stage());
    return;
  }
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
