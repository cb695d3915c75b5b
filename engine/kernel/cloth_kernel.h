// SPDX-License-Identifier: MIT
// The per-particle physics of vkcloth, written ONCE for both backends: the compute shaders
// include this file as GLSL (through common.glsl) and the CPU reference solver compiles it as
// C++ (through engine/src/internal/kernel.hpp, with GLM, for float and for double), as Jolt's
// HairIntegrate.h is shared by its HLSL and its C++ solver. The equations: docs/model.md.
//
// Rules that keep CPU and GPU bit-identical (on lavapipe; a real GPU may round sqrt/division
// differently):
// - Every expression is written out in one fixed order, and every result lands in a `precise`
//   variable, so the shader compiler may neither reassociate nor fuse it into an FMA (the C++
//   side builds with -ffp-contract=off; `precise` is empty there).
// - Literals are `real(...)`: a bare 2.0 would be a double in C++.
// - A condition on a per-particle value chooses with select(c, a, b) (c ? a : b), both computed, never
//   with an `if` or `?:`: the CPU's SIMD kernels (engine/src/core/row_kernel_simd.inl) run forces.h,
//   contacts.h, friction.h and integrators.h on lanes of W particles, where such a condition is a mask
//   (a C++ compile error there if it reaches an `if`). real and vec3 values are per particle; a bool
//   or uint that is per particle is declared VARYING(bool) / VARYING(uint); a plain bool or uint (a flag, a
//   collider's type, shapes.h) is the same for every particle of a call and may branch. Work that no
//   particle of the call needs may be skipped: `if (!any_particle(c)) return;` (c itself for one
//   particle; on lanes, some lane's c), or where the lanes would almost never skip (a spring's
//   `len > 0`) `if (!maybe_any_particle(c)) return;` (c for one particle; true on lanes, untested).
//   Exempt: the mesh search (contacts.h, VKCLOTH_KERNEL_NO_MESH) and the headers the lanes do not
//   include.
// - Pure functions of values: no buffer (a mesh collider's hierarchy is read through the including
//   file's accessors), no loop over particles or colliders. Each caller
//   gathers its inputs its own way (texel fetches, std::vector) and loops itself.
//
// The language macros below are defined once, per language, in kernel/language.h, which the
// including file includes first. Provided by the including file: real, vec3, uint, KFN (function prefix:
// `inline` and always inlined in C++), KFN_NOINLINE (the mesh search's prefix: kept out of line in C++),
// OUT(T) / INOUT(T) (out / inout parameters: T& in C++), precise, VARYING(T) (T; see above),
// select(c, a, b) (c ? a : b), any_particle(c) and maybe_any_particle(c) (c), sqrt, abs, min, max, and
// all_finite(vec3) (no component is NaN or inf); for mesh colliders MESH_DATA_PARAM / MESH_DATA
// (the mesh buffers: a dummy uint in GLSL, whose buffers are global), mesh_node and mesh_triangle;
// floor; for self_collide (only where SELF_DATA_PARAM is defined) SELF_DATA_PARAM / SELF_DATA,
// self_range, self_entry, self_particle and self_velocity;
// VKCLOTH_COLLIDER_PRESENT(type): false only when no collider of that type can reach the caller
// (C++: always true; GLSL: a specialisation constant, so that the absent shapes' code is compiled
// out, since llvmpipe runs every branch of a non-uniform `if`). It changes no result.
// Constants: constants.h (included here).
// No include guard: kernel.hpp includes this file once per precision, in two namespaces.

// One header per concern, in dependency order.
#include "constants.h"
#include "vector.h"
#include "forces.h"
#include "shapes.h"
#include "contacts.h"
#include "friction.h"
#include "strain.h"
#include "attach.h"
#include "integrators.h"
#include "blocks.h"
#include "implicit.h"
#include "vbd.h"
// self_collision.h after vbd.h: its contact energy is a vbd spring.
#include "self_collision.h"
