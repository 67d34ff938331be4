// Shadow depth pass of a spot light or a point light's cube face: the depth its map stores is the
// radial distance from the light over its range (docs/techniques.md, "Light kinds"), not the
// perspective z / w, whose precision crowds at the near plane; the shading compares in the same
// convention. Cut-outs of alpha-tested occluders write no depth.
#version 460
#extension GL_GOOGLE_include_directive : require
#include "msm/render/bindings.h"
#define MSM_LIGHT_BINDING MSM_BINDING_SHADOW_DEPTH_MASKED_LIGHTS
#include "frame.glsl"
#include "alpha_test.glsl"
#include "msm/local_light.h"
#include "local_light_depth.glsl"

layout(binding = MSM_BINDING_SHADOW_DEPTH_MASKED_OPACITY) uniform sampler2D opacity_texture;
// Per sample: gl_FragDepth is one depth for every sample the fragment covers, and the lookups take
// the MSAA samples' depths at their own positions (the receiver plane's, shading_depth.glsl).
// Homogeneous, its w written as 1: the position is xyz / w, exact wherever the interpolator divides
// by 1 / w_clip. lavapipe (Mesa 22.3) interpolates a sample-rate varying's a / w_clip at the sample
// but divides by the pixel centre's 1 / w_clip: every component, w included, comes out scaled by the
// same factor, which the division cancels (without it the depths moved by up to a third of their
// slope across the texel along the map's depth gradient, and PCF's receiver plane shadowed lit ground).
layout(location = 0) sample in vec4 world_position_h;
layout(location = 1) in vec2 texcoord;
layout(push_constant) uniform Push { ObjectPush object; };

void main() {
  if (!alpha_test_passes(object, true, opacity_texture, texcoord)) discard;
  LightUniforms light = lights[object.light.x];
  vec3 world_position = world_position_h.xyz / world_position_h.w;
  gl_FragDepth = local_light_map_depth(light, world_position);
}
