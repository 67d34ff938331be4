// Shadow depth pass: positions into the light's orthographic clip space; no fragment stage. One
// draw per light, into its layer of the depth array (ObjectPush::light).
#version 460
#extension GL_GOOGLE_include_directive : require
#include "msm/render/bindings.h"
#define MSM_LIGHT_BINDING MSM_BINDING_SHADOW_DEPTH_LIGHTS
#include "frame.glsl"

layout(location = 0) in vec3 position;
layout(push_constant) uniform Push { ObjectPush object; };

void main() { gl_Position = lights[object.light.x].view_projection * vec4(position, 1.0f); }
