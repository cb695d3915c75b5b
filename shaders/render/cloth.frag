// SPDX-License-Identifier: MIT
#version 450
#extension GL_GOOGLE_include_directive : require
// Two-sided lighting: the side the solver's normal points to is the front; the back side is
// shaded with the flipped normal and tinted (pc.color), so the two faces look different.
#include "render_common.glsl"
layout(set = 0, binding = 0) uniform sampler2D fabric;
layout(location = 0) in vec3 in_world;
layout(location = 1) in vec3 in_normal;
layout(location = 2) in vec2 in_uv;
layout(location = 0) out vec4 out_color;
void main() {
  vec3 n = in_normal;
  float len = length(n);
  // Degenerate normal (zero before the first force pass or at a collapsed fan): face the viewer.
  n = len > 1e-6 ? n / len : normalize(pc.eye.xyz - in_world);
  bool front = dot(n, pc.eye.xyz - in_world) >= 0.0;
  vec3 albedo = texture(fabric, in_uv).rgb;
  if (!front) {
    n = -n;
    albedo *= pc.color.rgb;
  }
  out_color = vec4(shade(albedo, n, in_world), 1.0);
}
