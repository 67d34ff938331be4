// Shading with the linear filtered techniques: the blurred (and mip-mapped) moment images, read
// with hardware bilinear/trilinear filtering, at the nearest texel or dithered, then
// reconstructed by the shared technique code.
#version 460
#extension GL_GOOGLE_include_directive : require
layout(binding = 2) uniform sampler2D moments0;
layout(binding = 3) uniform sampler2D moments1; // second half of 6MSM; else moments0 again
#include "shading.glsl"
#include "lookup.glsl"

float shadow_intensity(ShadowLookup s) {
  bool six = kTechnique == MSM_TECH_MSM6_192 || kTechnique == MSM_TECH_MSM6_96;
  bool second = six || kSplitRG;
  MsmTexel texel = MsmTexel(vec4(0.0f), vec4(0.0f));
  if (frame.lookup.x == MSM_LOOKUP_BILINEAR) {
    vec2 uv = (s.t + 0.5f) * frame.shadow_map.y;
    s.z -= receiver_plane_bias(s, textureQueryLod(moments0, uv).x);
  } else {
    s.z -= receiver_plane_bias(s, 0.0f);
  }
  float zf = s.z;
  if (frame.lookup.x == MSM_LOOKUP_BILINEAR) {
    vec2 uv = (s.t + 0.5f) * frame.shadow_map.y;
    texel.a = texture(moments0, uv);
    if (second) texel.b = texture(moments1, uv);
  } else {
    ivec2 i = lookup_texel(s.t);
    texel.a = texelFetch(moments0, i, 0);
    if (second) texel.b = texelFetch(moments1, i, 0);
    zf = receiver_depth_at(s, i);
  }
  if (kSplitRG) texel = MsmTexel(vec4(texel.a.x, texel.a.y, texel.b.x, texel.b.y), vec4(0.0f));
  return msm_technique_shadow(kTechnique, texel, zf, frame.technique_params);
}
