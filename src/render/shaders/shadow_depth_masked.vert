// Shadow depth pass of alpha-tested occluders (glTF alphaMode MASK): positions into the light's
// clip space and the texture coordinate of the opacity texture.
#version 460
#extension GL_GOOGLE_include_directive : require
#include "msm/render/bindings.h"
#define MSM_LIGHT_BINDING MSM_BINDING_SHADOW_DEPTH_MASKED_LIGHTS
#include "frame.glsl"

layout(location = 0) in vec3 position;
layout(location = 2) in vec2 uv;
layout(location = 0) out vec2 texcoord;
layout(push_constant) uniform Push { ObjectPush object; };

void main() {
  texcoord = uv;
  gl_Position = lights[object.light.x].view_projection * vec4(position, 1.0f);
}
