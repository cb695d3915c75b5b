// SPDX-License-Identifier: MIT
#version 450
#extension GL_GOOGLE_include_directive : require
// The cloth straight from the solver's buffers: binding 0 = positions[current], 1 = normals,
// 2 = uvs; each a vec4 per particle (stride 16), indexed by the topology's triangle list (a grid's
// or a mesh's, holes and boundaries as they are).
#include "render_common.glsl"
layout(location = 0) in vec4 in_pos;
layout(location = 1) in vec4 in_normal;
layout(location = 2) in vec4 in_uv;
layout(location = 0) out vec3 out_world;
layout(location = 1) out vec3 out_normal;
layout(location = 2) out vec2 out_uv;
void main() {
  out_world = in_pos.xyz;
  out_normal = in_normal.xyz;
  out_uv = in_uv.xy;
  gl_Position = pc.view_proj * vec4(in_pos.xyz, 1.0);
}
