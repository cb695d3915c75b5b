// SPDX-License-Identifier: MIT
// Declarations shared by self_collision.comp and the C++ side (engine/src/vulkan/
// passes/self_collision_gpu.cpp). Self-collision's passes use their own descriptor set layout: the main
// layout's bindings they need (same numbers, same buffers, vkcloth_shared.h) plus the spatial
// hash's buffers below. Push constants: SelfPush below, `stage` selecting the pass.
#ifndef VKCLOTH_SELF_COLLISION_SHARED_H
#define VKCLOTH_SELF_COLLISION_SHARED_H

#include "kernel/layout/implicit_shared.h"

#ifdef __cplusplus
namespace vkcloth::gpu::shared {
#endif

#define VKCLOTH_BINDING_SELF_PARAMS 39 // (after implicit Euler's) SelfParams per instance
#define VKCLOTH_BINDING_SELF_REST 40   // rest positions, w: inverse mass (vec4 per particle of the topology)
#define VKCLOTH_BINDING_SELF_COUNTS                                                                          \
  41 // particles per bucket (uint, table size per instance; zero between substeps)
#define VKCLOTH_BINDING_SELF_STARTS 42 // each bucket's first entry (uint, table size + 1 per instance)
#define VKCLOTH_BINDING_SELF_BLOCKS                                                                          \
  43 // each scan block's first entry (uint, table size / SCAN_BLOCK per instance)
#define VKCLOTH_BINDING_SELF_KEYS 44   // each particle's cell key when sorted (uint, per particle)
#define VKCLOTH_BINDING_SELF_SORTED 45 // the particles by bucket, then by index, with their keys (uvec2)
#define VKCLOTH_BINDING_SELF_DELTA 46  // this Jacobi pass's move and velocity change (2 vec4 per particle)
// The neighbour lists (SelfParams::half_skin2 > 0; CpuSolver's SelfCollisionGrid built, listed, list).
#define VKCLOTH_BINDING_SELF_BUILT                                                                           \
  47 // where each particle was when the lists were built, w: reach^2 (vec4; NaN: never)
#define VKCLOTH_BINDING_SELF_LISTED 48 // each list's length (uint per particle; > capacity: overflowed)
#define VKCLOTH_BINDING_SELF_LIST 49   // VKCLOTH_SELF_LIST_CAPACITY particles per particle (uint)
#define VKCLOTH_BINDING_SELF_STALE                                                                           \
  50 // 2 uint per instance: nonzero when the lists must be built again; the build's thickness (bits)

// Set 1 of the self_collision_texel build: what COLLIDE's walk reads, through uniform texel buffer
// views (llvmpipe turns a storage-buffer load into a per-lane loop, a texel fetch into one
// gather); the self_collision_storage build reads the same from set 0 and has no set 1.
#define VKCLOTH_SELF_TEXEL_POS 0    // the positions being written (POS_OUT), RGBA32F
#define VKCLOTH_SELF_TEXEL_VEL 1    // velocities, RGBA32F
#define VKCLOTH_SELF_TEXEL_REST 2   // SELF_REST, RGBA32F
#define VKCLOTH_SELF_TEXEL_STARTS 3 // SELF_STARTS, R32UI
#define VKCLOTH_SELF_TEXEL_SORTED 4 // SELF_SORTED, RG32UI
#define VKCLOTH_SELF_TEXEL_COUNT 5

// VKCLOTH_SELF_SCAN_BLOCK (kernel/constants.h): buckets per workgroup of the SCAN_BLOCKS pass.
#define VKCLOTH_SELF_SCAN_PER_INVOCATION 8u

// self_collision.comp passes (PushConstants::stage), in recording order; one barrier between each.
// With a skin, every Jacobi pass starts with CHECK, and COUNT .. LIST do nothing unless it found a
// particle that moved more than half the skin (SELF_STALE).
#define VKCLOTH_SELF_COUNT 0u       // per particle: its bucket; counts[bucket] += 1 (integer atomics)
#define VKCLOTH_SELF_SCAN_BLOCKS 1u // per scan block: exclusive prefix sums of its counts, its total
#define VKCLOTH_SELF_SCAN_TOP 2u    // one workgroup per instance: exclusive prefix sums of the block totals
#define VKCLOTH_SELF_SCAN_ADD 3u    // per bucket: its block's start added (starts: absolute), the end
#define VKCLOTH_SELF_SCATTER 4u     // per particle: a slot in its bucket (counts[bucket] -= 1: zero again)
#define VKCLOTH_SELF_SORT 5u        // per bucket: its particles in increasing index (the CPU's order)
#define VKCLOTH_SELF_COLLIDE 6u     // per particle: cloth_kernel.h self_collide(_listed) -> DELTA
#define VKCLOTH_SELF_APPLY 7u       // per particle: x += dx, v += dv (cloth_kernel.h self_apply)
#define VKCLOTH_SELF_CHECK 8u       // per particle: SELF_STALE |= self_moved (COLLIDE's first clears it)
#define VKCLOTH_SELF_LIST 9u        // per particle: its neighbour list (self_gather), BUILT = its position
#define VKCLOTH_SELF_CONTACT                                                                                 \
  10u // per particle, each vbd sweep: self_energy_listed -> ACC_POS, ACC_VEL, STAGE_VEL

/// Self-collision parameters of one instance (std430: 32 bytes), converted from the double
/// SimParams::self_collision as CpuSolver<float>::self_collide converts them.
struct SelfParams {
  uint iterations; // 0: self-collision off for this instance
  float thickness;
  float inv_cell; // 1 / the hash's cell size: twice the reach (thickness + skin), or the thickness without a
                  // skin
  float friction;
  float reach2;     // the reach squared (the lists' candidates)
  float half_skin2; // (skin / 2)^2; 0: no skin, no lists (COLLIDE walks the cells)
  float stiffness;  // > 0: vbd takes self-contact as an energy in its sweeps (no passes after the step)
  uint unused;
};

/// self_collision.comp's push constants (PushConstants' five fields, then its own).
struct SelfPush {
  uint count;
  uint nx;
  uint ny;
  uint stage; // the pass (VKCLOTH_SELF_*)
  uint step;
  uint table_size; // buckets of each instance's hash table (kernel.hpp self_table_size)
  uint iteration;  // the Jacobi iteration (COLLIDE, APPLY)
  uint in_sweeps; // 1: recorded by vbd's sweeps (the lists and CONTACT of the energy instances), 0: after the
                  // step
};

#ifdef __cplusplus
static_assert(sizeof(SelfPush) == sizeof(PushConstants));
static_assert(VKCLOTH_BINDING_SELF_PARAMS == VKCLOTH_BINDING_IMPL_ARGS + 1);
static_assert(sizeof(SelfParams) == 32);
/// Self-collision's storage bindings (set 0) and its texel build's views (set 1), in
/// descriptor-write order: its one binding table (engine/src/vulkan/passes/self_collision.cpp).
inline constexpr uint self_collision_bindings[] = {
    VKCLOTH_BINDING_POS_OUT,     VKCLOTH_BINDING_VEL,         VKCLOTH_BINDING_PARTICLE,
    VKCLOTH_BINDING_FLAGS,       VKCLOTH_BINDING_INSTANCES,   VKCLOTH_BINDING_SELF_PARAMS,
    VKCLOTH_BINDING_SELF_REST,   VKCLOTH_BINDING_SELF_COUNTS, VKCLOTH_BINDING_SELF_STARTS,
    VKCLOTH_BINDING_SELF_BLOCKS, VKCLOTH_BINDING_SELF_KEYS,   VKCLOTH_BINDING_SELF_SORTED,
    VKCLOTH_BINDING_SELF_DELTA,  VKCLOTH_BINDING_SELF_BUILT,  VKCLOTH_BINDING_SELF_LISTED,
    VKCLOTH_BINDING_SELF_LIST,   VKCLOTH_BINDING_SELF_STALE,  VKCLOTH_BINDING_ACC_POS,
    VKCLOTH_BINDING_ACC_VEL,     VKCLOTH_BINDING_STAGE_VEL,   VKCLOTH_BINDING_POS_IN};
inline constexpr uint self_collision_texel_bindings[] = {VKCLOTH_SELF_TEXEL_POS, VKCLOTH_SELF_TEXEL_VEL,
                                                         VKCLOTH_SELF_TEXEL_REST, VKCLOTH_SELF_TEXEL_STARTS,
                                                         VKCLOTH_SELF_TEXEL_SORTED};
static_assert(sizeof(self_collision_texel_bindings) / sizeof(uint) == VKCLOTH_SELF_TEXEL_COUNT);
} // namespace vkcloth::gpu::shared
#endif

#endif // VKCLOTH_SELF_COLLISION_SHARED_H
