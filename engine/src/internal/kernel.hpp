// SPDX-License-Identifier: MIT
// The per-particle physics as C++: engine/kernel/cloth_kernel.h, the one source the compute
// shaders include too, compiled here with GLM (which follows GLSL's syntax) once for float
// (kernel::f32, CpuSolver<float>: the GPU's bits) and once for double (kernel::f64). Both sets
// are visible in vkcloth::kernel; overloading on the vector type picks the precision.
// The GLSL side of the same bridge: shaders/include/common.glsl.
#pragma once

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>
#include <type_traits>

#include <glm/vec3.hpp>

#include "vkcloth/collider_mesh.hpp"
#include "vkcloth/params.hpp"
#include "kernel/constants.h"

// The shader constants the kernel compares against are the C++ enums' values.
static_assert(VKCLOTH_COLLIDER_PLANE == std::uint32_t(vkcloth::Collider::Type::plane));
static_assert(VKCLOTH_COLLIDER_SPHERE == std::uint32_t(vkcloth::Collider::Type::sphere));
static_assert(VKCLOTH_COLLIDER_CAPSULE == std::uint32_t(vkcloth::Collider::Type::capsule));
static_assert(VKCLOTH_COLLIDER_BOX == std::uint32_t(vkcloth::Collider::Type::box));
static_assert(VKCLOTH_COLLIDER_MESH == std::uint32_t(vkcloth::Collider::Type::mesh));
static_assert(VKCLOTH_INTEGRATOR_EXPLICIT_EULER == std::uint32_t(vkcloth::Integrator::explicit_euler));
static_assert(VKCLOTH_INTEGRATOR_SEMI_IMPLICIT_EULER ==
              std::uint32_t(vkcloth::Integrator::semi_implicit_euler));
static_assert(VKCLOTH_INTEGRATOR_RK4 == std::uint32_t(vkcloth::Integrator::rk4));
static_assert(VKCLOTH_INTEGRATOR_IMPLICIT_EULER == std::uint32_t(vkcloth::Integrator::implicit_euler));
static_assert(VKCLOTH_INTEGRATOR_VBD == std::uint32_t(vkcloth::Integrator::vbd));

#include "kernel/language.h" // the kernel's macros, scalar C++

namespace vkcloth::kernel {

// What cloth_kernel.h expects besides real and vec3; the nested namespaces below find these.
using uint = std::uint32_t;
using std::abs;
using std::floor;
using std::max;
using std::min;
using std::sqrt;
// c ? a : b (a function: on two GLM vector lvalues `?:` picks an lvalue, which GCC copies through
// memory in the springs' loop).
template <typename T> inline __attribute__((always_inline)) T select(bool c, T a, T b) {
  return c ? a : b;
}
template <typename V> bool all_finite(V v) {
  return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z);
}

/// A mesh collider's hierarchy and triangles (ColliderMesh's arrays, read in place), the particles'
/// search entries (cloth_kernel.h mesh_contact: 8 reals each, in the solver's precision; null:
/// none, every query searches) and the particle a query is for; the accessors cloth_kernel.h
/// mesh_contact reads them with (the mesh in float, converted to the solver's precision).
struct MeshData {
  const ColliderMesh::Node* nodes = nullptr;
  const ColliderMesh::Triangle* triangles = nullptr;
  void* cache = nullptr;
  std::uint32_t particle = 0;
  const ColliderMesh::Triangle* velocities = nullptr; ///< a skinned mesh's corner velocities
  const std::uint32_t* neighbours = nullptr;          ///< ColliderMesh::neighbours (null: none)
  std::uint64_t* node_visits = nullptr;               ///< counts the search's node reads (tests)
};
template <typename V> void mesh_node(const MeshData& m, uint i, V& lo, uint& first, V& hi, uint& count) {
  if (m.node_visits)
    ++*m.node_visits;
  const ColliderMesh::Node& n = m.nodes[i];
  lo = V(n.lo);
  hi = V(n.hi);
  first = n.first;
  count = n.count;
}
template <typename V> void mesh_triangle(const MeshData& m, uint i, V& a, V& b, V& c) {
  const ColliderMesh::Triangle& t = m.triangles[i];
  a = V(t.a);
  b = V(t.b);
  c = V(t.c);
}
/// A particle's search entry (cloth_kernel.h mesh_contact): 8 reals; the triangle's index is stored
/// as the bits of a float (double: as its value).
template <typename R> R mesh_cache_word(uint w) {
  if constexpr (sizeof(R) == sizeof(uint))
    return std::bit_cast<R>(w);
  else
    return R(w);
}
template <typename R> uint mesh_cache_uint(R w) {
  if constexpr (sizeof(R) == sizeof(uint))
    return std::bit_cast<uint>(w);
  else
    return uint(w);
}
template <typename R> R* mesh_cache_entry(const MeshData& m, uint slot) {
  return static_cast<R*>(m.cache) + 8 * (std::size_t(slot) + m.particle);
}
/// The triangle across edge k of triangle i (the mesh's own indices; VKCLOTH_MESH_NONE: none).
inline uint mesh_neighbour(const MeshData& m, uint /*adj0*/, uint i, uint k) {
  return m.neighbours ? m.neighbours[3 * std::size_t(i) + k] : VKCLOTH_MESH_NONE;
}
template <typename R> void mesh_clearance(const MeshData& m, uint i, R& front, R& back) {
  front = R(m.triangles[i].clearance_front);
  back = R(m.triangles[i].clearance_back);
}
template <typename V> void mesh_velocity(const MeshData& m, uint i, V& va, V& vb, V& vc) {
  const ColliderMesh::Triangle& t = m.velocities[i];
  va = V(t.a);
  vb = V(t.b);
  vc = V(t.c);
}
template <typename V, typename R>
void mesh_cache_load(const MeshData& m, uint slot, V& n, uint& tri, V& centre, R& radius) {
  if (!m.cache) {
    n = centre = V(0);
    tri = 0;
    radius = R(0);
    return;
  }
  const R* e = mesh_cache_entry<R>(m, slot);
  n = V(e[0], e[1], e[2]);
  tri = mesh_cache_uint(e[3]);
  centre = V(e[4], e[5], e[6]);
  radius = e[7];
}
template <typename V, typename R>
void mesh_cache_store(const MeshData& m, uint slot, V n, uint tri, V centre, R radius) {
  if (!m.cache)
    return;
  R* e = mesh_cache_entry<R>(m, slot);
  const R w[8] = {n.x, n.y, n.z, mesh_cache_word<R>(tri), centre.x, centre.y, centre.z, radius};
  std::copy(w, w + 8, e);
}
/// Self-collision's spatial hash as cloth_kernel.h self_collide walks it, in the solver's precision:
/// the table (`start`: each bucket's first entry, size + 1 of them; `sorted`: the particles, by bucket
/// and then index; `key`: each particle's cell key when sorted) and the particles' state, read in
/// place (CpuSolver::self_collide).
template <typename Real> struct SelfDataT {
  const std::uint32_t* start = nullptr;
  const std::uint32_t* sorted = nullptr;
  const std::uint32_t* key = nullptr;
  const glm::vec<3, Real>* pos = nullptr;
  const glm::vec<3, Real>* vel = nullptr;
  const Real* inv_mass = nullptr;
  const glm::vec<3, Real>* rest = nullptr;
  std::uint32_t* list = nullptr; // the neighbour lists: VKCLOTH_SELF_LIST_CAPACITY entries per particle
  // In table order (optional: null reads through the particle): each entry's key, and its
  // particle's position and rest position as the table was built (self_entry_particle: the list
  // build walks them as contiguous memory).
  const std::uint32_t* sorted_key = nullptr;
  const glm::vec<3, Real>* entry_pos = nullptr;
  const glm::vec<3, Real>* entry_rest = nullptr;
  // vbd's contact energy (optional): the positions at the step's start; self_velocity then gives each
  // particle's move since then in place of its velocity (self_energy's friction).
  const glm::vec<3, Real>* step_start = nullptr;
};
template <typename Real> void self_range(const SelfDataT<Real>& d, uint b, uint& first, uint& stop) {
  first = d.start[b];
  stop = d.start[b + 1];
}
template <typename Real> void self_entry(const SelfDataT<Real>& d, uint i, uint& q, uint& key) {
  q = d.sorted[i];
  key = d.sorted_key ? d.sorted_key[i] : d.key[q];
}
template <typename Real, typename V>
void self_entry_particle(const SelfDataT<Real>& d, uint i, uint q, V& x, V& rest) {
  x = d.entry_pos ? d.entry_pos[i] : d.pos[q];
  rest = d.entry_rest ? d.entry_rest[i] : d.rest[q];
}
template <typename Real> void self_list_put(const SelfDataT<Real>& d, uint p, uint slot, uint q) {
  d.list[std::size_t(p) * VKCLOTH_SELF_LIST_CAPACITY + slot] = q;
}
template <typename Real> uint self_list_get(const SelfDataT<Real>& d, uint p, uint i) {
  return d.list[std::size_t(p) * VKCLOTH_SELF_LIST_CAPACITY + i];
}
template <typename Real, typename V>
void self_particle(const SelfDataT<Real>& d, uint q, V& x, Real& w, V& rest) {
  x = d.pos[q];
  w = d.inv_mass[q];
  rest = d.rest[q];
}
template <typename Real> glm::vec<3, Real> self_velocity(const SelfDataT<Real>& d, uint q) {
  return d.step_start ? glm::vec<3, Real>(d.pos[q] - d.step_start[q]) : d.vel[q];
}

namespace f32 {
using real = float;
using vec3 = glm::vec3;
using SelfData = SelfDataT<float>;
#include "kernel/cloth_kernel.h"
} // namespace f32

namespace f64 {
using real = double;
using vec3 = glm::dvec3;
using SelfData = SelfDataT<double>;
#include "kernel/cloth_kernel.h"
} // namespace f64

using namespace f32;
using namespace f64;

/// Buckets of self-collision's hash table for `count` particles: a power of two, at least twice the count
/// and a whole number of the GPU scan's blocks (VKCLOTH_SELF_SCAN_BLOCK), the same on both
/// backends (the table decides which cells share a bucket, so the order pairs are summed in).
inline std::uint32_t self_table_size(std::uint32_t count) {
  std::uint64_t t = 512;
  while (t < 2ull * count) // at most half full: few buckets shared by two cells
    t *= 2;
  return static_cast<std::uint32_t>(t);
}

/// The most CG iterations of one fast-projection solve over `links` links, the same on both
/// backends: CG needs about as many as the links' graph is wide (its condition number grows with
/// the square of the width), ~sqrt(links) on a cloth; 10 sqrt(links) leaves room for its worst
/// steps in float (the report's soft cloth at 64 x 64 took up to ~5 sqrt(links)).
inline std::uint32_t projection_cg_cap(std::size_t links) {
  std::uint32_t root = 0;
  while (std::uint64_t(root) * root < links)
    ++root;
  return 50 + 10 * root;
}

/// The kernel's SpringBlock of precision Real.
template <typename Real>
using SpringBlock = std::conditional_t<std::is_same_v<Real, float>, f32::SpringBlock, f64::SpringBlock>;
/// The kernel's ColliderShape of precision Real.
template <typename Real>
using ColliderShape = std::conditional_t<std::is_same_v<Real, float>, f32::ColliderShape, f64::ColliderShape>;

/// A collider as the kernel takes it, every double field cast once to Real: the one conversion
/// both backends use (CpuSolver; the GPU solver packs kernel_shape<float> into its Collider
/// buffer), so the CPU float solver and the GPU see the same values. mesh_root / mesh_tri0: where
/// the collider's mesh starts in the buffers the caller walks (0 when it walks the mesh in place);
/// mesh_cache: where its particles' search entries start; mesh_vel0: where a skinned mesh's corner
/// velocities start (ignored for a rigid mesh, whose shape gets VKCLOTH_MESH_NONE); mesh_adj0: where
/// its neighbours start (the GPU's buffer; the CPU reads MeshData::neighbours).
template <typename Real>
kernel::ColliderShape<Real> kernel_shape(const Collider& c, std::uint32_t mesh_root = 0,
                                         std::uint32_t mesh_tri0 = 0, std::uint32_t mesh_cache = 0,
                                         std::uint32_t mesh_vel0 = 0, std::uint32_t mesh_adj0 = 0) {
  using V = glm::vec<3, Real>;
  kernel::ColliderShape<Real> s{};
  s.type = std::uint32_t(c.type);
  switch (c.type) {
  case Collider::Type::plane:
    s.a = V(c.normal);
    s.b = Real(c.offset);
    break;
  case Collider::Type::sphere:
    s.a = V(c.center);
    s.b = Real(c.radius);
    break;
  case Collider::Type::capsule:
    s.a = V(c.a);
    s.b = Real(c.radius);
    s.c = V(c.b);
    break;
  case Collider::Type::box:
    s.a = V(c.center);
    s.c = V(c.half_extents);
    break;
  case Collider::Type::mesh:
    s.a = V(c.center);
    s.b = Real(c.thickness);
    break;
  }
  s.ax = V(c.rotation[0]);
  s.ay = V(c.rotation[1]);
  s.az = V(c.rotation[2]);
  s.mesh_root = mesh_root;
  s.mesh_tri0 = mesh_tri0;
  s.mesh_cache = mesh_cache;
  s.mesh_adj0 = mesh_adj0;
  const bool skinned = c.type == Collider::Type::mesh && c.mesh && !c.mesh->triangle_velocities().empty();
  s.mesh_vel0 = skinned ? mesh_vel0 : VKCLOTH_MESH_NONE;
  s.moving = c.moving() || skinned;
  s.velocity = V(c.linear_velocity);
  s.spin = V(c.angular_velocity);
  s.pivot = V(c.centre());
  s.mu_k = Real(c.friction);
  s.mu_s = Real(c.static_coefficient());
  return s;
}

} // namespace vkcloth::kernel

#define VKCLOTH_KERNEL_LANGUAGE_END // no kernel macro past the bridge
#include "kernel/language.h"
#undef VKCLOTH_KERNEL_LANGUAGE_END
