// Resampling of one light's shadow map into its rectified map of prefiltered single scattering
// (JCGT §5.1.1, §5.2; rectification.h), one dispatch per light (the push constant's size.z: the
// light, its rectification rects[light] and its layer of the rectified images; the depth map bound
// is that light's layer): per rectified texel, the light ray at (r, φ) is
// looked up in the light's depth map, without filtering (the nearest texel, sample 0), or, where
// the technique's parameter x is 1, with filtering (§5.2; the _filtered variants, MSM_FILTERED_MAP):
// a trilinear sample of the frame's blurred, mipmapped 4-moment map of [0,1] depth (moment_resolve,
// blur and mipmaps of msm-hamburger-128-unit; FrameConfig::resampling_moments) at the level of the
// texel's footprint in the shadow map (msm_rectified_resampling_lod), turned into two depths by
// JCGT Algorithm 2; or, where x is 2 (kOnTheFlyFilter), the earlier on-the-fly filter kept
// for comparison: a bilinear sample of the four moments of the depth map's texels (each the mean
// of its MSAA samples' moments: the resolved moment map without blur and mips). Each depth is
// mapped to the rectified depth π − θ and turned into the technique's moments in its storage basis
// (Θ4*; with MSM_SIX_MOMENTS Θ6* over two images: (odd, even.x) and (even.y, even.z); with MSM_CSM
// Klehm et al.'s 16 sin/cos terms of [0,1] depth mapped to [0,1] (msm_csm_to_unorm), four per layer
// of the light's eight layers 8 light .. 8 light + 7 of an RGBA16F array: the 8-bit storage comes
// after the prefix sums), written as
// float for the prefix sums. A light ray outside the map, or over a texel without
// a caster, gets the farthest rectified depth: nothing on it shadows any view ray. A spot light's
// texel (rectification.h's spot section, rects[light].spot) is the light ray at angle ψ from the
// light's direction to the camera, looked up in the spot's map of radial distance without filtering.
#include "msm/render/rectification_uniforms.h"
#include "msm/quantize.h"
#define MSM_LIGHT_BINDING MSM_BINDING_RECTIFY_LIGHTS
#include "frame.glsl"
#ifdef MSM_FILTERED_MAP
layout(binding = MSM_BINDING_RECTIFY_SOURCE) uniform sampler2D resampling_moments; // the light's layer, every mip, trilinear
#else
#define MSM_DEPTH_BINDING MSM_BINDING_RECTIFY_SOURCE
#include "depth_map.glsl"
layout(constant_id = MSM_RECTIFY_ON_THE_FLY_SPEC_ID) const bool kOnTheFlyFilter = false; // parameter x = 2
#endif

// Whether some light of the frame is a spot light (FrameConfig::spot_lights): a constant, so that
// frames of directional lights only compile no spot path.
layout(constant_id = MSM_SPEC_SPOT_LIGHTS) const bool kSpotLights = false;

layout(local_size_x = 8, local_size_y = 8) in;
layout(std430, binding = MSM_BINDING_RECTIFY_RECTS) readonly buffer RectificationBlock { RectificationUniforms rects[]; };
layout(push_constant) uniform Push { ImagePassPush pass; }; // size.z: the light
#ifdef MSM_CSM
layout(binding = MSM_BINDING_RECTIFY_TARGET, rgba16f) uniform writeonly image2DArray rectified;
#else
layout(binding = MSM_BINDING_RECTIFY_TARGET, rgba32f) uniform writeonly image2D rectified;
#endif
#ifdef MSM_SIX_MOMENTS
layout(binding = MSM_BINDING_RECTIFY_TARGET1, rgba32f) uniform writeonly image2D rectified1;
#endif

#ifndef MSM_FILTERED_MAP
// A spot light's texel (rectification.h's spot section): the light ray (ψ, φ) from the light looked up
// in the spot's perspective map of radial distance / range, without filtering (the nearest texel,
// sample 0); a caster at distance ρ on it gives the rectified depth of its γ, seen from the camera.
// A ray outside the map (outside the spot's cone) or over no caster: the farthest depth.
TwoDepths spot_texel(int light, RectificationUniforms rect, RectificationFrame f, RectifiedBounds b, vec2 uv) {
  TwoDepths farthest = TwoDepths(vec2(1.0f), vec2(1.0f, 0.0f));
  vec3 direction = msm_spot_light_ray_direction(f, b, uv);
  vec4 clip = lights[light].view_projection * vec4(lights[light].spot_position.xyz + direction, 1.0f);
  vec2 ndc = vec2(clip) / clip.w;
  if (!(clip.w > 0.0f) || any(greaterThan(abs(ndc), vec2(1.0f)))) return farthest;
  int map = int(frame.shadow_map.x);
  ivec2 t = clamp(ivec2(floor((ndc * 0.5f + 0.5f) * frame.shadow_map.x)), ivec2(0), ivec2(map - 1));
  float depth = depth_sample(t, 0);
  if (!(depth < 1.0f)) return farthest;
  return msm_spot_rectified_one_depth(b, uv.x * b.r_max, rect.spot.x, depth * lights[light].spot_position.w);
}
#endif

// A directional light's texel: the light ray at (r, φ) through the texel's centre in the light's
// orthographic map (rectification.h).
TwoDepths directional_texel(int light, RectificationUniforms rect, RectificationFrame f, RectifiedBounds b, vec2 uv,
                            ivec2 size) {
  TwoDepths d = TwoDepths(vec2(1.0f), vec2(1.0f, 0.0f));
  vec3 p = msm_rectified_light_ray_point(f, b, uv);
  float r = msm_rectified_r_phi(b, uv).x;
  vec4 clip = lights[light].view_projection * vec4(p, 1.0f);
  // The map's depth d lies at rectification z = extent (d − d(p)) on this light ray.
  vec2 depth_to_z = vec2(rect.map.z, -clip.z * rect.map.z);
  bool inside = all(greaterThanEqual(vec2(clip.x, clip.y), vec2(-1.0f))) &&
                all(lessThanEqual(vec2(clip.x, clip.y), vec2(1.0f)));
  if (inside) {
#ifdef MSM_FILTERED_MAP
    // The texel's footprint: the light's (orthographic) projection of the frame's axes across the
    // light, in shadow-map texels per unit, through the rectification's Jacobian.
    float half_map = 0.5f * frame.shadow_map.x;
    vec2 per_x = half_map * vec2(lights[light].view_projection * vec4(f.x_axis, 0.0f));
    vec2 per_y = half_map * vec2(lights[light].view_projection * vec4(f.y_axis, 0.0f));
    float lod = msm_rectified_resampling_lod(msm_rectified_r_phi(b, uv),
                                             vec2(b.r_max / float(size.x), b.phi_span / float(size.y)), per_x, per_y);
    vec4 moments = textureLod(resampling_moments, vec2(clip.x, clip.y) * 0.5f + 0.5f, lod);
    d = msm_rectified_two_depths(b, r, depth_to_z, moments);
#else
    int map = int(frame.shadow_map.x);
    ivec2 t = clamp(ivec2(floor((vec2(clip.x, clip.y) * 0.5f + 0.5f) * frame.shadow_map.x)), ivec2(0), ivec2(map - 1));
    if (kOnTheFlyFilter) {
      vec2 p = (vec2(clip.x, clip.y) * 0.5f + 0.5f) * frame.shadow_map.x - 0.5f;
      ivec2 i0 = ivec2(floor(p));
      vec2 f = p - vec2(i0);
      int samples = frame.kernel.y;
      vec4 moments = vec4(0.0f);
      for (int k = 0; k < 4; ++k) {
        ivec2 o = ivec2(k & 1, k >> 1);
        float w = (o.x == 1 ? f.x : 1.0f - f.x) * (o.y == 1 ? f.y : 1.0f - f.y) / float(samples);
        ivec2 c = clamp(i0 + o, ivec2(0), ivec2(map - 1));
        for (int s = 0; s < samples; ++s) moments += w * msm_moments4(msm_saturate(depth_sample(c, s)));
      }
      d = msm_rectified_two_depths(b, r, depth_to_z, moments);
    } else {
      float depth = depth_sample(t, 0);
      if (depth < 1.0f) d = msm_rectified_one_depth(b, r, depth_to_z, depth);
    }
#endif
  }
  return d;
}

// The texel's moments in the technique's storage basis.
void store_texel(ivec2 texel, int light, TwoDepths d) {
#if defined(MSM_CSM)
  CsmMoments m = msm_rectified_csm(d, MSM_CSM_MAX_TERMS);
  for (int t = 0; t < MSM_CSM_MAX_TEXELS; ++t) imageStore(rectified, ivec3(texel, MSM_CSM_MAX_TEXELS * light + t), msm_csm_to_unorm(msm_csm_texel(m, t)));
#elif defined(MSM_SIX_MOMENTS)
  Moments6 m = msm_theta6_star(msm_rectified_moments6(d));
  imageStore(rectified, texel, vec4(m.odd, m.even.x));
  imageStore(rectified1, texel, vec4(m.even.y, m.even.z, 0.0f, 0.0f));
#else
  imageStore(rectified, texel, msm_theta4_star(msm_rectified_moments4(d)));
#endif
}

void main() {
  ivec2 texel = ivec2(gl_GlobalInvocationID.xy);
  int light = pass.size.z;
  RectificationUniforms rect = rects[light];
  ivec2 size = ivec2(int(rect.map.x), int(rect.map.y));
  if (texel.x >= size.x || texel.y >= size.y) return;
  RectificationFrame f = msm_rectification_frame_of(rect);
  RectifiedBounds b = msm_rectified_bounds_of(rect);
  vec2 uv = (vec2(texel) + 0.5f) / vec2(size);
  TwoDepths d = TwoDepths(vec2(1.0f), vec2(1.0f, 0.0f));
#ifndef MSM_FILTERED_MAP
  // Spot lights are resampled without filtering only (the renderer refuses the other resamplings).
  if (kSpotLights && msm_rectification_is_spot(rect)) {
    d = spot_texel(light, rect, f, b, uv);
  } else
#endif
  {
    d = directional_texel(light, rect, f, b, uv, size);
  }
  store_texel(texel, light, d);
}
