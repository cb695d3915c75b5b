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

// collider_contact's mesh branch on lanes (defined below, after the kernel).
inline void mesh_contact(const LaneMesh<Isa>& m, ColliderShape s, vec3 q, vec3 p_side, real reach,
                         real& distance, vec3& normal);

#include "kernel/vector.h"
#include "kernel/forces.h"
#include "kernel/contacts.h"
#include "kernel/friction.h"
#include "kernel/integrators.h"
#include "kernel/blocks.h"
#include "kernel/vbd.h"

// The lanes whose entries answer (mesh_cache_hit) take mesh_face_contact on lanes; the others take the
// scalar kernel's mesh_contact lane by lane (the search, which renews their entries): the same
// formulas, so each lane gets the reference's bits.
inline void mesh_contact(const LaneMesh<Isa>& m, ColliderShape s, vec3 q, vec3 p_side, real reach,
                         real& distance, vec3& normal) {
  using R = typename Isa::Real;
  constexpr int W = Isa::W;
  R v[16][W]; // n, centre, radius, then the face's corners a, b, c (zero for other entries)
  for (int l = 0; l < W; ++l) {
    vkcloth::kernel::MeshData md = *m.mesh;
    md.particle = m.particle(l);
    glm::vec<3, R> n, centre, a(0), b(0), c(0);
    std::uint32_t tri;
    R radius;
    vkcloth::kernel::mesh_cache_load(md, m.scalar->mesh_cache, n, tri, centre, radius);
    if (n != glm::vec<3, R>(0))
      vkcloth::kernel::mesh_triangle(md, tri, a, b, c);
    const R row[16] = {n.x, n.y, n.z, centre.x, centre.y, centre.z, radius, a.x,
                       a.y, a.z, b.x, b.y,      b.z,      c.x,      c.y,    c.z};
    for (int k = 0; k < 16; ++k)
      v[k][l] = row[k];
  }
  auto lanes = [&](int k) {
    real r;
    __builtin_memcpy(&r.v, v[k], sizeof r.v);
    return r;
  };
  auto lanes3 = [&](int k) { return vec3(lanes(k), lanes(k + 1), lanes(k + 2)); };
  const vec3 n = lanes3(0), a = lanes3(7);
  const varying<bool> hit = mesh_cache_hit(n, lanes3(3), lanes(6), a, lanes3(10), lanes3(13), q, s.b + reach);
  mesh_face_contact(s, n, a, q, p_side, reach, distance, normal);
  for (int l = 0; l < W; ++l) {
    if (hit.m[l])
      continue;
    vkcloth::kernel::MeshData md = *m.mesh;
    md.particle = m.particle(l);
    const glm::vec<3, R> ql(q.x.v[l], q.y.v[l], q.z.v[l]), sl(p_side.x.v[l], p_side.y.v[l], p_side.z.v[l]);
    R d;
    glm::vec<3, R> nl;
    vkcloth::kernel::mesh_contact(md, *m.scalar, ql, sl, reach.v[l], d, nl);
    distance.v[l] = d;
    normal.x.v[l] = nl.x;
    normal.y.v[l] = nl.y;
    normal.z.v[l] = nl.z;
  }
}
