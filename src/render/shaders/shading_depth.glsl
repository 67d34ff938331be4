// Shading with the depth-based techniques: the plain shadow map, PCF and PCSS. PCF uses exactly the
// kernel the moment techniques get from their pipeline (Gaussian blur, then a bilinear lookup):
// the weight of depth texel i along an axis is (1 - f) g[i - i0 + R] + f g[i - i0 - 1 + R] for
// t = i0 + f, over taps + 1 texels, and every MSAA sample counts 1 / samples.
#include "shading.glsl"
#include "soft_clamps.glsl"
#include "soft_light.glsl"
#define MSM_DEPTH_BINDING MSM_BINDING_SHADING_SHADOW_MAP
#define MSM_DEPTH_LAYERED 1
#include "depth_map.glsl"

// The depth map's MSAA samples and the PCF kernel's taps (FrameConfig::msaa, ::taps), compiled in:
// as loop bounds read from the uniforms they made lavapipe recompile the shader per frame (see
// kLightCount in shading.glsl).
layout(constant_id = MSM_SPEC_DEPTH_SAMPLES) const int kSamples = 1;
layout(constant_id = MSM_SPEC_PCF_TAPS) const int kTaps = 1;

vec2 sample_offset(int k) {
  vec4 pair = frame.sample_offsets[k / 2];
  return (k & 1) == 0 ? vec2(pair.x, pair.y) : vec2(pair.z, pair.w);
}

// The texel's samples in front of the receiver plane, each compared with the plane's depth at its
// own position (the rasterizer wrote the occluder's depth there): x their number, y the sum of
// their depths (PCSS's blocker search).
vec2 texel_blockers(ivec2 i, ShadowLookup s) {
  int size = int(frame.shadow_map.x);
  const int samples = kSamples;
  ivec2 c = clamp(i, ivec2(0), ivec2(size - 1));
  float plane = s.z + dot(s.depth_per_texel, vec2(i) - s.t);
  vec2 blockers = vec2(0.0f);
  for (int k = 0; k < samples; ++k) {
    float d = depth_sample(c, k);
    if (d < plane + dot(s.depth_per_texel, sample_offset(k))) blockers += vec2(1.0f, d);
  }
  return blockers;
}

// Fraction of the texel's samples in front of the receiver plane.
float texel_occlusion(ivec2 i, ShadowLookup s) { return texel_blockers(i, s).x / float(kSamples); }

// Percentage-closer soft shadows (soft.h): every sample of the grid-aligned search rectangle is
// tested against the receiver plane, those in front average to the blocker depth; the penumbra
// region of soft.h is then filtered with texel_occlusion, each texel weighted by its overlap. The
// search and filter sizes follow soft.h exactly as for the moment soft shadows (kernel width
// frame.soft_kernel.x, 15 by default), so the two differ only in what they read.
float pcss_shadow(ShadowLookup s) {
  ivec2 map = ivec2(int(frame.shadow_map.x));
  int width = frame.soft_kernel.x;
  const int samples = kSamples;
  SoftLight light = soft_light(shadow_layer, s);
  float zf = msm_signed_depth(s.z);
  vec2 position = s.t + 0.5f; // texel i covers [i, i + 1) in soft.h
  SatRect r = msm_soft_search_rect(
      position, msm_soft_search_half_width(light.spread, zf, light.near_depth, light.perspective, width), map);
  vec2 blockers = vec2(0.0f);
  for (int y = r.lo.y; y <= r.hi.y; ++y)
    for (int x = r.lo.x; x <= r.hi.x; ++x) blockers += texel_blockers(ivec2(x, y), s);
  BlockerResult blocker = msm_soft_pcss_blocker(blockers.y, blockers.x, float(msm_sat_rect_texels(r) * samples), s.z);
  bool filtered = blocker.shadow > 0.0f && blocker.shadow < 1.0f;
  float zb = msm_signed_depth(blocker.depth);
  count_soft_lookup(filtered &&
                    msm_soft_penumbra_clamped(light.spread, zf, zb, light.near_depth, light.perspective, width));
  if (blocker.shadow <= 0.0f) return 0.0f;
  // Every sample of the search region blocks: so does every one of the smaller filter region.
  if (blocker.shadow >= 1.0f) return 1.0f;
  vec2 hp = msm_soft_penumbra_half_width(light.spread, zf, zb, light.near_depth, light.perspective, width);
  SoftRegion region = msm_soft_region(position, hp, map);
  ivec2 lo = ivec2(floor(region.lo)), hi = min(ivec2(ceil(region.hi)), map) - 1;
  float shadow = 0.0f;
  for (int y = lo.y; y <= hi.y; ++y) {
    float wy = msm_soft_texel_overlap(y, region.lo.y, region.hi.y);
    for (int x = lo.x; x <= hi.x; ++x)
      shadow += wy * msm_soft_texel_overlap(x, region.lo.x, region.hi.x) * texel_occlusion(ivec2(x, y), s);
  }
  vec2 extent = region.hi - region.lo;
  return shadow / (extent.x * extent.y);
}

// Tap k of the PCF kernel of the light's layer: the frame's (kTaps of them), or with cascades the
// layer's own (LightUniforms::kernel: the first cascade's width in world units, msm/cascade.h; 0
// beyond its radius), from msm/filter.h as the host computes the frame's.
float pcf_weight(int k) {
  if (!kCascades) return kernel_weight(k);
  vec4 kernel = lights[shadow_layer].kernel;
  return msm_filter_weight_at(k - kTaps / 2, int(kernel.y), kernel.x);
}

float shadow_intensity(ShadowLookup s) {
  if (kTechnique == MSM_TECH_PCSS) return pcss_shadow(s);
  if (kTechnique == MSM_TECH_PLAIN) return texel_occlusion(ivec2(floor(s.t + 0.5f)), s);
  const int taps = kTaps, radius = kTaps / 2;
  float weights[kTaps];
  for (int k = 0; k < taps; ++k) weights[k] = pcf_weight(k);
  ivec2 i0 = ivec2(floor(s.t));
  vec2 f = s.t - vec2(i0);
  float shadow = 0.0f;
  for (int y = 0; y <= taps; ++y) {
    float wy = (y < taps ? (1.0f - f.y) * weights[y] : 0.0f) + (y > 0 ? f.y * weights[y - 1] : 0.0f);
    for (int x = 0; x <= taps; ++x) {
      float wx = (x < taps ? (1.0f - f.x) * weights[x] : 0.0f) + (x > 0 ? f.x * weights[x - 1] : 0.0f);
      shadow += wx * wy * texel_occlusion(i0 + ivec2(x, y) - ivec2(radius), s);
    }
  }
  return shadow;
}
