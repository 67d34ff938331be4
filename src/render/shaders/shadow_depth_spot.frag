// Shadow depth pass of a spot light or a point light's cube face: the depth its map stores is the
// radial distance from the light over its range (docs/techniques.md, "Light kinds"), not the
// perspective z / w, whose precision crowds at the near plane; the shading compares in the same
// convention. Cut-outs of alpha-tested occluders write no depth.
#version 460
#extension GL_GOOGLE_include_directive : require
#include "msm/render/bindings.h"
#define MSM_LIGHT_BINDING MSM_BINDING_SHADOW_DEPTH_MASKED_LIGHTS
#include "alpha_test.glsl"
#include "frame.glsl"
#include "msm/local_light.h"

layout(binding = MSM_BINDING_SHADOW_DEPTH_MASKED_OPACITY) uniform sampler2D opacity_texture;
layout(location = 1) in vec2 texcoord;
layout(push_constant) uniform Push { ObjectPush object; };

// Per sample (gl_SamplePosition runs the shader per sample): gl_FragDepth is one depth for every
// sample the fragment covers, and the lookups take the MSAA samples' depths at their own positions
// (the receiver plane's, shading_depth.glsl). The sample's point is unprojected from its position
// and the rasterizer's depth there, not interpolated: on lavapipe a `sample in` world position on
// a large ground seen by a point light's side faces varied with the samples' x offsets but not
// their y offsets, and the ground then shadowed half of its own samples.
void main() {
  if (!alpha_test_passes(object, true, opacity_texture, texcoord)) discard;
  LightUniforms light = lights[object.light.x];
  vec2 ndc = (floor(gl_FragCoord.xy) + gl_SamplePosition) * (2.0f / frame.shadow_map.x) - 1.0f;
  vec4 h = inverse(light.view_projection) * vec4(ndc, gl_FragCoord.z, 1.0f);
  gl_FragDepth =
      clamp(msm_local_light_depth(distance(h.xyz / h.w, light.spot_position.xyz), light.spot_position.w), 0.0f, 1.0f);
}
