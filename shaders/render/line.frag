// SPDX-License-Identifier: MIT
#version 450
#extension GL_GOOGLE_include_directive : require
#include "render_common.glsl"
layout(location = 0) out vec4 out_color;
void main() { out_color = vec4(pc.color.rgb, 1.0); }
