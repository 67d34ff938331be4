// Translucent occluders into the moment shadow map: light clip space, the texture coordinate of the
// opacity texture and the world position (a spot light or a point light's face stores the radial
// distance from it). One draw per light and object, into the light's layer.
#version 460
#extension GL_GOOGLE_include_directive : require
#include "msm/render/bindings.h"
#define MSM_LIGHT_BINDING MSM_BINDING_TRANSLUCENT_LIGHTS
#include "frame.glsl"

layout(location = 0) in vec3 position;
layout(location = 2) in vec2 uv;
layout(location = 0) out vec2 texcoord;
layout(location = 1) out vec3 world_position;
layout(push_constant) uniform Push { ObjectPush object; };

void main() {
  texcoord = uv;
  world_position = position;
  gl_Position = lights[object.light.x].view_projection * vec4(position, 1.0f);
}
