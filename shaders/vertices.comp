// SPDX-License-Identifier: MIT
#version 450
#extension GL_GOOGLE_include_directive : require
// vkcloth-builds: one workgroup-constant (shaders/CMakeLists.txt)
// The interleaved vertex output (GpuSolverOptions::interleaved_vertices), one invocation per
// particle, after the last step of a recording: the current position, the normal as stored and
// the uv, packed into one Vertex (32 bytes) for hosts whose pipeline reads one vertex binding.
// Reads POS_IN (bound to the current positions), NORMAL, UV; writes VERTICES.
#include "kernel/layout/vkcloth_shared.h"
#include "common.glsl"

layout(std430, set = 0, binding = VKCLOTH_BINDING_POS_IN) readonly buffer PosIn { vec4 pos_in[]; };
layout(std430, set = 0, binding = VKCLOTH_BINDING_NORMAL) readonly buffer NormalIn { vec4 normal_in[]; };
layout(std430, set = 0, binding = VKCLOTH_BINDING_UV) readonly buffer UvIn { vec4 uv_in[]; };
layout(std430, set = 0, binding = VKCLOTH_BINDING_VERTICES) writeonly buffer VertexOut { Vertex vertices[]; };

void main() {
  begin_instance();
  const uint p = particle_index();
  if (p >= pc.count) return;
  const uint g = base + p;
  const vec3 x = pos_in[g].xyz, n = normal_in[g].xyz;
  const vec2 uv = uv_in[g].xy;
  vertices[g] = Vertex(vec4(x, n.x), vec4(n.yz, uv));
}
