// Shadow depth pass of a spot light: the depth its map stores is the radial distance from the
// light over its range (docs/techniques.md, "Light kinds"), not the perspective z / w, whose
// precision crowds at the near plane; the shading compares in the same convention. Cut-outs of
// alpha-tested occluders write no depth.
#version 460
#extension GL_GOOGLE_include_directive : require
#include "msm/render/bindings.h"
#define MSM_LIGHT_BINDING MSM_BINDING_SHADOW_DEPTH_MASKED_LIGHTS
#include "frame.glsl"
#include "alpha_test.glsl"
#include "msm/local_light.h"

layout(binding = MSM_BINDING_SHADOW_DEPTH_MASKED_OPACITY) uniform sampler2D opacity_texture;
// Per sample: gl_FragDepth is one depth for every sample the fragment covers, and the lookups take
// the MSAA samples' depths at their own positions (the receiver plane's, shading_depth.glsl).
layout(location = 0) sample in vec3 world_position;
layout(location = 1) in vec2 texcoord;
layout(push_constant) uniform Push { ObjectPush object; };

void main() {
  if (!alpha_test_passes(object, true, opacity_texture, texcoord)) discard;
  LightUniforms light = lights[object.light.x];
  gl_FragDepth = clamp(msm_local_light_depth(distance(world_position, light.spot_position.xyz), light.spot_position.w),
                       0.0f, 1.0f);
}
