// SPDX-License-Identifier: MIT
#version 450
#extension GL_GOOGLE_include_directive : require
// Solid lit colour (mode 0) or a checkerboard of pc.color and a darker shade (mode 1: the floor).
#include "render_common.glsl"
layout(location = 0) in vec3 in_pos; // in the draw's frame
layout(location = 1) in vec3 in_normal;
layout(location = 2) in vec2 in_cell;
layout(location = 0) out vec4 out_color;
void main() {
  vec3 n = normalize(in_normal);
  if (dot(n, pc.eye.xyz - in_pos) < 0.0) n = -n;
  vec3 albedo = pc.color.rgb;
  if (pc.color.w > 0.5) {
    ivec2 c = ivec2(floor(in_cell / pc.eye.w));
    if (((c.x + c.y) & 1) != 0) albedo *= 0.55;
  }
  out_color = vec4(shade(albedo, n, in_pos), 1.0);
}
