// SPDX-License-Identifier: MIT
#version 450
#extension GL_GOOGLE_include_directive : require
// The final pass of the CG dot products: ONE workgroup sums the per-workgroup partials of the
// previous implicit.comp pass in a fixed shape (invocation l adds partials l, l + 64, ... in
// order, then a shared-memory tree), updates the CG scalars (CgState) and rewrites the indirect
// dispatch arguments: zero groups once converged, so the remaining recorded iterations are no-ops
// and no CPU round trip is needed per iteration.
#include "implicit_shared.h"

layout(local_size_x = VKCLOTH_WORKGROUP_SIZE) in;
layout(push_constant) uniform PushBlock { PushConstants pc; };
layout(std430, set = 0, binding = VKCLOTH_BINDING_IMPL_PARTIALS) readonly buffer PartialBuf { vec4 partials[]; };
layout(std430, set = 0, binding = VKCLOTH_BINDING_IMPL_STATE) buffer StateBuf { CgState cg; };
layout(std430, set = 0, binding = VKCLOTH_BINDING_IMPL_ARGS) writeonly buffer ArgBuf { CgArgs args; };

shared vec4 red[VKCLOTH_WORKGROUP_SIZE];

void main() {
  const uint l = gl_LocalInvocationID.x;
  precise vec4 s = vec4(0.0);
  for (uint i = l; i < pc.pad1; i += VKCLOTH_WORKGROUP_SIZE) s = s + partials[i];
  red[l] = s;
  barrier();
  for (uint k = VKCLOTH_WORKGROUP_SIZE / 2; k > 0u; k >>= 1) {
    if (l < k) {
      precise vec4 t = red[l] + red[l + k];
      red[l] = t;
    }
    barrier();
  }
  if (l != 0u) return;
  const vec4 sum = red[0];
  const float tol2 = pc.c_next;
  bool done = cg.done != 0u;
  if (pc.stage == VKCLOTH_REDUCE_INIT) {
    cg.rz = sum.x;
    cg.rr = sum.y;
    cg.ref2 = max(sum.z, sum.w); // max(|S b|^2, |S h M g|^2): implicit_euler.hpp
    cg.alpha = 0.0;
    cg.beta = 0.0;
    cg.iterations = 0u;
    cg.solves = cg.solves + 1u;
    done = sum.y <= tol2 * cg.ref2;
  } else if (pc.stage == VKCLOTH_REDUCE_ALPHA) {
    if (!(sum.x > 0.0))
      done = true;
    else
      cg.alpha = cg.rz / sum.x;
  } else {
    cg.beta = sum.x / cg.rz;
    cg.rz = sum.x;
    cg.rr = sum.y;
    cg.iterations = cg.iterations + 1u;
    cg.total_iterations = cg.total_iterations + 1u;
    done = sum.y <= tol2 * cg.ref2 || cg.iterations >= pc.pad0;
  }
  cg.done = done ? 1u : 0u;
  args.particle_x = done ? 0u : cg.groups_x;
  args.particle_y = done ? 0u : cg.groups_y;
  args.particle_z = done ? 0u : 1u;
  args.reduce_x = done ? 0u : 1u;
  args.reduce_y = done ? 0u : 1u;
  args.reduce_z = done ? 0u : 1u;
}
