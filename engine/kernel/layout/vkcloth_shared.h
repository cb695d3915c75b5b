// SPDX-License-Identifier: MIT
// Declarations shared by the GLSL compute shaders and the C++ Vulkan solver: workgroup size,
// descriptor binding indices, push constants and the storage-buffer element layouts.
// Declared ONCE here; C++ static_asserts at the bottom pin the std430 layout.
#ifndef VKCLOTH_SHARED_H
#define VKCLOTH_SHARED_H

#include "kernel/constants.h" // the physics' constants (ring bits, collider types, ...)

#ifdef __cplusplus
#include <cstddef>
#include <cstdint>
namespace vkcloth::gpu::shared {
using uint = std::uint32_t;
struct vec4 {
  float x, y, z, w;
};
#endif

// The specialisation constant that fixes the pass a pipeline runs (common.glsl SC_STAGE; the host:
// pipelines.hpp ShaderVariant::stage); VKCLOTH_ANY_STAGE: the push constants' `stage` decides.
#define VKCLOTH_STAGE_CONSTANT 44
#define VKCLOTH_ANY_STAGE 0xffffffffu

// Batches: one dispatch serves every instance (cloth) of a batch that shares one topology;
// instance = gl_WorkGroupID.z. Per-particle state buffers hold the instances one after the other
// (instance i's particle p at i * count + p); topology buffers (PARTICLE, OFFSETS, EDGES) are
// shared; each instance has its InstanceParams, its colliders (a range of COLLIDERS) and its Flags.
// A standalone GpuSolver is a batch of one.

// Descriptor bindings (set 0). One layout serves both pipelines; each shader declares the
// bindings it uses. Four descriptor sets differ only in which buffers sit behind the
// *_IN / *_BASE / *_OUT / FORCE_OUT bindings (position parity x state-or-RK4-stage input).
#define VKCLOTH_BINDING_POS_IN 0     // positions the force pass reads (state or RK4 stage)
#define VKCLOTH_BINDING_VEL_IN 1     // velocities the force pass reads (state or RK4 stage)
#define VKCLOTH_BINDING_FORCE_OUT 2  // force after contacts (state force, or RK4 stage scratch)
#define VKCLOTH_BINDING_VEL_FILT 3   // velocity after contact filtering (force -> integrate)
#define VKCLOTH_BINDING_NORMAL 4     // unit vertex normals (cloth), written every force pass
#define VKCLOTH_BINDING_POS_BASE 5   // positions at the start of the step (= positions[read])
#define VKCLOTH_BINDING_POS_OUT 6    // positions at the end of the step (= positions[write])
#define VKCLOTH_BINDING_VEL 7        // state velocities (read and written by integrate)
#define VKCLOTH_BINDING_STAGE_POS 8  // RK4 stage positions y_k
#define VKCLOTH_BINDING_STAGE_VEL 9  // RK4 stage velocities
#define VKCLOTH_BINDING_ACC_POS 10   // RK4 running sum k1 + 2 k2 + 2 k3 + k4 (positions)
#define VKCLOTH_BINDING_ACC_VEL 11   // RK4 running sum (velocities)
#define VKCLOTH_BINDING_PARTICLE 12  // ParticleInfo per particle
#define VKCLOTH_BINDING_OFFSETS 13   // CSR offsets, count + 1 entries (SpringAdjacency::offsets)
#define VKCLOTH_BINDING_EDGES 14     // CSR entries in gather order (Edge)
#define VKCLOTH_BINDING_COLLIDERS 15 // Collider array (collider_count entries, at least one slot)
#define VKCLOTH_BINDING_FLAGS 16     // Flags per instance (divergence detection)
#define VKCLOTH_BINDING_INSTANCES 17 // InstanceParams per instance
#define VKCLOTH_BINDING_STRAIN_LINKS                                                                         \
  18 // StrainLink per strain link, in colour order (ClothTopology::strain_links)
#define VKCLOTH_BINDING_TETHERS                                                                              \
  19 // TetherSlot, VKCLOTH_TETHERS_PER_PARTICLE per particle, euclidean then geodesic
#define VKCLOTH_BINDING_UV 20 // texture coordinates (vec4: u, v, 0, 0), read by vertices.comp
#define VKCLOTH_BINDING_VERTICES                                                                             \
  21 // interleaved Vertex per particle (GpuSolverOptions::interleaved_vertices)
#define VKCLOTH_BINDING_MESH_NODES 22 // MeshNode: every mesh collider's hierarchy (Collider::mesh_root)
#define VKCLOTH_BINDING_MESH_TRIS 23  // MeshTriangle: their triangles in leaf order (Collider::mesh_tri0)
#define VKCLOTH_BINDING_VBD_ORDER 24  // vbd: the particles in colour order (ClothTopology::vertex_order)
#define VKCLOTH_BINDING_TARGETS 25    // Target per particle of each instance (its attachments' and host's)
#define VKCLOTH_BINDING_FRAMES 26     // FrameMotion per instance: its frame's jump and carry this substep
#define VKCLOTH_BINDING_MESH_CACHE                                                                           \
  27 // search entries (mesh_contact) as 2 vec4 per particle and mesh collider (Collider::pivot.w)
#define VKCLOTH_BINDING_COUNT 28

// Set 1 (force.comp, fused.comp, strain_*.comp): POS_IN again, as an RGBA32F uniform texel buffer view,
// PARTICLE as an RG32UI one (x: the mass's bits, y: pinned), and (fused.comp) VEL as RGBA32F and
// FLAGS as R32UI; INSTANCES as RGBA32UI (common.glsl begin_instance); the topology's lists
// (force_body.glsl list_range, edge_at) as RGBA32UI views; the
// colliders and the mesh colliders' nodes and triangles as RGBA32UI (common.glsl collider_shape,
// mesh_node, mesh_triangle).
#define VKCLOTH_TEXEL_BINDING_POS_IN 0
#define VKCLOTH_TEXEL_BINDING_PARTICLE 1
#define VKCLOTH_TEXEL_BINDING_VEL 2
#define VKCLOTH_TEXEL_BINDING_FLAGS 3
#define VKCLOTH_TEXEL_BINDING_INSTANCES 4    // InstanceParams as RGBA32UI, 5 texels per instance
#define VKCLOTH_TEXEL_BINDING_RANGES 5       // per particle its list's begin, fan end, end (RGBA32UI)
#define VKCLOTH_TEXEL_BINDING_EDGES 6        // EDGES as RGBA32UI, one texel per Edge
#define VKCLOTH_TEXEL_BINDING_STRAIN_LINKS 7 // STRAIN_LINKS as R32UI, 3 texels per StrainLink
#define VKCLOTH_TEXEL_BINDING_TETHERS 8      // TETHERS as RG32UI, one texel per TetherSlot
#define VKCLOTH_TEXEL_BINDING_COLLIDERS 9    // COLLIDERS as RGBA32UI, VKCLOTH_COLLIDER_TEXELS per Collider
#define VKCLOTH_TEXEL_BINDING_MESH_NODES 10  // MESH_NODES as RGBA32UI, 2 texels per MeshNode
#define VKCLOTH_TEXEL_BINDING_MESH_TRIS 11   // MESH_TRIS as RGBA32UI, 3 texels per MeshTriangle
#define VKCLOTH_TEXEL_BINDING_COUNT 12
#define VKCLOTH_COLLIDER_TEXELS 9 // 16-byte texels per Collider (static_assert below)

// InstanceParams::flags bits.
#define VKCLOTH_FLAG_HAS_GRID 1u      // the topology is a grid: rebuild normals from the grid fan
#define VKCLOTH_FLAG_WIND 2u          // wind strength != 0
#define VKCLOTH_FLAG_CONTACT_BOTH 4u  // contacts remove the whole normal part (Figure 12 variant)
#define VKCLOTH_FLAG_RING_NORMALS 8u  // a surface that is not a grid: normals from the EDGES' ring bits
#define VKCLOTH_FLAG_FLIP_NORMALS 16u // store -n in the normals buffer (GpuSolverOptions::flip_normals)
#define VKCLOTH_FLAG_SELF_COLLISION                                                                          \
  32u // self-collision on (self_collision.comp; strain_finish.comp's stage 2)

// Flags::first_bad_step before anything diverged.
#define VKCLOTH_NO_BAD_STEP 0xffffffffu

/// Per-dispatch parameters (32 bytes), the same for every instance of the batch. Every pass's push
/// constants start with these five fields (common.glsl reads count, stage and step); the last three
/// are each pass's own, named for what they carry: StrainLinksPush below, ImplicitPush
/// (implicit_shared.h), SelfPush (self_collision_shared.h), ProjectionPush
/// (strain_projection_shared.h). A shader names its struct with VKCLOTH_PUSH_STRUCT (common.glsl).
struct PushConstants {
  uint count; // particles per instance
  uint nx;    // grid width (0 for chains)
  uint ny;    // grid height
  uint stage; // the pass of a multi-pass shader: RK4 stage 0..3 (0 for Euler), a strain_finish stage,
              // implicit Euler's or self-collision's pass, strain_links' sweep, the projection's dispatch
  uint step;  // 1-based step number since the batch's flag epoch (the step being computed)
  uint unused0;
  uint unused1;
  uint unused2;
};

/// strain_links.comp: one colour of one sweep (`stage`: the sweep), or one family of chains.
struct StrainLinksPush {
  uint count;
  uint nx;
  uint ny;
  uint stage;
  uint step;
  uint link_first;  // the colour's first link (chains: the family's first)
  uint link_count;  // the colour's links (chains: the family's chains)
  uint chain_links; // 0: a colour; else the links of each chain of the family (| VKCLOTH_CHAIN_BACKWARD)
};

/// targets.comp (`stage`: VKCLOTH_TARGETS_DRIVE or _HOLD): the entries of each instance's targets
/// that this substep's upload wrote (the most any instance has; the rest of its range is stale).
struct TargetsPush {
  uint count;
  uint nx;
  uint ny;
  uint stage;
  uint step;
  uint target_count;
  uint unused0;
  uint unused1;
};

/// vbd.comp (VKCLOTH_VBD_*: `stage`): one colour of one sweep in VKCLOTH_VBD_SOLVE.
#define VKCLOTH_VBD_BEGIN 0u  // normals, inertia targets (VEL_FILT), first guess (POS_OUT)
#define VKCLOTH_VBD_SOLVE 1u  // one colour's Newton steps in place on POS_OUT, the push (STAGE_POS)
#define VKCLOTH_VBD_FINISH 2u // velocities, friction, projection, divergence
struct VbdPush {
  uint count;
  uint nx;
  uint ny;
  uint stage;
  uint step;
  uint colour_first; // the colour's first entry of VBD_ORDER
  uint colour_count; // its particles
  uint contact;      // 1: add self-contact's force and stiffness (ACC_POS, ACC_VEL, STAGE_VEL) to the step
};

/// Per-instance parameters (80 bytes; InstanceParams[instance] at VKCLOTH_BINDING_INSTANCES).
/// Floats are converted from the double SimParams on the host exactly as CpuSolver<float>
/// converts them.
struct InstanceParams {
  uint flags;          // VKCLOTH_FLAG_*
  uint integrator;     // VKCLOTH_INTEGRATOR_*
  uint collider_first; // this instance's colliders: COLLIDERS[collider_first ..]
  uint collider_count;
  vec4 gravity_damping; // xyz: gravity, w: damping mu
  vec4 wind;            // xyz: unit wind direction, w: strength Kw
  float dt;             // time step (of one substep)
  float w6;             // RK4: dt / 6
  float band;           // contact band 2 eps
  float eps;            // projection distance eps
  float limit;          // divergence limit
  float max_strain;     // stretch_limit.max_strain
  uint stretch;         // VKCLOTH_STRETCH_* (0: stretch control off)
  uint stretch_sweeps;  // stretch_limit.iterations: Provot sweeps per substep
};

/// One interleaved vertex (std430: 32 bytes): position xyz, normal xyz, uv, in the floats
/// p.x p.y p.z n.x | n.y n.z u v (VKCLOTH_BINDING_VERTICES, vertices.comp).
struct Vertex {
  vec4 position_nx;
  vec4 nyz_uv;
};

/// Per-particle constants (std430: 8 bytes).
struct ParticleInfo {
  float mass;
  uint pinned; // 1 when pinned
};

/// One gather-list entry (std430: 16 bytes: one RGBA32UI texel, fetched at once on the texel path).
struct Edge {
  uint other;
  float rest_length;
  float stiffness;
  uint ring; // VKCLOTH_RING_* bits: this entry's part in the vertex normal (GatherEdge::ring)
};

/// One particle's target at a substep's end (targets.comp; the CPU's detail::TargetEntry; std430: 32
/// bytes). Instance i's targets start at TARGETS[i * count]; VKCLOTH_NO_TARGET ends them.
#define VKCLOTH_NO_TARGET 0xffffffffu
#define VKCLOTH_TARGETS_DRIVE 0u // targets.comp stage: pinned particles onto their targets (before a substep)
#define VKCLOTH_TARGETS_HOLD 1u  // free particles back within reach (after a substep)
#define VKCLOTH_FRAME_JUMP 2u    // every particle moved by its frame's jump (before a substep)
#define VKCLOTH_FRAME_CARRY 3u   // free particles carried with the frame (after a substep)
struct Target {
  float px, py, pz; // the target
  uint particle;    // VKCLOTH_NO_TARGET: past the instance's last target
  float vx, vy, vz; // its velocity
  float reach;      // how far a free particle may be from it (m)
};

/// The cloth's frame over one substep (targets.comp's FRAME stages; the CPU's detail::FrameStep;
/// std430: 144 bytes): the jump x -> (row0.xyz . x, row1.xyz . x, row2.xyz . x) + (row0.w, row1.w,
/// row2.w), and the carry's inputs (kernel attach.h carried_velocity).
struct FrameMotion {
  vec4 row0; // the jump's rotation rows, w: its shift
  vec4 row1;
  vec4 row2;
  vec4 dv;     // xyz: the frame's linear velocity change, w: 1 - inertia.linear
  vec4 omega0; // xyz: its angular velocity at the substep's start, w: 1 - inertia.angular
  vec4 omega1; // xyz: at its end
  vec4 c0;     // xyz: its centre at the start
  vec4 c1;     // xyz: at the end
  uint jump;   // 1: this substep jumps
  uint carry;  // 1: this substep carries
  uint unused0;
  uint unused1;
};

/// A strain link (ClothTopology's StrainLink; std430: 12 bytes).
struct StrainLink {
  uint a;
  uint b;
  float rest_length;
};

/// One tether slot of a particle (ClothTopology's Tether; std430: 8 bytes).
struct TetherSlot {
  uint anchor; // VKCLOTH_NO_TETHER: no tether in this slot (nor in the following ones)
  float rest_length;
};

/// A collider at its pose for the next substep (cloth_kernel.h ColliderShape; std430: 144 bytes).
struct Collider {
  vec4 shape;     // plane: (n, offset); sphere: (centre, radius); capsule: (a, radius); box: (centre, 0);
                  // mesh: (origin, thickness)
  uint type;      // VKCLOTH_COLLIDER_*
  uint moving;    // 1: velocity, spin and pivot apply
  uint mesh_root; // mesh: its root in MESH_NODES
  uint mesh_tri0; // mesh: its first triangle in MESH_TRIS
  vec4 end_b;     // capsule: (b, 0); box: (half extents, 0); mesh: w: the bits of its first corner
                  // velocities in MESH_TRIS (VKCLOTH_MESH_NONE: rigid)
  vec4 axis_x;    // box, mesh: the body's axes in the world (the rotation's columns); x.w: a mesh:
                  // the bits of where its neighbours start in MESH_TRIS
  vec4 axis_y;
  vec4 axis_z;
  vec4 velocity; // xyz: linear velocity; w: kinetic friction
  vec4 spin;     // xyz: angular velocity; w: static friction
  vec4 pivot;    // xyz: the point spin turns about; w: mesh: the bits of its first MESH_CACHE entry
};

/// A node of a mesh collider's hierarchy (vkcloth::ColliderMesh::Node; std430: 32 bytes).
struct MeshNode {
  vec4 lo_first; // xyz: box min; w: the bits of `first` (leaf: first triangle; inner: first child)
  vec4 hi_count; // xyz: box max; w: the bits of `count` (0: inner node)
};

/// A mesh collider's triangle (vkcloth::ColliderMesh::Triangle; std430: 48 bytes).
struct MeshTriangle {
  vec4 a;
  vec4 b;
  vec4 c;
};

/// Divergence flags of one instance, written with integer atomics (finish.glsl).
struct Flags {
  uint diverged;       // non-zero once any particle went non-finite or past the limit
  uint first_bad_step; // smallest PushConstants::step that diverged (VKCLOTH_NO_BAD_STEP if none)
  uint bad_particle;   // smallest particle index that diverged at that step
  uint pad;
};

#ifdef __cplusplus
static_assert(sizeof(PushConstants) == 32);
static_assert(sizeof(StrainLinksPush) == 32);
static_assert(sizeof(VbdPush) == 32);
static_assert(sizeof(TargetsPush) == 32);

/// The state layout (every pass that reads the batch's state through its sets: force, integrate,
/// fused, strain_links, strain_finish, vertices): set 0 holds every VKCLOTH_BINDING_* (0 ..
/// VKCLOTH_BINDING_COUNT - 1), set 1 these views. Its one binding table:
/// engine/src/vulkan/passes/state_set.hpp.
inline constexpr uint state_texel_bindings[] = {
    VKCLOTH_TEXEL_BINDING_POS_IN,    VKCLOTH_TEXEL_BINDING_PARTICLE,     VKCLOTH_TEXEL_BINDING_VEL,
    VKCLOTH_TEXEL_BINDING_FLAGS,     VKCLOTH_TEXEL_BINDING_INSTANCES,    VKCLOTH_TEXEL_BINDING_RANGES,
    VKCLOTH_TEXEL_BINDING_EDGES,     VKCLOTH_TEXEL_BINDING_STRAIN_LINKS, VKCLOTH_TEXEL_BINDING_TETHERS,
    VKCLOTH_TEXEL_BINDING_COLLIDERS, VKCLOTH_TEXEL_BINDING_MESH_NODES,   VKCLOTH_TEXEL_BINDING_MESH_TRIS};
static_assert(sizeof(state_texel_bindings) / sizeof(uint) == VKCLOTH_TEXEL_BINDING_COUNT);

/// A pass's push constants (one of the structs above) with `pc`'s five common fields.
template <typename Push> Push push_from(const PushConstants& pc) {
  Push p{};
  p.count = pc.count;
  p.nx = pc.nx;
  p.ny = pc.ny;
  p.stage = pc.stage;
  p.step = pc.step;
  return p;
}
static_assert(sizeof(InstanceParams) == 80);
static_assert(offsetof(InstanceParams, gravity_damping) == 16);
static_assert(offsetof(InstanceParams, wind) == 32);
static_assert(offsetof(InstanceParams, dt) == 48);
static_assert(offsetof(InstanceParams, limit) == 64);
static_assert(sizeof(ParticleInfo) == 8);
static_assert(sizeof(Vertex) == 32);
static_assert(sizeof(Edge) == 16);
static_assert(sizeof(StrainLink) == 12);
static_assert(sizeof(Target) == 32);
static_assert(sizeof(FrameMotion) == 144);
static_assert(sizeof(TetherSlot) == 8);
static_assert(offsetof(InstanceParams, max_strain) == 68);
static_assert(sizeof(Collider) == 144);
static_assert(sizeof(Collider) == VKCLOTH_COLLIDER_TEXELS * 16);
static_assert(offsetof(Collider, type) == 16);
static_assert(offsetof(Collider, end_b) == 32);
static_assert(sizeof(MeshNode) == 32);
static_assert(sizeof(MeshTriangle) == 48);
static_assert(sizeof(Flags) == 16);
static_assert(sizeof(vec4) == 16);
} // namespace vkcloth::gpu::shared
#endif

#endif // VKCLOTH_SHARED_H
