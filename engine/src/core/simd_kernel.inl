// SPDX-License-Identifier: MIT
// The shared kernel on SIMD lanes of ISA traits `Isa` (row_kernel_simd.inl includes this file once
// per precision, in a namespace that names Isa, with the bridge's macros defined): real = W lanes,
// vec3 = three of them, VARYING(bool) / VARYING(uint) = lanes of conditions / uints (simd_lanes.inl).
// A plain bool or uint is uniform (the same for every lane), and so is the collider: shapes.h is
// compiled with scalar real and vec3, and the contact functions take its values as broadcast lanes.
// No include guard: included twice.

using real = Lanes<Isa>;
using vec3 = Lanes3<Isa>;
using uint = std::uint32_t;
template <typename X> using varying = typename Varying<Isa, X>::type;

namespace uniform {
using real = typename Isa::Real;
using vec3 = Uniform3<Isa>;
#include "kernel/shapes.h"
} // namespace uniform
using uniform::ColliderShape;
using uniform::has_friction;
using uniform::still_frictionless;
using uniform::without_friction;

// No mesh collider reaches the lanes (CpuSolver takes a mesh's particles one by one): collider_contact's
// mesh branch is never taken here.
inline void mesh_contact(NoMesh, ColliderShape, vec3, vec3, real, real&, vec3&) {
  __builtin_trap();
}

#include "kernel/vector.h"
#include "kernel/forces.h"
#include "kernel/contacts.h"
#include "kernel/friction.h"
#include "kernel/integrators.h"
#include "kernel/blocks.h"
#include "kernel/vbd.h"
