// Shadow-map lookups of the filtered techniques (MSM_LOOKUP_*): where to read, and the
// bilinear weights. The blue-noise textures (64 layers, RG8) dither the nearest lookup.
#include "msm/render/bindings.h"
layout(binding = MSM_BINDING_SHADING_BLUE_NOISE) uniform sampler2DArray blue_noise;

// Texel-centre coordinate t (texel i covers [i - 0.5, i + 0.5)) -> the texel a nearest or
// dithered lookup reads, clamped to the map.
ivec2 lookup_texel(vec2 t) {
  if (kLookup == MSM_LOOKUP_DITHER) {
    ivec2 n = (ivec2(gl_FragCoord.xy) + frame.lookup.zw) & 63;
    t += texelFetch(blue_noise, ivec3(n, frame.lookup.y), 0).xy - 0.5f;
  }
  int last = int(frame.shadow_map.x) - 1;
  return clamp(ivec2(floor(t + 0.5f)), ivec2(0), ivec2(last));
}

// The receiver plane's depth at the centre of texel i: a nearest or dithered lookup reads a
// texel up to a texel away from the fragment, and comparing with the fragment's own depth there
// would shadow sloped receivers by their own slope (acne).
float receiver_depth_at(ShadowLookup s, ivec2 i) { return s.z + dot(s.depth_per_texel, vec2(i) - s.t); }

// The four texels of a bilinear lookup at t (clamped) and their weights (x: i0, y: i0 + 1).
struct Bilinear {
  ivec2 i0, i1;
  vec2 f;
};
Bilinear bilinear_texels(vec2 t) {
  int last = int(frame.shadow_map.x) - 1;
  vec2 base = floor(t);
  Bilinear b;
  b.f = t - base;
  b.i0 = clamp(ivec2(base), ivec2(0), ivec2(last));
  b.i1 = clamp(ivec2(base) + 1, ivec2(0), ivec2(last));
  return b;
}

// Receiver-plane bias of the filtered techniques (msm/bias.h), in [0,1] depth, to subtract from
// the fragment depth: the filter kernel spans several texels of a sloped receiver, and the half
// of them in front of the fragment would shadow it (self-shadowing, worst at grazing light).
// frame.receiver_bias.x: the kernel's variance per axis in texels² from the blur and the MSAA
// sample positions (host; with cascades the layer's, LightUniforms::kernel.z); the layer's
// LightUniforms::kernel.w: a multiplier (RenderSettings::resolved_receiver_plane_bias, by default
// 1 for a cascade and 0 for one map; 0 = off), applied to σ (so the negative warp's σ² bias scales
// by its square). The lookup adds its own
// footprint: bilinear at mip λ reads texels that average 2^λ x 2^λ mip-0 texels (variance
// (4^λ − 1)/12 per axis) with tent weights over 2^λ texels (4^λ f(1 − f), 4^λ/6 on average over
// the fractional position f): 4^λ/4 − 1/12 in all, 1/6 at mip 0; trilinear blends two levels,
// which λ's fraction approximates. A nearest or dithered lookup compares at the receiver plane's
// depth at the texel it reads (receiver_depth_at): its kernel is the blur's.
float receiver_plane_bias(ShadowLookup s, float lod) {
  // A cascade's kernel is its own (narrower in its texels: LightUniforms::kernel).
  float variance = kCascades ? lights[shadow_layer].kernel.z : frame.receiver_bias.x;
  // Off (or NaN): a multiplier of 0 (finite σ), selected rather than branched on, because lavapipe
  // recompiles a shader per frame for some branches on a uniform (kLightCount, shading.glsl).
  float multiplier = lights[shadow_layer].kernel.w > 0.0f ? lights[shadow_layer].kernel.w : 0.0f;
  if (kLookup == MSM_LOOKUP_BILINEAR) variance += exp2(2.0f * lod) * 0.25f - 1.0f / 12.0f;
  float sigma = multiplier * msm_receiver_depth_sigma(s.depth_per_texel, variance); // [0,1] depth
  if (msm_technique_is_six_moments(kTechnique)) return MSM_RECEIVER_SIGMAS6 * sigma;
  if (kTechnique == MSM_TECH_EVSM4_64 || kTechnique == MSM_TECH_EVSM4_128)
    return 0.5f * msm_receiver_plane_bias_negative_warp(2.0f * sigma, frame.technique_params.z); // [-1,1] warp
  // Cantelli (VSM, EVSM2's positive warp) and Markov (ESM): nothing in front at the mean depth.
  if (kTechnique == MSM_TECH_VSM32 || kTechnique == MSM_TECH_VSM64 || kTechnique == MSM_TECH_ESM32 ||
      kTechnique == MSM_TECH_EVSM2_32 || kTechnique == MSM_TECH_EVSM2_64)
    return 0.0f;
  // Four moments: Hamburger, Hausdorff, trigonometric (power moments of the circle's angle to
  // second order for the narrow spread of a kernel) and the non-linear maps (Hamburger 4MSM).
  return MSM_RECEIVER_SIGMAS4 * sigma;
}
