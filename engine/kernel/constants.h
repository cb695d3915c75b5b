// SPDX-License-Identifier: MIT
// vkcloth kernel: the constants of the physics, shared by the kernel (GLSL and C++), the CPU
// solver and the GPU passes. Only #defines, so it is valid GLSL and C++; the C++ enums they mirror
// are asserted equal in engine/src/internal/kernel.hpp. The GPU's binding layout is elsewhere
// (engine/kernel/layout/vkcloth_shared.h): the CPU includes this file, never that one.
#ifndef VKCLOTH_KERNEL_CONSTANTS_H
#define VKCLOTH_KERNEL_CONSTANTS_H

// Invocations per workgroup (1-D). It is also the reduction order of the sums both backends
// compute in blocks (the fast projection's dot products). Dispatches round up and every shader
// guards `p < count`.
#define VKCLOTH_WORKGROUP_SIZE 64

// Edge::ring bits (ClothTopology's ring-ordered gather lists, cloth_kernel.h add_ring_term): the
// fan triangle (a, b) of a particle adds cross(x_a - x, x_b - x) to its normal; a chain of fan
// triangles (r0, r1), (r1, r2), ... is carried by consecutive entries r0, r1, r2, ...
#define VKCLOTH_RING_START 1u // the first entry of a chain: remember its edge
#define VKCLOTH_RING_PREV 2u  // add the triangle (previous entry, this entry)
#define VKCLOTH_RING_CLOSE 4u // then add the triangle (this entry, the chain's first entry)

// InstanceParams::stretch bits (SimParams::stretch_limit).
#define VKCLOTH_STRETCH_PROVOT 1u     // Provot sweeps over the strain links (strain_links.comp)
#define VKCLOTH_STRETCH_TETHERS 2u    // tethers (strain_finish.comp)
#define VKCLOTH_STRETCH_GEODESIC 4u   // tethers with geodesic rest lengths (the second half of TETHERS)
#define VKCLOTH_STRETCH_PROJECTION 8u // the fast projection (strain_project.comp)
#define VKCLOTH_STRETCH_CHAINS 16u    // Provot's sweeps along a grid's rows and columns (strain_links.comp)
#define VKCLOTH_CHAIN_BACKWARD 0x80000000u // StrainLinksPush::chain_links: the chains' pass back
#define VKCLOTH_TETHERS_PER_PARTICLE 4u    // vkcloth::tethers_per_particle
#define VKCLOTH_NO_TETHER 0xffffffffu      // an unused tether slot (vkcloth::no_tether)
// The fast projection (cloth_kernel.h projection_*, docs/model.md "Stretch control"): links whose
// C = |u|^2 / B^2 - 1 is above -BAND take part in a Newton iteration's solve (those within the band
// keep their length, so the solve cannot stretch them past the bound); the projection stops once
// every link's strain is within TOLERANCE of max_strain; each solve is Jacobi-preconditioned CG
// to |r|^2 <= CG_TOL2 |r0|^2, at most cg_cap(links) iterations (projection_cg_cap).
#define VKCLOTH_PROJECTION_BAND 0.01
#define VKCLOTH_PROJECTION_TOLERANCE 1.0e-4
#define VKCLOTH_PROJECTION_CG_TOL2 1.0e-8

// InstanceParams::integrator (the vkcloth::Integrator values; engine/src/internal/kernel.hpp asserts it).
#define VKCLOTH_INTEGRATOR_EXPLICIT_EULER 0u
#define VKCLOTH_INTEGRATOR_SEMI_IMPLICIT_EULER 1u
#define VKCLOTH_INTEGRATOR_RK4 2u
#define VKCLOTH_INTEGRATOR_IMPLICIT_EULER 3u
#define VKCLOTH_INTEGRATOR_VBD 4u

// Collider::type (the vkcloth::Collider::Type values; engine/src/internal/kernel.hpp asserts it).
#define VKCLOTH_COLLIDER_PLANE 0u
#define VKCLOTH_COLLIDER_SPHERE 1u
#define VKCLOTH_COLLIDER_CAPSULE 2u
#define VKCLOTH_COLLIDER_BOX 3u
#define VKCLOTH_COLLIDER_MESH 4u
// No triangle (a mesh search that found none; a mesh collider without corner velocities).
#define VKCLOTH_MESH_NONE 0xffffffffu
#define VKCLOTH_COLLIDER_ALL_TYPES 0x1fu // bit t for every type t above (SC_COLLIDER_TYPES)

// Self-collision's buckets per workgroup of the GPU's SCAN_BLOCKS pass (64 invocations x 8): the
// hash table's size is a multiple of it on both backends (kernel.hpp self_table_size).
#define VKCLOTH_SELF_SCAN_BLOCK 512u
// The most entries of a particle's self-collision neighbour list (self_collide_listed: past it, the
// particle walks the build's cells instead).
#define VKCLOTH_SELF_LIST_CAPACITY 32u
// Self-contact friction in vbd's sweeps (self_energy): a relative slip over the step slower than
// this (m/s) is held as static friction, a stiff spring of force mu lambda at slip speed * h; the
// tolerance of IPC's smoothed friction (Li et al. 2020), which vbd's Gaia takes over.
#define VKCLOTH_SELF_FRICTION_SLIP_SPEED 1e-3

#endif // VKCLOTH_KERNEL_CONSTANTS_H
