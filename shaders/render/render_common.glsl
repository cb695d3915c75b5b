// SPDX-License-Identifier: MIT
// Shared by the render shaders: push constants (128 bytes, the minimum every device offers) and
// the lighting. Must match DrawConstants in engine/src/render/cloth_renderer.cpp.
//
// Each draw has its own frame: the world for the cloth, the floor and a chain; a collider's own
// frame for a collider (view_proj is then the view-projection times its rigid pose, and the eye
// and the light are given in that frame). Lighting only uses lengths and angles, which a rigid
// motion keeps, so shading in the collider's frame is shading in the world.
layout(push_constant) uniform DrawConstants {
  mat4 view_proj; // the draw's frame -> clip (Vulkan clip space: y down, depth 0..1)
  vec4 eye;       // xyz: camera position (draw's frame); w: checker cell size (mode 1)
  vec4 light;     // xyz: unit direction TOWARDS the light (draw's frame); w: ambient
  vec4 color;     // rgb: mesh colour or the cloth's back tint; w: mode (0 lit solid, 1 checker floor)
  vec4 shape;     // mesh.vert: xyz scale of the vertices per axis; w: a capsule's half length
} pc;

// Lambert + ambient + a little Blinn-Phong, with `n` already facing the viewer; `p` in the
// draw's frame.
vec3 shade(vec3 albedo, vec3 n, vec3 p) {
  vec3 l = normalize(pc.light.xyz);
  vec3 v = normalize(pc.eye.xyz - p);
  float diffuse = max(dot(n, l), 0.0);
  float spec = pow(max(dot(n, normalize(l + v)), 0.0), 32.0) * 0.15;
  return albedo * (pc.light.w + (1.0 - pc.light.w) * diffuse) + vec3(spec);
}
