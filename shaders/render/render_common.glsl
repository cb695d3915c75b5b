// SPDX-License-Identifier: MIT
// Shared by the render shaders: push constants (128 bytes, the minimum every device offers) and
// the lighting. Must match DrawConstants in engine/src/render/cloth_renderer.cpp.
layout(push_constant) uniform DrawConstants {
  mat4 view_proj; // world -> clip (Vulkan clip space: y down, depth 0..1)
  vec4 eye;       // xyz: camera position (world)
  vec4 light;     // xyz: unit direction TOWARDS the light (world); w: ambient
  vec4 color;     // mesh: base colour; cloth: back-face tint
  vec4 params;    // x: mode (0 lit solid, 1 checker floor), y: checker cell size, z: instance scale
} pc;

// Lambert + ambient + a little Blinn-Phong, with `n` already facing the viewer.
vec3 shade(vec3 albedo, vec3 n, vec3 world_pos) {
  vec3 l = normalize(pc.light.xyz);
  vec3 v = normalize(pc.eye.xyz - world_pos);
  float diffuse = max(dot(n, l), 0.0);
  float spec = pow(max(dot(n, normalize(l + v)), 0.0), 32.0) * 0.15;
  return albedo * (pc.light.w + (1.0 - pc.light.w) * diffuse) + vec3(spec);
}
