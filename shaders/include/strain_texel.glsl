// SPDX-License-Identifier: MIT
// What strain_links.comp and strain_finish.comp read through set 1's texel views in their *_texel
// builds (llvmpipe turns an SSBO load into a per-lane loop, a texel fetch into one gather;
// force_body.glsl), or from set 0's storage buffers in their *_storage builds: set 1 is
// the one of the positions being WRITTEN this substep (SolverBatch::record_stretch), so POS_IN's
// view shows positions[write]. Within one pass no invocation reads what another writes (a
// colour's links share no particle; tether anchors are pinned and never written).
#ifndef VKCLOTH_STRAIN_TEXEL_GLSL
#define VKCLOTH_STRAIN_TEXEL_GLSL

#ifdef VKCLOTH_TEXEL_VIEWS
layout(set = 1, binding = VKCLOTH_TEXEL_BINDING_POS_IN) uniform samplerBuffer pos_now_texel;
layout(set = 1, binding = VKCLOTH_TEXEL_BINDING_VEL) uniform samplerBuffer vel_texel;
layout(set = 1, binding = VKCLOTH_TEXEL_BINDING_PARTICLE) uniform usamplerBuffer particle_texel;
layout(set = 1, binding = VKCLOTH_TEXEL_BINDING_FLAGS) uniform usamplerBuffer flags_texel;

layout(std430, set = 0, binding = VKCLOTH_BINDING_POS_OUT) writeonly buffer PosOut { vec4 pos_out[]; };
layout(std430, set = 0, binding = VKCLOTH_BINDING_VEL) writeonly buffer VelBuf { vec4 vel[]; };

vec3 pos_now(uint q) { return texelFetch(pos_now_texel, int(base + q)).xyz; }
vec3 vel_now(uint q) { return texelFetch(vel_texel, int(base + q)).xyz; }
bool pinned_at(uint p) { return texelFetch(particle_texel, int(p)).y != 0u; }
// frozen() through the flags' view: Flags[inst].first_bad_step (4 words per Flags) < this step.
bool frozen_now() { return texelFetch(flags_texel, int(inst * 4u + 1u)).x < pc.step; }
#else
// The *_storage builds: the same values from the storage buffers of set 0 (POS_OUT is
// positions[write], the buffer the texel builds read through set 1).
layout(std430, set = 0, binding = VKCLOTH_BINDING_POS_OUT) buffer PosOut { vec4 pos_out[]; };
layout(std430, set = 0, binding = VKCLOTH_BINDING_VEL) buffer VelBuf { vec4 vel[]; };

vec3 pos_now(uint q) { return pos_out[base + q].xyz; }
vec3 vel_now(uint q) { return vel[base + q].xyz; }
bool pinned_at(uint p) { return particle[p].pinned != 0u; }
bool frozen_now() { return frozen(); }
#endif

#endif
