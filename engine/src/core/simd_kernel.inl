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
  using V = typename Isa::V;
  using Triangle = vkcloth::ColliderMesh::Triangle;
  constexpr int W = Isa::W;
  const bool skinned = deforming(s);
  const vkcloth::kernel::MeshData& md = *m.mesh;
  // Each lane's entry (kernel.hpp mesh_cache_load: n, the triangle's index, centre, radius; all zero
  // without entries), gathered as two rows of four.
  V e[8];
  if (!md.cache)
    std::fill(e, e + 8, V{});
  else {
    std::uint32_t at[W];
    for (int l = 0; l < W; ++l)
      at[l] = 8 * (m.scalar->mesh_cache + m.particle(l));
    Isa::gather4(static_cast<const R*>(md.cache), at, e[0], e[1], e[2], e[3]);
    Isa::gather4(static_cast<const R*>(md.cache) + 4, at, e[4], e[5], e[6], e[7]);
  }
  auto lanes = [](V x) { return real(x); };
  const vec3 n(lanes(e[0]), lanes(e[1]), lanes(e[2]));
  // A face or edge entry names a triangle; the others read the first and take zeros.
  const varying<bool> named = n.x != real(0) || n.y != real(0) || n.z != real(0);
  // Each lane's rows: its triangle's (row_tri) and, skinned, its corner velocities' (row_vel), in
  // floats (ColliderMesh::Triangle: 12 of them, a corner and a clearance a row); scalar stores that
  // gather4 reads back one at a time (a vector load of them would wait for each store).
  static_assert(sizeof(Triangle) == 12 * sizeof(float) && offsetof(Triangle, b) == 16 &&
                offsetof(Triangle, c) == 32);
  std::uint32_t row_tri[W], row_vel[W];
  for (int l = 0; l < W; ++l) {
    const std::uint32_t tri = named.m[l] ? vkcloth::kernel::mesh_cache_uint(e[3][l]) : m.scalar->mesh_tri0;
    row_tri[l] = 12 * tri;
    row_vel[l] = 12 * (m.scalar->mesh_vel0 + (tri - m.scalar->mesh_tri0));
  }
  // The three corners in the rows `at` names (zeros for a lane without a triangle).
  auto corners = [&](const Triangle* rows, const std::uint32_t* at, vec3& a, vec3& b, vec3& c) {
    const float* f = reinterpret_cast<const float*>(rows);
    V t[12];
    for (int k = 0; k < 3; ++k)
      Isa::gather4(f + 4 * k, at, t[4 * k], t[4 * k + 1], t[4 * k + 2], t[4 * k + 3]);
    const vec3 zero(real(0));
    a = select(named, vec3(lanes(t[0]), lanes(t[1]), lanes(t[2])), zero);
    b = select(named, vec3(lanes(t[4]), lanes(t[5]), lanes(t[6])), zero);
    c = select(named, vec3(lanes(t[8]), lanes(t[9]), lanes(t[10])), zero);
  };
  vec3 a, b, c;
  corners(md.triangles, row_tri, a, b, c);
  const vec3 centre(lanes(e[4]), lanes(e[5]), lanes(e[6]));
  const varying<bool> hit = mesh_cache_hit(n, centre, lanes(e[7]), a, b, c, q, s.b + reach);
  mesh_face_contact(s, n, a, q, p_side, reach, distance, normal);
  deform = vec3(real(0));
  if (skinned) { // at q's foot on the face, as contacts.h mesh_contact's entry hit
    vec3 va, vb, vc;
    corners(md.velocities, row_vel, va, vb, vc);
    deform = triangle_velocity(s, q - n * (dot3(q, n) - dot3(a, n)), a, b, c, va, vb, vc);
  }
  const varying<bool> miss = !hit;
  if (!any_particle(miss))
    return;
  for (int l = 0; l < W; ++l) {
    if (!miss.m[l])
      continue;
    vkcloth::kernel::MeshData ml = md;
    ml.particle = m.particle(l);
    const glm::vec<3, R> ql(q.x.v[l], q.y.v[l], q.z.v[l]), sl(p_side.x.v[l], p_side.y.v[l], p_side.z.v[l]);
    R d;
    glm::vec<3, R> nl, dl;
    vkcloth::kernel::mesh_contact(ml, *m.scalar, ql, sl, reach.v[l], d, nl, dl);
    distance.v[l] = d;
    normal.x.v[l] = nl.x;
    normal.y.v[l] = nl.y;
    normal.z.v[l] = nl.z;
    deform.x.v[l] = dl.x;
    deform.y.v[l] = dl.y;
    deform.z.v[l] = dl.z;
  }
}
