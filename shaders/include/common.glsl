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

// The push constants' struct: PushConstants, or the pass's own (vkcloth_shared.h), which the shader
// names before including this file.
#ifndef VKCLOTH_PUSH_STRUCT
#define VKCLOTH_PUSH_STRUCT PushConstants
#endif
#ifdef VKCLOTH_PC_COPY
// The shader copies the push constants into `pc` before any branch (begin_instance: pc = pc_block;
// why: docs/performance.md "lavapipe (llvmpipe) notes").
layout(push_constant) uniform PushBlock { VKCLOTH_PUSH_STRUCT pc_block; };
VKCLOTH_PUSH_STRUCT pc;
#else
layout(push_constant) uniform PushBlock { VKCLOTH_PUSH_STRUCT pc; };
#endif

// Bit t set: some instance of the batch may have a collider of type t (VKCLOTH_COLLIDER_*); 0: none
// has colliders (every ip.collider_count == 0), the contact loops compiled out. The absent shapes'
// branches of the kernel's switch over the shapes (collider_contact: VKCLOTH_COLLIDER_PRESENT) are
// compiled out too (GpuSolver specialises fused.comp with the batch's types; the other shaders
// keep the default: every type; why: docs/performance.md "lavapipe (llvmpipe) notes").
layout(constant_id = 41) const uint SC_COLLIDER_TYPES = VKCLOTH_COLLIDER_ALL_TYPES;
const bool SC_COLLIDERS = SC_COLLIDER_TYPES != 0u;

layout(std430, set = 0, binding = VKCLOTH_BINDING_PARTICLE) readonly buffer ParticleBuf { ParticleInfo particle[]; };
layout(std430, set = 0, binding = VKCLOTH_BINDING_COLLIDERS) readonly buffer ColliderBuf { Collider colliders[]; };
layout(std430, set = 0, binding = VKCLOTH_BINDING_MESH_NODES) readonly buffer MeshNodeBuf { MeshNode mesh_nodes[]; };
layout(std430, set = 0, binding = VKCLOTH_BINDING_MESH_TRIS) readonly buffer MeshTriBuf { MeshTriangle mesh_tris[]; };
layout(std430, set = 0, binding = VKCLOTH_BINDING_FLAGS) buffer FlagBuf { Flags flags[]; };
layout(std430, set = 0, binding = VKCLOTH_BINDING_INSTANCES) readonly buffer InstanceBuf { InstanceParams instances[]; };

// read_instance, read_collider, read_mesh_node, read_mesh_triangle: these buffers, or set 1's
// views of them in the solver passes' texel builds.
#define VKCLOTH_ACCESS_INSTANCE
#include "buffer_access.glsl"

// The pass this pipeline runs, fixed when it is made (pipelines.hpp ShaderVariant::stage): a shader
// whose passes branch on the stage (strain_finish, self_collision, implicit .comp) gets one
// pipeline per stage, the others' code compiled out (why: docs/performance.md "lavapipe (llvmpipe)
// notes"). VKCLOTH_ANY_STAGE (the default): pc.stage decides.
layout(constant_id = VKCLOTH_STAGE_CONSTANT) const uint SC_STAGE = VKCLOTH_ANY_STAGE;
uint pass_stage() { return SC_STAGE != VKCLOTH_ANY_STAGE ? SC_STAGE : pc.stage; }

// This invocation's instance of the batch, the index of its particle 0 in the state buffers and
// its parameters; set by begin_instance(), the first call of every main().
uint inst;
uint base;
InstanceParams ip;

// The normal as stored for the host (GpuSolverOptions::flip_normals). The physics uses n itself;
// flipping changes nothing there anyway (wind Kw <n, u> n is even in n).
vec4 normal_output(vec3 nrm) {
  return vec4((ip.flags & VKCLOTH_FLAG_FLIP_NORMALS) != 0u ? -nrm : nrm, 0.0);
}

void begin_instance() {
  inst = gl_WorkGroupID.z;
#ifdef VKCLOTH_PC_COPY
  pc = pc_block; // before any branch (see above)
#endif
  base = inst * pc.count;
  ip = read_instance(inst);
}

// Particle index within the instance: 1-D, with a second grid dimension when one row of workgroups is not enough.
uint particle_index() {
  return gl_WorkGroupID.y * gl_NumWorkGroups.x * gl_WorkGroupSize.x + gl_GlobalInvocationID.x;
}

// A step after the first diverged one leaves the state as it was after the bad step (like the
// CPU, which stops there). Stable within a dispatch: first_bad_step only takes this step's value.
bool frozen() { return flags[inst].first_bad_step < pc.step; }

// The per-particle physics shared with the CPU reference (cloth_kernel.h, also compiled as C++
// by engine/src/internal/kernel.hpp): its language prelude for GLSL.
#include "kernel/language.h" // the kernel's macros, GLSL
// No component is NaN or inf, from the bits: a compiler that assumes finite floats cannot fold it.
bool all_finite(vec3 v) {
  const uvec3 bits = floatBitsToUint(v) & 0x7f800000u; // exponent all ones: inf or NaN
  return all(notEqual(bits, uvec3(0x7f800000u)));
}
// Mesh colliders' hierarchies and triangles: global buffers; MESH_DATA is the particle (its index in
// the batch), whose search entries (cloth_kernel.h mesh_contact) it reads and writes.
void mesh_node(uint particle, uint i, out vec3 lo, out uint first, out vec3 hi, out uint count) {
  const MeshNode n = read_mesh_node(i);
  lo = n.lo_first.xyz;
  first = floatBitsToUint(n.lo_first.w);
  hi = n.hi_count.xyz;
  count = floatBitsToUint(n.hi_count.w);
}
void mesh_triangle(uint particle, uint i, out vec3 a, out vec3 b, out vec3 c) {
  const MeshTriangle t = read_mesh_triangle(i);
  a = t.a.xyz;
  b = t.b.xyz;
  c = t.c.xyz;
}
// A mesh's neighbours (ColliderMesh::neighbours) follow every triangle and velocity in MESH_TRIS,
// four triangles' (12 words) to a MeshTriangle, from adj0 on.
uint mesh_neighbour(uint particle, uint adj0, uint i, uint k) {
  const uint word = (i % 4u) * 3u + k;
  const MeshTriangle t = read_mesh_triangle(adj0 + i / 4u);
  const vec4 v = word < 4u ? t.a : (word < 8u ? t.b : t.c);
  return floatBitsToUint(v[word % 4u]);
}
void mesh_clearance(uint particle, uint i, out float front, out float back) {
  const MeshTriangle t = read_mesh_triangle(i);
  front = t.a.w;
  back = t.b.w;
}
layout(std430, set = 0, binding = VKCLOTH_BINDING_MESH_CACHE) buffer MeshCacheBuf { vec4 mesh_entries[]; };
void mesh_velocity(uint particle, uint i, out vec3 va, out vec3 vb, out vec3 vc) {
  const MeshTriangle t = read_mesh_triangle(i); // a skinned mesh's velocities follow the triangles
  va = t.a.xyz;
  vb = t.b.xyz;
  vc = t.c.xyz;
}
void mesh_cache_load(uint particle, uint slot, out vec3 n, out uint tri, out vec3 centre, out float radius) {
  const uint i = 2u * (slot + particle);
  const vec4 a = mesh_entries[i];
  const vec4 b = mesh_entries[i + 1u];
  n = a.xyz;
  tri = floatBitsToUint(a.w);
  centre = b.xyz;
  radius = b.w;
}
void mesh_cache_store(uint particle, uint slot, vec3 n, uint tri, vec3 centre, float radius) {
  const uint i = 2u * (slot + particle);
  mesh_entries[i] = vec4(n, uintBitsToFloat(tri));
  mesh_entries[i + 1u] = vec4(centre, radius);
}
#define VKCLOTH_COLLIDER_PRESENT(type) ((SC_COLLIDER_TYPES & (1u << (type))) != 0u)
#include "kernel/cloth_kernel.h"

// The instance's collider c as the kernel takes it (the host packed kernel_shape<float>).
ColliderShape collider_shape(uint c) {
  const Collider col = read_collider(ip.collider_first + c);
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
  s.mesh_cache = floatBitsToUint(col.pivot.w);
  s.mesh_vel0 = floatBitsToUint(col.end_b.w);
  s.mesh_adj0 = floatBitsToUint(col.axis_x.w);
  s.moving = col.moving != 0u;
  s.velocity = col.velocity.xyz;
  s.spin = col.spin.xyz;
  s.pivot = col.pivot.xyz;
  s.mu_k = col.velocity.w;
  s.mu_s = col.spin.w;
  return s;
}

#endif
