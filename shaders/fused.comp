// SPDX-License-Identifier: MIT
#version 450
#extension GL_GOOGLE_include_directive : require
// Fused Euler step, one invocation per particle of every instance of the batch, one dispatch per
// step (GpuSolverOptions::fused): the force pass (force_body.glsl: normal rebuilt from the neighbours' POS_IN, spring gather,
// contacts) followed by the Euler update and projection (finish.glsl) in registers. Valid in one
// dispatch because positions are ping-ponged (every invocation reads POS_IN = positions[read] and
// writes only its own POS_OUT = positions[write]) and the velocity is read and written only by its
// own invocation. Removes the force / filtered-velocity round trip through memory and one barrier
// per step. Same float expressions, in the same order, as force.comp + integrate.comp.
// Reads POS_IN (all), VEL (own); writes POS_OUT, VEL (own), and FORCE_OUT, NORMAL (own) in the
// last substep of a recorded batch (SC_WRITE_AUX).
#include "vkcloth_shared.h"
#define VKCLOTH_PC_COPY
#include "common.glsl"
#include "force_body.glsl"

layout(std430, set = 0, binding = VKCLOTH_BINDING_FORCE_OUT) writeonly buffer ForceOut { vec4 force_out[]; };
layout(std430, set = 0, binding = VKCLOTH_BINDING_NORMAL) writeonly buffer NormalOut { vec4 normal_out[]; };
layout(std430, set = 0, binding = VKCLOTH_BINDING_POS_OUT) writeonly buffer PosOut { vec4 pos_out[]; };
layout(std430, set = 0, binding = VKCLOTH_BINDING_VEL) buffer VelBuf { vec4 vel[]; };

#include "finish.glsl"

// False for every substep of a recorded batch but the last (GpuSolver fused_pipes[0][*]): the
// forces and normals of the other substeps are overwritten before anyone can read them, and
// llvmpipe pays a per-lane scalar loop for each of these stores.
layout(constant_id = 40) const bool SC_WRITE_AUX = true;

// The state velocity and the flags word read through texel views of VEL and FLAGS (set 1), like
// the positions (force_body.glsl pos_at): on llvmpipe an SSBO load is a per-lane loop even at a
// constant offset. Each invocation reads its own velocity before it stores it, and any flags value
// this dispatch can see gives the same frozen() answer (older steps' values are visible through
// the barrier; this step's own writes are >= pc.step). The *_storage build loads them from VEL and
// FLAGS themselves.
#ifdef VKCLOTH_TEXEL_VIEWS
layout(set = 1, binding = VKCLOTH_TEXEL_BINDING_VEL) uniform samplerBuffer vel_texel;
layout(set = 1, binding = VKCLOTH_TEXEL_BINDING_FLAGS) uniform usamplerBuffer flags_texel;
vec3 vel_now(uint g) { return texelFetch(vel_texel, int(g)).xyz; }
bool frozen_now() { return texelFetch(flags_texel, int(inst * 4u + 1u)).x < pc.step; }
#else
vec3 vel_now(uint g) { return vel[g].xyz; }
bool frozen_now() { return frozen(); }
#endif

void main() {
  begin_instance();
  const uint p = particle_index();
  if (p >= pc.count) return;
  const uint g = base + p; // this particle's entry in the state buffers
  // A frozen step (after a divergence) writes back the state it read through the same stores as a
  // live step (keeps it in the buffer that becomes current): llvmpipe runs every branch, so a
  // separate copy cost a masked per-lane load and store loop in every step. finish() re-checks the
  // frozen state, which is the bad step's output: the same particles, no flag changes.
  // frozen(): Flags[inst].first_bad_step (4 words per Flags) < this step
  const bool fr = frozen_now();
  const vec3 v0 = vel_now(g);
  vec3 vf = v0;
  vec3 f, nrm;
  particle_force(p, vf, f, nrm);
  if (SC_WRITE_AUX && !fr) {
    force_out[g] = vec4(f, 0.0);
    normal_out[g] = normal_output(nrm);
  }

  const bool pinned = pinned_at(p);
  const vec3 x0 = pos_at(p);
  vec3 x = x0;
  vec3 v = vf;
  if (!pinned && !fr)
    euler_update(ip.integrator == VKCLOTH_INTEGRATOR_SEMI_IMPLICIT_EULER, x, v, f, mass_at(p), ip.dt);
  if (fr) v = v0;
  finish(p, pinned || fr, x0, x, v);
}
