// Shading pass: world-space vertices (the scene is flattened on load) to the camera.
#version 460
#extension GL_GOOGLE_include_directive : require
#include "frame.glsl"

layout(location = 0) in vec3 position;
layout(location = 1) in vec3 normal;
layout(location = 2) in vec2 uv;

layout(location = 0) out vec3 world_position;
layout(location = 1) out vec3 world_normal;
layout(location = 2) out vec2 texcoord;

void main() {
  world_position = position;
  world_normal = normal;
  texcoord = uv;
  gl_Position = frame.camera_view_projection * vec4(position, 1.0f);
}
