// SPDX-License-Identifier: MIT
// The kernel's language contract, defined once: the macros cloth_kernel.h is written against (its
// header comment says what each means), for each language that compiles it:
//   GLSL            (no __cplusplus): shaders/include/common.glsl, before cloth_kernel.h;
//   C++, scalar     engine/src/internal/kernel.hpp, once for float and once for double;
//   C++, on lanes   VKCLOTH_KERNEL_LANES defined: engine/src/core/row_kernel_simd.inl, W particles
//                   per value (varying<T>, LaneMesh, any_particle a function of the lanes' mask).
// Each inclusion first removes the previous one's definitions, so a C++ file can switch from the
// scalar contract to the lanes' one and back; VKCLOTH_KERNEL_LANGUAGE_END only removes them (the
// end of each C++ bridge, so that no macro leaks into the rest of the engine).
// Left to the includer, because they name its own data: real and vec3, the mesh and self-collision
// accessors (mesh_node, self_range, ...), GLSL's SELF_DATA_PARAM (defined only by the shaders that
// walk self-collision's table) and GLSL's VKCLOTH_COLLIDER_PRESENT (a specialisation constant).
// No include guard: included once per switch.

#undef KFN
#undef KFN_NOINLINE
#undef OUT
#undef INOUT
#undef VARYING
#undef any_particle
#undef maybe_any_particle
#undef MESH_DATA_PARAM
#undef MESH_DATA
#ifdef __cplusplus
#undef precise
#undef VKCLOTH_COLLIDER_PRESENT
#undef VKCLOTH_KERNEL_NO_MESH
#undef SELF_DATA_PARAM
#undef SELF_DATA
#endif

#ifndef VKCLOTH_KERNEL_LANGUAGE_END
#ifndef __cplusplus // GLSL
#define real float
#define KFN
#define KFN_NOINLINE
#define OUT(T) out T
#define INOUT(T) inout T
#define VARYING(T) T
#define select(c, a, b) ((c) ? (a) : (b))
#define any_particle(c) (c)
#define maybe_any_particle(c) (c)
#define MESH_DATA_PARAM uint mesh_data // the particle: the mesh buffers are global
#define MESH_DATA mesh_data
#else // C++: every kernel function inlined into its caller (GCC's own choice varies with their size,
      // and an out-of-line collider_contact costs the contact path ~40 %), but the mesh search
#define KFN inline __attribute__((always_inline))
#define KFN_NOINLINE inline __attribute__((noinline))
#define OUT(T) T&
#define INOUT(T) T&
#define precise // -ffp-contract=off does what GLSL's precise does
#define VKCLOTH_COLLIDER_PRESENT(type) true
#ifdef VKCLOTH_KERNEL_LANES // W particles per value; any_particle is the lanes' Mask's function
#define VARYING(T) varying<T>
#define MESH_DATA_PARAM const LaneMesh<Isa>& mesh_data
#define MESH_DATA mesh_data
#define VKCLOTH_KERNEL_NO_MESH // the mesh search runs per particle (simd_kernel.inl)
#else
#define VARYING(T) T
#define any_particle(c) (c)
#define maybe_any_particle(c) (c)
#define MESH_DATA_PARAM const MeshData& mesh_data
#define MESH_DATA mesh_data
#define SELF_DATA_PARAM const SelfData& self_data
#define SELF_DATA self_data
#endif
#endif
#endif // VKCLOTH_KERNEL_LANGUAGE_END
