// SPDX-License-Identifier: MIT
#version 450
#extension GL_GOOGLE_include_directive : require
// Colliders and chain masses: binding 0 = mesh vertices (vec4 position, w = checker u; vec4
// normal, w = checker v), binding 1 = per-instance offset (vec4; a chain's positions buffer, or
// one zero vec4 for colliders), scaled by pc.params.z.
#include "render_common.glsl"
layout(location = 0) in vec4 in_pos;
layout(location = 1) in vec4 in_normal;
layout(location = 2) in vec4 in_offset;
layout(location = 0) out vec3 out_world;
layout(location = 1) out vec3 out_normal;
layout(location = 2) out vec2 out_cell;
void main() {
  out_world = in_pos.xyz * pc.params.z + in_offset.xyz;
  out_normal = in_normal.xyz;
  out_cell = vec2(in_pos.w, in_normal.w);
  gl_Position = pc.view_proj * vec4(out_world, 1.0);
}
