// SPDX-License-Identifier: MIT
// vkcloth kernel: the collider as the kernel takes it (docs/model.md "Collisions"), and what is decided
// by the collider alone. A collider is the same for every particle of a call: the CPU's SIMD lanes
// include this header with scalar real / vec3 (row_kernel_simd.inl), so the shape's own tests are
// plain bools there (the contact functions take its values as broadcast lanes).
// Part of the kernel that cloth_kernel.h gathers (the rules it states hold here: fixed order,
// `precise` results, real(...) literals). No include guard: the C++ bridge includes it once per precision.

// A collider as the kernel takes it, in the solver's precision, at its pose for this substep
// (the host advances moving colliders: vkcloth::Collider::posed_at). GLSL: common.glsl
// collider_shape(); C++: kernel.hpp kernel_shape().
struct ColliderShape {
  uint type; // VKCLOTH_COLLIDER_*
  vec3 a;    // plane: unit normal; sphere, box, mesh: centre (mesh: its origin); capsule: end a
  real b;    // plane: offset; sphere, capsule: radius; mesh: thickness
  vec3 c;    // capsule: end b; box: half extents
  vec3 ax;   // box, mesh: the body's axes in the world (columns of its rotation)
  vec3 ay;
  vec3 az;
  uint mesh_root; // mesh: its root node and first triangle in the mesh buffers
  uint mesh_tri0;
  uint mesh_cache; // mesh: where its particles' search entries start (the bridge adds the particle)
  uint mesh_vel0;  // mesh: its first triangle's corner velocities (VKCLOTH_MESH_NONE: a rigid mesh)
  uint mesh_adj0;  // mesh: its triangles' neighbours (mesh_neighbour)
  bool moving;     // the surface moves: velocity, spin and pivot apply
  vec3 velocity;   // linear velocity
  vec3 spin;       // angular velocity about pivot
  vec3 pivot;
  real mu_k; // Coulomb friction: kinetic and static coefficients (0, 0: frictionless)
  real mu_s;
};

// A collider that neither moves nor has friction: its contact response is the report's filter
// (contact_response).
KFN bool still_frictionless(ColliderShape s) {
  return !s.moving && s.mu_s == real(0) && s.mu_k == real(0);
}

// A skinned mesh: its triangles' corners move (per-corner velocities; it counts as moving).
KFN bool deforming(ColliderShape s) {
  return s.mesh_vel0 != VKCLOTH_MESH_NONE;
}

// A collider with Coulomb friction.
KFN bool has_friction(ColliderShape s) {
  return s.mu_s != real(0) || s.mu_k != real(0);
}

// The same collider without friction: the contact response that only removes the inward part
// (vertex block descent's finish, whose friction acted inside the solve).
KFN ColliderShape without_friction(ColliderShape s) {
  ColliderShape r = s;
  r.mu_k = real(0);
  r.mu_s = real(0);
  return r;
}
