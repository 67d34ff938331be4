// Shading with the linear filtered techniques: the blurred (and mip-mapped) moment images (arrays
// with one layer per light), read
// with hardware bilinear/trilinear filtering, at the nearest texel or dithered, then
// reconstructed by the shared technique code; with coloured translucency (shading_moments_rgb.frag
// defines MSM_COLOURED_SHADOWS) once per colour channel. A separate shader, not a specialization
// constant: lavapipe compiled the three reconstructions even where the constant disabled them,
// tripling the pipeline build time of every linear technique.
#include "msm/render/bindings.h"
layout(binding = MSM_BINDING_SHADING_SHADOW_MAP) uniform sampler2DArray moments0;
layout(binding = MSM_BINDING_SHADING_SHADOW_MAP1) uniform sampler2DArray moments1; // second half of 6MSM; else moments0 again
// Coloured translucency: the green and blue channels' moment images (bound to moments0/1 where the
// frame has none; only shading_moments_rgb.frag reads them).
layout(binding = MSM_BINDING_SHADING_GREEN_MOMENTS) uniform sampler2DArray moments0_g;
layout(binding = MSM_BINDING_SHADING_GREEN_MOMENTS1) uniform sampler2DArray moments1_g;
layout(binding = MSM_BINDING_SHADING_BLUE_MOMENTS) uniform sampler2DArray moments0_b;
layout(binding = MSM_BINDING_SHADING_BLUE_MOMENTS1) uniform sampler2DArray moments1_b;
#include "shading.glsl"
#include "lookup.glsl"

// The shadow intensity from one set of moment images (one colour channel's, or the only one).
float shadow_from(sampler2DArray first, sampler2DArray second_image, ShadowLookup s) {
  bool six = msm_technique_is_six_moments(kTechnique);
  bool second = six || kSplitRG;
  MsmTexel texel = MsmTexel(vec4(0.0f), vec4(0.0f));
  vec2 uv = (s.t + 0.5f) * frame.shadow_map.y;
  vec2 duv_dx = s.dt_dx * frame.shadow_map.y, duv_dy = s.dt_dy * frame.shadow_map.y;
  if (kLookup == MSM_LOOKUP_BILINEAR) {
    // The mip the lookup reads (textureQueryLod's x, from the same derivatives).
    float lod = log2(max(length(s.dt_dx), length(s.dt_dy)));
    s.z -= receiver_plane_bias(s, clamp(lod, 0.0f, float(textureQueryLevels(first) - 1)));
  } else {
    s.z -= receiver_plane_bias(s, 0.0f);
  }
  float zf = s.z;
  if (kLookup == MSM_LOOKUP_BILINEAR) {
    texel.a = textureGrad(first, vec3(uv, shadow_layer), duv_dx, duv_dy);
    if (second) texel.b = textureGrad(second_image, vec3(uv, shadow_layer), duv_dx, duv_dy);
  } else {
    ivec2 i = lookup_texel(s.t);
    texel.a = texelFetch(first, ivec3(i, shadow_layer), 0);
    if (second) texel.b = texelFetch(second_image, ivec3(i, shadow_layer), 0);
    zf = receiver_depth_at(s, i);
  }
  if (kSplitRG) texel = MsmTexel(vec4(texel.a.x, texel.a.y, texel.b.x, texel.b.y), vec4(0.0f));
  return msm_technique_shadow(kTechnique, texel, zf, frame.technique_params);
}

float shadow_intensity(ShadowLookup s) { return shadow_from(moments0, moments1, s); }

#ifdef MSM_COLOURED_SHADOWS
vec3 shadow_intensity_rgb(ShadowLookup s) {
  return vec3(shadow_from(moments0, moments1, s), shadow_from(moments0_g, moments1_g, s),
              shadow_from(moments0_b, moments1_b, s));
}
#endif
