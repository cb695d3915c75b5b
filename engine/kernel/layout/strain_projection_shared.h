// SPDX-License-Identifier: MIT
// Declarations shared by strain_project.comp and the C++ side (engine/src/vulkan/
// passes/strain_projection_gpu.cpp). The fast projection's pass uses its own descriptor set layout: the
// main layout's bindings it needs (same numbers, same buffers, vkcloth_shared.h) plus its own
// below. Push constants: ProjectionPush below.
#ifndef VKCLOTH_STRAIN_PROJECTION_SHARED_H
#define VKCLOTH_STRAIN_PROJECTION_SHARED_H

#include "kernel/layout/self_collision_shared.h"

#ifdef __cplusplus
namespace vkcloth::gpu::shared {
#endif

#define VKCLOTH_BINDING_PROJ_INCIDENCE                                                                       \
  51 // uint: the topology's strain_incidence_offsets, then its strain_incidence
#define VKCLOTH_BINDING_PROJ_LINKS 52  // 2 vec4 per link per instance: (g, 1 / A_ll), (lambda, r, d, q)
#define VKCLOTH_BINDING_PROJ_GATHER 53 // vec4 per particle per instance: grad C^T of d or lambda
#define VKCLOTH_BINDING_PROJ_STATE 54  // ProjState per instance
#define VKCLOTH_BINDING_PROJ_ARGS 55   // ProjArgsHead, then a uint per instance: reset every substep

// The phases of one Newton iteration (ProjState::phase), as CpuSolver::project_strain runs them.
#define VKCLOTH_PROJ_LINKS 0u     // per link: C, g, in the solve, r = d = rhs; sums r.z, r.r; max C
#define VKCLOTH_PROJ_GATHER 1u    // per particle: grad C^T d
#define VKCLOTH_PROJ_MATVEC 2u    // per link: q = A d; sum d.q -> alpha
#define VKCLOTH_PROJ_UPDATE 3u    // per link: lambda += alpha d, r -= alpha q; sums -> beta
#define VKCLOTH_PROJ_DIRECTION 4u // per link: d = z + beta d
#define VKCLOTH_PROJ_APPLY 5u     // per particle: x -= W grad C^T lambda (v follows)
#define VKCLOTH_PROJ_DONE 6u      // this substep's projection is over

// llvmpipe stops every loop of an invocation after 65 535 iterations in all (silently); one
// dispatch runs as many phases as keep each invocation under this many (pc.phase_budget).
#define VKCLOTH_PROJ_LOOP_BUDGET 30000u

/// Where one instance's projection stands between dispatches (std430: 48 bytes).
struct ProjState {
  uint phase;  // VKCLOTH_PROJ_*
  uint newton; // Newton iterations done
  uint cg;     // CG iterations of this solve done
  uint pad;
  float rz, rr, stop, alpha; // r.z, r.r, the solve's |r|^2 target, the step
  float beta, pad1, pad2, pad3;
};

/// The indirect arguments of the substep's dispatches (x, y, z: 1, 1, instances, written by the host
/// before the first) and which instances are done: the last to finish sets x = 0, so that the
/// dispatches left are empty (std430: 16 bytes, then one uint per instance).
struct ProjArgsHead {
  uint x, y, z;
  uint finished; // instances done (or without the projection) this substep
};

/// strain_project.comp's push constants (PushConstants' five fields, then its own).
struct ProjectionPush {
  uint count;
  uint nx;
  uint ny;
  uint stage; // the dispatch within the substep (0 starts the projection over)
  uint step;
  uint links;        // strain links of the topology
  uint cg_cap;       // the most CG iterations of one solve (kernel.hpp projection_cg_cap)
  uint phase_budget; // the phases one dispatch may run (its loop budget)
};

#ifdef __cplusplus
static_assert(sizeof(ProjectionPush) == sizeof(PushConstants));
static_assert(VKCLOTH_BINDING_PROJ_INCIDENCE == VKCLOTH_BINDING_SELF_STALE + 1);
static_assert(sizeof(ProjState) == 48);
static_assert(sizeof(ProjArgsHead) == 16);
/// The projection's storage bindings, in descriptor-write order: its one binding table
/// (engine/src/vulkan/passes/stretch.cpp).
inline constexpr uint strain_project_bindings[] = {
    VKCLOTH_BINDING_POS_OUT,        VKCLOTH_BINDING_VEL,        VKCLOTH_BINDING_PARTICLE,
    VKCLOTH_BINDING_FLAGS,          VKCLOTH_BINDING_INSTANCES,  VKCLOTH_BINDING_STRAIN_LINKS,
    VKCLOTH_BINDING_PROJ_INCIDENCE, VKCLOTH_BINDING_PROJ_LINKS, VKCLOTH_BINDING_PROJ_GATHER,
    VKCLOTH_BINDING_PROJ_STATE,     VKCLOTH_BINDING_PROJ_ARGS};
} // namespace vkcloth::gpu::shared
#endif

#endif // VKCLOTH_STRAIN_PROJECTION_SHARED_H
