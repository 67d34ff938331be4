// Shadow depth pass of a spot light or a point light's cube face: positions into its perspective
// clip space, the world position for the fragment stage's radial depth (homogeneous, w = 1: see the
// fragment stage) and the opacity texture's coordinate for its alpha test.
#version 460
#extension GL_GOOGLE_include_directive : require
#include "msm/render/bindings.h"
#define MSM_LIGHT_BINDING MSM_BINDING_SHADOW_DEPTH_MASKED_LIGHTS
#include "frame.glsl"

layout(location = 0) in vec3 position;
layout(location = 2) in vec2 uv;
layout(location = 0) out vec4 world_position_h;
layout(location = 1) out vec2 texcoord;
layout(push_constant) uniform Push { ObjectPush object; };

void main() {
  world_position_h = vec4(position, 1.0f);
  texcoord = uv;
  gl_Position = lights[object.light.x].view_projection * vec4(position, 1.0f);
}
