// SPDX-License-Identifier: MIT
#version 450
#extension GL_GOOGLE_include_directive : require
// Colliders and chain masses: binding 0 = mesh vertices (vec4 position, w = the floor's checker u
// or a capsule vertex's end, +1 / -1, else 0; vec4 normal, w = checker v), binding 1 =
// per-instance offset (vec4; a chain's positions buffer, or one zero vec4 for colliders).
// Positions are scaled per axis by pc.shape.xyz (normals by the inverse), then a capsule's two
// hemispheres move apart along z by its half length (pc.shape.w), so one unit mesh draws any
// sphere, capsule and box.
#include "render_common.glsl"
layout(location = 0) in vec4 in_pos;
layout(location = 1) in vec4 in_normal;
layout(location = 2) in vec4 in_offset;
layout(location = 0) out vec3 out_pos; // in the draw's frame (render_common.glsl)
layout(location = 1) out vec3 out_normal;
layout(location = 2) out vec2 out_cell;
void main() {
  vec3 p = in_pos.xyz * pc.shape.xyz + in_offset.xyz;
  p.z += in_pos.w * pc.shape.w;
  out_pos = p;
  out_normal = in_normal.xyz / pc.shape.xyz; // the inverse transpose of the diagonal scale
  out_cell = vec2(in_pos.w, in_normal.w);
  gl_Position = pc.view_proj * vec4(p, 1.0);
}
