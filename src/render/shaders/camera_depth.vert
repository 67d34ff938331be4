// The camera's depth pre-pass (depth_bounds.cpp): positions into the camera's clip space, and the
// texture coordinate of alpha-tested objects' opacity.
#version 460
#extension GL_GOOGLE_include_directive : require
#include "msm/render/frame.h"

layout(location = 0) in vec3 position;
layout(location = 2) in vec2 uv;
layout(location = 0) out vec2 texcoord;
layout(push_constant) uniform Push {
  ObjectPush object;
  mat4 view_projection;
};

void main() {
  texcoord = uv;
  gl_Position = view_projection * vec4(position, 1.0f);
}
