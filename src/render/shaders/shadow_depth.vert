// Shadow depth pass: positions into the light's orthographic clip space; no fragment stage.
#version 460
#extension GL_GOOGLE_include_directive : require
#include "frame.glsl"

layout(location = 0) in vec3 position;

void main() { gl_Position = frame.light_view_projection * vec4(position, 1.0f); }
