// SPDX-License-Identifier: MIT
// vkcloth kernel: vector helpers shared by every concern (docs/model.md).
// Part of the kernel that cloth_kernel.h gathers (the rules it states hold here: fixed order,
// `precise` results, real(...) literals). No include guard: the C++ bridge includes it once per precision.

// ---- Vector helpers ----------------------------------------------------------------------------

// a.x b.x + a.y b.y + a.z b.z, left to right.
KFN precise real dot3(vec3 a, vec3 b) {
  precise real r = a.x * b.x + a.y * b.y;
  r = r + a.z * b.z;
  return r;
}

// cross(x, y) in glm::cross's order.
KFN precise vec3 cross3(vec3 x, vec3 y) {
  precise real cx = x.y * y.z - y.y * x.z;
  precise real cy = x.z * y.x - y.z * x.x;
  precise real cz = x.x * y.y - y.x * x.y;
  return vec3(cx, cy, cz);
}
