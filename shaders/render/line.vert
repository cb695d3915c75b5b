// SPDX-License-Identifier: MIT
#version 450
#extension GL_GOOGLE_include_directive : require
// Chain springs as lines between the solver's current positions (binding 0, vec4, stride 16).
#include "render_common.glsl"
layout(location = 0) in vec4 in_pos;
void main() { gl_Position = pc.view_proj * vec4(in_pos.xyz, 1.0); }
