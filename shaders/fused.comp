// SPDX-License-Identifier: MIT
#version 450
#extension GL_GOOGLE_include_directive : require
// vkcloth-builds: texel-and-storage workgroup-constant (shaders/CMakeLists.txt)
// Fused Euler step, one invocation per particle of every instance of the batch, one dispatch per
// step (GpuSolverOptions::fused): the force pass (force_body.glsl: normal rebuilt from the neighbours' POS_IN, spring gather,
// contacts) followed by the Euler update and projection (finish.glsl) in registers. Valid in one
// dispatch because positions are ping-ponged (every invocation reads POS_IN = positions[read] and
// writes only its own POS_OUT = positions[write]) and the velocity is read and written only by its
// own invocation. Removes the force / filtered-velocity round trip through memory and one barrier
// per step. Same float expressions, in the same order, as force.comp + integrate.comp.
// Reads POS_IN (all), VEL (own); writes POS_OUT, VEL (own), and FORCE_OUT, NORMAL (own) in the
// last substep of a recorded batch (SC_WRITE_AUX).
#include "kernel/layout/vkcloth_shared.h"
#define VKCLOTH_PC_COPY
#include "common.glsl"
#include "force_body.glsl"

layout(std430, set = 0, binding = VKCLOTH_BINDING_FORCE_OUT) writeonly buffer ForceOut { vec4 force_out[]; };
layout(std430, set = 0, binding = VKCLOTH_BINDING_NORMAL) writeonly buffer NormalOut { vec4 normal_out[]; };
layout(std430, set = 0, binding = VKCLOTH_BINDING_POS_OUT) writeonly buffer PosOut { vec4 pos_out[]; };
layout(std430, set = 0, binding = VKCLOTH_BINDING_VEL) buffer VelBuf { vec4 vel[]; };

#include "finish.glsl"

// False for every substep of a recorded batch but the last (passes/explicit_update.cpp fused_[0][*]): the
// forces and normals of the other substeps are overwritten before anyone can read them, so they
// are not stored (docs/performance.md "lavapipe (llvmpipe) notes").
layout(constant_id = 40) const bool SC_WRITE_AUX = true;

// read_velocity, read_frozen: the state velocity (each invocation reads its own before it stores
// it) and the flags word.
#define VKCLOTH_ACCESS_VEL_FLAGS
#include "buffer_access.glsl"

void main() {
  begin_instance();
  const uint p = particle_index();
  if (p >= pc.count) return;
  const uint g = base + p; // this particle's entry in the state buffers
  // A frozen step (after a divergence) writes back the state it read through the same stores as a
  // live step (keeps it in the buffer that becomes current; not a separate copy: docs/performance.md
  // "lavapipe (llvmpipe) notes"). finish() re-checks the frozen state, which is the bad step's
  // output: the same particles, no flag changes.
  const bool fr = read_frozen();
  const vec3 v0 = read_velocity(p);
  vec3 vf = v0;
  vec3 f, nrm;
  particle_force(p, vf, f, nrm);
  if (SC_WRITE_AUX && !fr) {
    force_out[g] = vec4(f, 0.0);
    normal_out[g] = normal_output(nrm);
  }

  const bool pinned = read_particle(p).pinned != 0u;
  const vec3 x0 = read_pos_in(p);
  vec3 x = x0;
  vec3 v = vf;
  if (!pinned && !fr) {
    const float m = read_particle(p).mass;
    euler_update(ip.integrator == VKCLOTH_INTEGRATOR_SEMI_IMPLICIT_EULER, x, v, f, m, ip.dt);
  }
  if (fr) v = v0;
  finish(p, pinned || fr, x0, x, v);
}
