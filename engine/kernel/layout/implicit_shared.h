// SPDX-License-Identifier: MIT
// Declarations shared by the implicit-Euler shader (implicit.comp) and the
// C++ side (engine/src/vulkan/passes/implicit_gpu.cpp). The implicit passes use their own descriptor set
// layout: the main layout's bindings they need (same numbers, same buffers, vkcloth_shared.h)
// plus the CG buffers below. The implicit passes run batches of one instance. Push constants: the main
// PushConstants, with fields the implicit passes do not otherwise use carrying the pass parameters
// (VKCLOTH_IMPL_* below).
#ifndef VKCLOTH_IMPLICIT_SHARED_H
#define VKCLOTH_IMPLICIT_SHARED_H

#include "kernel/layout/vkcloth_shared.h"

#ifdef __cplusplus
namespace vkcloth::gpu::shared {
#endif

#define VKCLOTH_BINDING_IMPL_VF                                                                              \
  28 // (after VKCLOTH_BINDING_COUNT) contact-filtered velocity, removed force, contact axis (vec4 each)
#define VKCLOTH_BINDING_IMPL_KS 29 // per CSR entry: K_s as 2 vec4 (xx yy zz xy | xz yz - -)
#define VKCLOTH_BINDING_IMPL_BLOCK_INV                                                                       \
  30                              // P^-1: inverse diagonal block of A, 2 vec4 (xx yy zz xy | xz yz - -)
#define VKCLOTH_BINDING_IMPL_X 31 // CG solution dv (vec4), kept between solves (warm start)
#define VKCLOTH_BINDING_IMPL_R 32 // residual
#define VKCLOTH_BINDING_IMPL_Z 33 // preconditioned residual
#define VKCLOTH_BINDING_IMPL_D 34 // search direction
#define VKCLOTH_BINDING_IMPL_Q 35 // S A d
#define VKCLOTH_BINDING_IMPL_PARTIALS 36 // one vec4 per workgroup: its partial dot products (coherent)
#define VKCLOTH_BINDING_IMPL_STATE 37    // CgState
#define VKCLOTH_BINDING_IMPL_ARGS 38     // indirect dispatch arguments (CgArgs)

// implicit.comp passes (PushConstants::stage). SYSTEM, MATVEC and UPDATE end with a reduction:
// every workgroup writes its partial sums, and the LAST workgroup to arrive (CgState::arrived)
// sums them all in a fixed order and updates the CG scalars and the indirect arguments.
#define VKCLOTH_IMPL_FORCE 0u // normal, force, contact filtering -> FORCE_OUT, NORMAL, VF
#define VKCLOTH_IMPL_SYSTEM                                                                                  \
  1u // K_s per entry, P^-1, b, r = b - S A x0 -> r, z, d; partials (r.z, r.r, b.b, w.w);
     // last workgroup: rz, rr, ref2, solves + 1, done?
#define VKCLOTH_IMPL_MATVEC                                                                                  \
  2u // q = S A d; partials (d.q); last workgroup: alpha = rz / d.q (done if d.q <= 0)
#define VKCLOTH_IMPL_UPDATE                                                                                  \
  3u                              // x += alpha d, r -= alpha q, z = P^-1 r; partials (r.z, r.r);
                                  // last workgroup: beta, iterations + 1, done = converged or cap
#define VKCLOTH_IMPL_DIRECTION 4u // d = z + beta d
#define VKCLOTH_IMPL_FINISH 5u    // v' = v + x, contacts, x' = x + h v', projection, flags
#define VKCLOTH_IMPL_SOLVE 6u     // ONE workgroup: up to solve_budget more CG iterations (until done)

/// implicit.comp's push constants (vkcloth_shared.h PushConstants' five fields, then its own).
struct ImplicitPush {
  uint count;
  uint nx;
  uint ny;
  uint stage; // the pass (VKCLOTH_IMPL_*)
  uint step;
  uint cg_max_iterations;
  uint solve_budget; // SOLVE: the CG iterations this dispatch may run
  float tolerance2;  // cg_tolerance^2
};

/// CG scalars, written only by the last workgroup of a reducing pass or by SOLVE (one invocation).
struct CgState {
  float rz;
  float rr;
  float ref2; // the tolerance's reference: max(|S b|^2, |S h M g|^2)
  float alpha;
  float beta;
  uint done; // 1: converged / stopped; the remaining passes are dispatched with zero groups
  uint iterations;
  uint total_iterations; // over every solve since creation (wraps at 2^32)
  uint groups_x;         // the particle passes' dispatch size (set by the host at creation)
  uint groups_y;
  uint solves;  // solves since creation; 0: no dv to warm-start from yet
  uint arrived; // workgroups of the current reducing pass done so far (the last one resets it)
};

/// Indirect dispatch arguments of the per-particle CG passes, rewritten by every reduction:
/// zero groups once `done`.
struct CgArgs {
  uint particle_x, particle_y, particle_z, pad0;
};

#ifdef __cplusplus
static_assert(VKCLOTH_BINDING_IMPL_VF == VKCLOTH_BINDING_COUNT); // right after the main layout's bindings
static_assert(sizeof(CgState) == 48);
static_assert(sizeof(ImplicitPush) == sizeof(PushConstants));
static_assert(sizeof(CgArgs) == 16);
/// The implicit layout's storage bindings, in descriptor-write order: its one binding table
/// (engine/src/vulkan/passes/implicit_update.cpp).
inline constexpr uint implicit_bindings[] = {VKCLOTH_BINDING_POS_IN,     VKCLOTH_BINDING_FORCE_OUT,
                                             VKCLOTH_BINDING_NORMAL,     VKCLOTH_BINDING_POS_OUT,
                                             VKCLOTH_BINDING_VEL,        VKCLOTH_BINDING_PARTICLE,
                                             VKCLOTH_BINDING_OFFSETS,    VKCLOTH_BINDING_EDGES,
                                             VKCLOTH_BINDING_COLLIDERS,  VKCLOTH_BINDING_FLAGS,
                                             VKCLOTH_BINDING_INSTANCES,  VKCLOTH_BINDING_IMPL_VF,
                                             VKCLOTH_BINDING_IMPL_KS,    VKCLOTH_BINDING_IMPL_BLOCK_INV,
                                             VKCLOTH_BINDING_IMPL_X,     VKCLOTH_BINDING_IMPL_R,
                                             VKCLOTH_BINDING_IMPL_Z,     VKCLOTH_BINDING_IMPL_D,
                                             VKCLOTH_BINDING_IMPL_Q,     VKCLOTH_BINDING_IMPL_PARTIALS,
                                             VKCLOTH_BINDING_IMPL_STATE, VKCLOTH_BINDING_IMPL_ARGS,
                                             VKCLOTH_BINDING_MESH_NODES, VKCLOTH_BINDING_MESH_TRIS,
                                             VKCLOTH_BINDING_MESH_CACHE};
} // namespace vkcloth::gpu::shared
#endif

#endif // VKCLOTH_IMPLICIT_SHARED_H
