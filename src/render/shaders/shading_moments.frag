// Shading with the filtered techniques: the blurred (and mip-mapped) moment images, sampled with
// hardware bilinear/trilinear filtering, reconstructed by the shared technique code.
#version 460
#extension GL_GOOGLE_include_directive : require
layout(binding = 2) uniform sampler2D moments0;
layout(binding = 3) uniform sampler2D moments1; // second half of 6MSM; else moments0 again
#include "shading.glsl"

float shadow_intensity(ShadowLookup s) {
  vec2 uv = (s.t + 0.5f) * frame.shadow_map.y;
  MsmTexel texel = MsmTexel(texture(moments0, uv), vec4(0.0f));
  if (kTechnique == MSM_TECH_MSM6_192 || kTechnique == MSM_TECH_MSM6_96) texel.b = texture(moments1, uv);
  return msm_technique_shadow(kTechnique, texel, s.z, frame.technique_params);
}
