// SPDX-License-Identifier: MIT
// What every compute shader shares: workgroup size, push constants, the instance's parameters,
// the topology and collider buffers, and the per-particle physics of cloth_kernel.h (the same
// source the CPU reference compiles as C++), so lavapipe reproduces the CPU bit for bit.
#ifndef VKCLOTH_COMMON_GLSL
#define VKCLOTH_COMMON_GLSL

#ifdef VKCLOTH_WORKGROUP_SPEC
// The workgroup size as a specialisation constant (DeviceLayout::workgroup_size; id 43,
// pipelines.hpp kWorkgroupSizeConstant), VKCLOTH_WORKGROUP_SIZE unless the host sets it. Nothing
// in these shaders sizes an array with it; implicit*.comp (shared-memory trees) keep the constant.
layout(local_size_x = VKCLOTH_WORKGROUP_SIZE, local_size_x_id = 43) in;
#else
layout(local_size_x = VKCLOTH_WORKGROUP_SIZE) in;
#endif

#ifdef VKCLOTH_PC_COPY
// The shader copies the push constants into `pc` before any branch (main: pc = pc_block): llvmpipe
// (Mesa 22.x) loads a push constant once and broadcasts it only outside control flow; inside a
// branch (everything after `if (p >= pc.count) return;`) it gathers it lane by lane.
layout(push_constant) uniform PushBlock { PushConstants pc_block; };
PushConstants pc;
#else
layout(push_constant) uniform PushBlock { PushConstants pc; };
#endif

// Bit t set: some instance of the batch may have a collider of type t (VKCLOTH_COLLIDER_*); 0: none
// has colliders (every ip.collider_count == 0), the contact loops compiled out. llvmpipe runs a
// loop body once even when no invocation enters it, per-lane collider loads included, and every
// branch of the kernel's switch over the shapes (collider_contact: VKCLOTH_COLLIDER_PRESENT), so
// the absent shapes' code is compiled out too (GpuSolver specialises fused.comp with the batch's
// types; the other shaders keep the default: every type).
layout(constant_id = 41) const uint SC_COLLIDER_TYPES = VKCLOTH_COLLIDER_ALL_TYPES;
const bool SC_COLLIDERS = SC_COLLIDER_TYPES != 0u;

layout(std430, set = 0, binding = VKCLOTH_BINDING_PARTICLE) readonly buffer ParticleBuf { ParticleInfo particle[]; };
layout(std430, set = 0, binding = VKCLOTH_BINDING_COLLIDERS) readonly buffer ColliderBuf { Collider colliders[]; };
layout(std430, set = 0, binding = VKCLOTH_BINDING_MESH_NODES) readonly buffer MeshNodeBuf { MeshNode mesh_nodes[]; };
layout(std430, set = 0, binding = VKCLOTH_BINDING_MESH_TRIS) readonly buffer MeshTriBuf { MeshTriangle mesh_tris[]; };
layout(std430, set = 0, binding = VKCLOTH_BINDING_FLAGS) buffer FlagBuf { Flags flags[]; };
layout(std430, set = 0, binding = VKCLOTH_BINDING_INSTANCES) readonly buffer InstanceBuf { InstanceParams instances[]; };

// The pass this pipeline runs, fixed when it is made (pipelines.hpp ShaderVariant::stage): llvmpipe
// runs the code of every branch, even one that no invocation takes, so a shader whose passes branch
// on the stage (strain_finish, self_collision, implicit .comp) gets one pipeline per stage, the
// others' code compiled out. VKCLOTH_ANY_STAGE (the default): pc.stage decides.
layout(constant_id = VKCLOTH_STAGE_CONSTANT) const uint SC_STAGE = VKCLOTH_ANY_STAGE;
uint pass_stage() { return SC_STAGE != VKCLOTH_ANY_STAGE ? SC_STAGE : pc.stage; }

// This invocation's instance of the batch, the index of its particle 0 in the state buffers and
// its parameters; set by begin_instance(), the first call of every main().
uint inst;
uint base;
InstanceParams ip;

#if defined(VKCLOTH_PC_COPY) && defined(VKCLOTH_TEXEL_VIEWS)
// The same shaders (force.comp, fused.comp, integrate.comp, strain_*.comp) in their *_texel builds
// read the instance parameters through an RGBA32UI texel view (set 1): on llvmpipe an SSBO load is
// a per-lane loop even at an index that is the same for the whole workgroup; a texel fetch is one
// vectorised call. Their *_storage builds load instances[inst] (DeviceLayout picks the build).
layout(set = 1, binding = VKCLOTH_TEXEL_BINDING_INSTANCES) uniform usamplerBuffer instances_texel;
#endif

// The normal as stored for the host (GpuSolverOptions::flip_normals). The physics uses n itself;
// flipping changes nothing there anyway (wind Kw <n, u> n is even in n).
vec4 normal_output(vec3 nrm) {
  return vec4((ip.flags & VKCLOTH_FLAG_FLIP_NORMALS) != 0u ? -nrm : nrm, 0.0);
}

void begin_instance() {
  inst = gl_WorkGroupID.z;
#if defined(VKCLOTH_PC_COPY) && defined(VKCLOTH_TEXEL_VIEWS)
  pc = pc_block; // before any branch (see above)
  base = inst * pc.count;
  const int t = int(inst) * 5; // sizeof(InstanceParams) / 16
  const uvec4 a = texelFetch(instances_texel, t), g = texelFetch(instances_texel, t + 1),
              w = texelFetch(instances_texel, t + 2), d = texelFetch(instances_texel, t + 3),
              e = texelFetch(instances_texel, t + 4);
  ip.flags = a.x;
  ip.integrator = a.y;
  ip.collider_first = a.z;
  ip.collider_count = a.w;
  ip.gravity_damping = uintBitsToFloat(g);
  ip.wind = uintBitsToFloat(w);
  ip.dt = uintBitsToFloat(d.x);
  ip.w6 = uintBitsToFloat(d.y);
  ip.band = uintBitsToFloat(d.z);
  ip.eps = uintBitsToFloat(d.w);
  ip.limit = uintBitsToFloat(e.x);
  ip.max_strain = uintBitsToFloat(e.y);
  ip.stretch = e.z;
  ip.stretch_sweeps = e.w;
#else
#ifdef VKCLOTH_PC_COPY
  pc = pc_block;
#endif
  base = inst * pc.count;
  ip = instances[inst];
#endif
}

// Particle index within the instance: 1-D, with a second grid dimension when one row of workgroups is not enough.
uint particle_index() {
  return gl_WorkGroupID.y * gl_NumWorkGroups.x * gl_WorkGroupSize.x + gl_GlobalInvocationID.x;
}

// A step after the first diverged one leaves the state as it was after the bad step (like the
// CPU, which stops there). Stable within a dispatch: first_bad_step only takes this step's value.
bool frozen() { return flags[inst].first_bad_step < pc.step; }

// The per-particle physics shared with the CPU reference (cloth_kernel.h, also compiled as C++
// by engine/src/core/kernel.hpp): its language prelude for GLSL.
#define real float
#define KFN
#define KFN_NOINLINE
#define OUT(T) out T
#define INOUT(T) inout T
#define VARYING(T) T
#define select(c, a, b) ((c) ? (a) : (b))
#define any_particle(c) (c)
#define maybe_any_particle(c) (c)
// No component is NaN or inf, from the bits: a compiler that assumes finite floats cannot fold it.
bool all_finite(vec3 v) {
  const uvec3 bits = floatBitsToUint(v) & 0x7f800000u; // exponent all ones: inf or NaN
  return all(notEqual(bits, uvec3(0x7f800000u)));
}
// Mesh colliders' hierarchies and triangles: global buffers, so MESH_DATA is a dummy argument.
// The *_texel builds read them, and the colliders, through RGBA32UI texel views (set 1) instead:
// on llvmpipe each SSBO load below is a per-lane loop (the collider's 36 words for every particle
// and collider, twice per step), a texel fetch one vectorised call; a 32-bit texel is a copy of
// the word, uintBitsToFloat gives its float back: same bits.
#define MESH_DATA_PARAM uint mesh_data
#define MESH_DATA mesh_data
#if defined(VKCLOTH_PC_COPY) && defined(VKCLOTH_TEXEL_VIEWS)
layout(set = 1, binding = VKCLOTH_TEXEL_BINDING_COLLIDERS) uniform usamplerBuffer colliders_texel;
layout(set = 1, binding = VKCLOTH_TEXEL_BINDING_MESH_NODES) uniform usamplerBuffer mesh_nodes_texel;
layout(set = 1, binding = VKCLOTH_TEXEL_BINDING_MESH_TRIS) uniform usamplerBuffer mesh_tris_texel;
void mesh_node(uint unused, uint i, out vec3 lo, out uint first, out vec3 hi, out uint count) {
  const uvec4 l = texelFetch(mesh_nodes_texel, int(2u * i)), h = texelFetch(mesh_nodes_texel, int(2u * i + 1u));
  lo = uintBitsToFloat(l.xyz);
  first = l.w;
  hi = uintBitsToFloat(h.xyz);
  count = h.w;
}
void mesh_triangle(uint unused, uint i, out vec3 a, out vec3 b, out vec3 c) {
  const int t = int(3u * i);
  a = uintBitsToFloat(texelFetch(mesh_tris_texel, t).xyz);
  b = uintBitsToFloat(texelFetch(mesh_tris_texel, t + 1).xyz);
  c = uintBitsToFloat(texelFetch(mesh_tris_texel, t + 2).xyz);
}
#else
void mesh_node(uint unused, uint i, out vec3 lo, out uint first, out vec3 hi, out uint count) {
  const MeshNode n = mesh_nodes[i];
  lo = n.lo_first.xyz;
  first = floatBitsToUint(n.lo_first.w);
  hi = n.hi_count.xyz;
  count = floatBitsToUint(n.hi_count.w);
}
void mesh_triangle(uint unused, uint i, out vec3 a, out vec3 b, out vec3 c) {
  const MeshTriangle t = mesh_tris[i];
  a = t.a.xyz;
  b = t.b.xyz;
  c = t.c.xyz;
}
#endif
#define VKCLOTH_COLLIDER_PRESENT(type) ((SC_COLLIDER_TYPES & (1u << (type))) != 0u)
#include "kernel/cloth_kernel.h"

// The instance's collider c as the kernel takes it (the host packed kernel_shape<float>).
ColliderShape collider_shape(uint c) {
#if defined(VKCLOTH_PC_COPY) && defined(VKCLOTH_TEXEL_VIEWS)
  const int t = int(VKCLOTH_COLLIDER_TEXELS * (ip.collider_first + c)); // the Collider's 16-byte rows, in order
  const uvec4 shape = texelFetch(colliders_texel, t), head = texelFetch(colliders_texel, t + 1);
  const uvec4 velocity = texelFetch(colliders_texel, t + 6), spin = texelFetch(colliders_texel, t + 7);
  ColliderShape s;
  s.type = head.x;
  s.a = uintBitsToFloat(shape.xyz);
  s.b = uintBitsToFloat(shape.w);
  s.c = uintBitsToFloat(texelFetch(colliders_texel, t + 2).xyz);
  s.ax = uintBitsToFloat(texelFetch(colliders_texel, t + 3).xyz);
  s.ay = uintBitsToFloat(texelFetch(colliders_texel, t + 4).xyz);
  s.az = uintBitsToFloat(texelFetch(colliders_texel, t + 5).xyz);
  s.mesh_root = head.z;
  s.mesh_tri0 = head.w;
  s.moving = head.y != 0u;
  s.velocity = uintBitsToFloat(velocity.xyz);
  s.spin = uintBitsToFloat(spin.xyz);
  s.pivot = uintBitsToFloat(texelFetch(colliders_texel, t + 8).xyz);
  s.mu_k = uintBitsToFloat(velocity.w);
  s.mu_s = uintBitsToFloat(spin.w);
  return s;
#else
  const Collider col = colliders[ip.collider_first + c];
  ColliderShape s;
  s.type = col.type;
  s.a = col.shape.xyz;
  s.b = col.shape.w;
  s.c = col.end_b.xyz;
  s.ax = col.axis_x.xyz;
  s.ay = col.axis_y.xyz;
  s.az = col.axis_z.xyz;
  s.mesh_root = col.mesh_root;
  s.mesh_tri0 = col.mesh_tri0;
  s.moving = col.moving != 0u;
  s.velocity = col.velocity.xyz;
  s.spin = col.spin.xyz;
  s.pivot = col.pivot.xyz;
  s.mu_k = col.velocity.w;
  s.mu_s = col.spin.w;
  return s;
#endif
}

#endif
