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
                         real& distance, vec3& normal, vec3& deform);

#include "kernel/vector.h"
#include "kernel/forces.h"
#include "kernel/contacts.h"
#include "kernel/friction.h"
#include "kernel/integrators.h"
#include "kernel/blocks.h"
#include "kernel/vbd.h"

// The lanes whose entries answer (mesh_cache_hit) take mesh_face_contact (and a skinned mesh's
// triangle_velocity) on lanes; the others take the scalar kernel's mesh_contact lane by lane (the
// search, which renews their entries): the same formulas, so each lane gets the reference's bits.
inline void mesh_contact(const LaneMesh<Isa>& m, ColliderShape s, vec3 q, vec3 p_side, real reach,
                         real& distance, vec3& normal, vec3& deform) {
  using R = typename Isa::Real;
  using V = glm::vec<3, R>;
  constexpr int W = Isa::W;
  const bool skinned = deforming(s);
  // Per lane: n, centre, radius, the face's corners a, b, c and their velocities (zero for other entries).
  R v[25][W];
  for (int l = 0; l < W; ++l) {
    vkcloth::kernel::MeshData md = *m.mesh;
    md.particle = m.particle(l);
    V n, centre, a(0), b(0), c(0), va(0), vb(0), vc(0);
    std::uint32_t tri;
    R radius;
    vkcloth::kernel::mesh_cache_load(md, m.scalar->mesh_cache, n, tri, centre, radius);
    if (n != V(0)) {
      vkcloth::kernel::mesh_triangle(md, tri, a, b, c);
      if (skinned)
        vkcloth::kernel::mesh_velocity(md, m.scalar->mesh_vel0 + (tri - m.scalar->mesh_tri0), va, vb, vc);
    }
    // Rows 0-2 n, 3-5 centre, 6 radius, 7-15 a, b, c, 16-24 va, vb, vc.
    auto put3 = [&](int k, V x) {
      for (int d = 0; d < 3; ++d)
        v[k + d][l] = x[d];
    };
    put3(0, n);
    put3(3, centre);
    v[6][l] = radius;
    put3(7, a);
    put3(10, b);
    put3(13, c);
    if (skinned) {
      put3(16, va);
      put3(19, vb);
      put3(22, vc);
    }
  }
  auto lanes = [&](int k) {
    real r;
    __builtin_memcpy(&r.v, v[k], sizeof r.v);
    return r;
  };
  auto lanes3 = [&](int k) { return vec3(lanes(k), lanes(k + 1), lanes(k + 2)); };
  const vec3 n = lanes3(0), a = lanes3(7), b = lanes3(10), c = lanes3(13);
  const varying<bool> hit = mesh_cache_hit(n, lanes3(3), lanes(6), a, b, c, q, s.b + reach);
  mesh_face_contact(s, n, a, q, p_side, reach, distance, normal);
  deform = vec3(real(0));
  if (skinned) // at q's foot on the face, as contacts.h mesh_contact's entry hit
    deform =
        triangle_velocity(s, q - n * (dot3(q, n) - dot3(a, n)), a, b, c, lanes3(16), lanes3(19), lanes3(22));
  for (int l = 0; l < W; ++l) {
    if (hit.m[l])
      continue;
    vkcloth::kernel::MeshData md = *m.mesh;
    md.particle = m.particle(l);
    const V ql(q.x.v[l], q.y.v[l], q.z.v[l]), sl(p_side.x.v[l], p_side.y.v[l], p_side.z.v[l]);
    R d;
    V nl, dl;
    vkcloth::kernel::mesh_contact(md, *m.scalar, ql, sl, reach.v[l], d, nl, dl);
    distance.v[l] = d;
    normal.x.v[l] = nl.x;
    normal.y.v[l] = nl.y;
    normal.z.v[l] = nl.z;
    deform.x.v[l] = dl.x;
    deform.y.v[l] = dl.y;
    deform.z.v[l] = dl.z;
  }
}
