// SPDX-License-Identifier: MIT
// vkcloth kernel: symmetric 3x3 blocks, what implicit Euler (implicit.h) and vertex block descent
// (vbd.h) share: a spring's positive semi-definite stiffness block, a block times a vector, and the
// inverse of a positive definite block. No per-particle branch: it compiles on the CPU's SIMD lanes
// too (engine/src/core/simd_kernel.inl).
// Part of the kernel that cloth_kernel.h gathers (the rules it states hold here: fixed order,
// `precise` results, real(...) literals). No include guard: the C++ bridge includes it once per precision.

// A spring's 3x3 stiffness block, symmetric: diag = (xx, yy, zz), off = (xy, xz, yz).
struct SpringBlock {
  vec3 diag;
  vec3 off;
};

// The positive semi-definite part of a spring's Jacobian: k along the spring, and the transverse
// tension term k max(0, 1 - L0 / |u|) across it (the compressive part is dropped); n = u / |u|, the
// unit direction, and r = L0 / |u|, as the caller computes them (spring_block: by division;
// vbd_add_spring: from one reciprocal it shares with the force).
KFN SpringBlock spring_block_n(vec3 n, real r, real k) {
  SpringBlock s;
  precise real c = k * max(real(0), real(1) - r);
  precise real al = k - c;
  precise real xx = al * n.x * n.x + c, yy = al * n.y * n.y + c, zz = al * n.z * n.z + c;
  precise real xy = al * n.x * n.y, xz = al * n.x * n.z, yz = al * n.y * n.z;
  s.diag = vec3(xx, yy, zz);
  s.off = vec3(xy, xz, yz);
  return s;
}

// The zero block (a sum's start).
KFN SpringBlock zero_block() {
  SpringBlock s;
  s.diag = vec3(real(0));
  s.off = vec3(real(0));
  return s;
}

// c (I - n n^T) for a unit n: a stiffness c across n and none along it (self_energy's friction).
KFN SpringBlock tangent_block(vec3 n, real c) {
  SpringBlock s;
  precise real xx = c - c * n.x * n.x, yy = c - c * n.y * n.y, zz = c - c * n.z * n.z;
  precise real nc = real(0) - c;
  precise real xy = nc * n.x * n.y, xz = nc * n.x * n.z, yz = nc * n.y * n.z;
  s.diag = vec3(xx, yy, zz);
  s.off = vec3(xy, xz, yz);
  return s;
}

// K w for a symmetric block.
KFN precise vec3 apply_block(SpringBlock s, vec3 w) {
  precise real x = s.diag.x * w.x + s.off.x * w.y;
  x = x + s.off.y * w.z;
  precise real y = s.off.x * w.x + s.diag.y * w.y;
  y = y + s.off.z * w.z;
  precise real z = s.off.y * w.x + s.off.z * w.y;
  z = z + s.diag.z * w.z;
  return vec3(x, y, z);
}

// The inverse of a symmetric positive definite block: adjugate over determinant (A_pp is SPD:
// (1 + h mu) m > 0 plus a positive semi-definite sum, so det > 0).
KFN SpringBlock invert_block(SpringBlock a) {
  const real xx = a.diag.x, yy = a.diag.y, zz = a.diag.z;
  const real xy = a.off.x, xz = a.off.y, yz = a.off.z;
  precise real c_xx = yy * zz - yz * yz, c_yy = xx * zz - xz * xz, c_zz = xx * yy - xy * xy;
  precise real c_xy = xz * yz - xy * zz, c_xz = xy * yz - xz * yy, c_yz = xy * xz - xx * yz;
  precise real det = xx * c_xx + xy * c_xy;
  det = det + xz * c_xz;
  precise real inv = real(1) / det;
  SpringBlock r;
  precise vec3 d = vec3(c_xx, c_yy, c_zz) * inv;
  precise vec3 o = vec3(c_xy, c_xz, c_yz) * inv;
  r.diag = d;
  r.off = o;
  return r;
}
