// The scattering pass (JCGT §5.5: a deferred pass after the shading): per pixel, the view ray from
// the camera to the visible surface (to the far plane where there is none), the visible fraction
// of its in-scattering from every light of the frame, and the composite over the surface radiance
// (scattering.h: the sum over the lights), tone mapped. Light l's visible fraction:
//  - ray marching (JCGT §5.5.1's baseline): equidistant jittered samples (scattering.h, ray_march.h)
//    against light l's hard depth map (its layer of the depth array, sample 0 of each texel). Samples
//    outside the map's x, y range count as lit (nothing there casts into the map); below its far
//    plane they compare at depth 1.
//  - prefiltered (MSM_SCATTER_PREFILTERED, JCGT §5.1.1, §5.3, §5.4): one bilinear lookup in light l's
//    prefix-summed rectified map (its layer; its rectification rects[l], rectification.h), four (or,
//    MSM_SIX_MOMENTS, six) moments with adaptive β (or a fixed one: parameters y, z); with MSM_CSM
//    (Klehm et al. 2014) the eight layers 8 l .. 8 l + 7 of a convolution shadow map with 32
//    coefficients at 8 bits, reconstructed at the ray's [0,1] rectified depth. A spot light's lookup
//    is at its angle ψ at the light (rectification.h's spot section), and its unshadowed
//    in-scattering an integral over ψ (msm_spot_unshadowed_inscattering).
// The scattering attachment's alpha is the visible fraction over all lights (msm_scattering_sum_visible).
#include "msm/ray_march.h"
#include "msm/render/rectification_uniforms.h"
#include "msm/shading.h"
#define MSM_LIGHT_BINDING MSM_BINDING_SCATTER_LIGHTS
#include "frame.glsl"
#include "light_loop.glsl"
#ifdef MSM_SCATTER_PREFILTERED
// K transmittance layers per light (rectification.h; 1: the paper's Δ(v)), light l's from K l (CSM:
// eight image layers each, light l's layer k from 8 (K l + k)).
layout(constant_id = MSM_SPEC_SCATTER_LAYERS) const int kLayers = 1;
layout(constant_id = MSM_SPEC_PREFIX_SUM_MIPS) const bool kPrefixSumMips = false; // FrameConfig::prefix_sum_mips > 1
layout(constant_id = MSM_SPEC_SCATTER_BETA_MODE) const
    int kBetaMode = 0; // FrameConfig::scattering_beta: MSM_SCATTERING_BETA_*
layout(binding = MSM_BINDING_SCATTER_SHADOW_MAP) uniform sampler2DArray
    prefix_sums; // Θ4* (16-bit), Θ6* image 0 or CSM's RGBA8, bilinear
layout(std430, binding = MSM_BINDING_SCATTER_RECTS) readonly buffer RectificationBlock {
  RectificationUniforms rects[];
};
#ifdef MSM_SIX_MOMENTS
layout(binding = MSM_BINDING_SCATTER_PREFIX_SUMS1) uniform sampler2DArray prefix_sums1; // Θ6* image 1
#endif
#else
#define MSM_DEPTH_BINDING MSM_BINDING_SCATTER_SHADOW_MAP
#define MSM_DEPTH_LAYERED 1
#include "depth_map.glsl"
#endif

layout(binding = MSM_BINDING_SCATTER_SURFACE_RADIANCE) uniform sampler2D surface_radiance; // linear, before exposure
layout(binding = MSM_BINDING_SCATTER_CAMERA_DEPTH) uniform sampler2D camera_depth;
layout(binding = MSM_BINDING_SCATTER_BLUE_NOISE) uniform sampler2DArray blue_noise;
layout(push_constant) uniform Push { ScatteringPush scatter; };

layout(location = 0) out vec4 out_color;      // tone mapped; the attachment is sRGB
layout(location = 1) out vec4 out_scattering; // rgb: in-scattered radiance, a: visible fraction

// Whether some light of the frame is a spot light (FrameConfig::spot_lights; shading.glsl's): a
// constant, so that frames of directional lights only compile no spot path.
layout(constant_id = MSM_SPEC_SPOT_LIGHTS) const bool kSpotLights = false;
bool is_spot(int l) { return kSpotLights && lights[l].spot_position.w > 0.0f; }

#ifndef MSM_SCATTER_PREFILTERED

// 1 where spot light shadow_layer reaches p, 0 where its map (radial distance / range) has an
// occluder nearer to the light; its depth bias grows with the distance as the shading's
// (spot_lookup). Outside the map's frustum: lit (the cone brings nothing there).
float spot_light_reaches(vec3 p) {
  vec4 clip = lights[shadow_layer].view_projection * vec4(p, 1.0f);
  vec2 ndc = vec2(clip) / clip.w;
  if (!(clip.w > 0.0f) || any(greaterThan(abs(ndc), vec2(1.0f)))) return 1.0f;
  int size = int(frame.shadow_map.x);
  ivec2 texel = clamp(ivec2(floor((ndc * 0.5f + 0.5f) * frame.shadow_map.x)), ivec2(0), ivec2(size - 1));
  float r = distance(p, lights[shadow_layer].spot_position.xyz);
  float bias = frame.shadow_map.w * 2.0f * lights[shadow_layer].spot_axis.w * r;
  return depth_sample(texel, 0) < min((r - bias) / lights[shadow_layer].spot_position.w, 1.0f) ? 0.0f : 1.0f;
}

// 1 where light shadow_layer reaches p, 0 where its depth map has an occluder in front of p.
float light_reaches(vec3 p) {
  vec4 clip = lights[shadow_layer].view_projection * vec4(p, 1.0f);
  if (any(lessThan(vec2(clip.x, clip.y), vec2(-1.0f))) || any(greaterThan(vec2(clip.x, clip.y), vec2(1.0f))))
    return 1.0f;
  int size = int(frame.shadow_map.x);
  ivec2 texel =
      clamp(ivec2(floor((vec2(clip.x, clip.y) * 0.5f + 0.5f) * frame.shadow_map.x)), ivec2(0), ivec2(size - 1));
  return depth_sample(texel, 0) < min(clip.z, 1.0f) - frame.shadow_map.w ? 0.0f : 1.0f;
}

// One blue-noise jitter per pixel (the frame's layer and offset), strictly below 1.
float march_jitter(ivec2 pixel) {
  ivec2 n = (pixel + ivec2(frame.lookup.z, frame.lookup.w)) & 63;
  return (texelFetch(blue_noise, ivec3(n, frame.lookup.y), 0).x * 255.0f + 0.5f) / 256.0f;
}

// Spot light l's in-scattering along the ray, added to sum: its f E (msm_local_light_inscattering)
// varies along the ray, so each sample weighs it with its shadow; the light's visible fraction is
// Σ w f E V / Σ w f E (luminance) and its unshadowed f E the samples' mean, as the ray tracer's.
ScatteringSum add_spot_light(ScatteringSum sum, int l, ivec2 pixel, vec3 camera, vec3 direction, float s) {
  current_layer = l;
  float extinction = scatter.medium.x;
  int count = scatter.march.x;
  float jitter = march_jitter(pixel);
  vec3 unshadowed = vec3(0.0f), lit = vec3(0.0f);
  for (int i = 0; i < count; ++i) {
    vec3 p = camera + msm_ray_march_distance(s, count, i, jitter) * direction;
    vec3 fe = msm_ray_march_weight(extinction, s, count, i) *
              msm_local_light_inscattering(p, direction, lights[l].spot_position.xyz, lights[l].spot_axis.xyz,
                                           lights[l].irradiance.rgb, lights[l].spot_position.w, lights[l].spot_cone.x,
                                           lights[l].spot_cone.y, extinction, scatter.medium.y, scatter.medium.z);
    unshadowed += fe;
    if (msm_luminance(fe) > 0.0f) lit += fe * spot_light_reaches(p);
  }
  float total = msm_transmittance_integral(extinction, 0.0f, s);
  float weight = msm_luminance(unshadowed);
  float visible = weight > 0.0f ? msm_saturate(msm_luminance(lit) / weight) : 1.0f;
  return msm_scattering_add_light(sum, total > 0.0f ? unshadowed / total : vec3(0.0f), extinction, 1.0f, s, visible);
}

float visible_fraction(int l, ivec2 pixel, vec3 camera, vec3 direction, float s) {
  current_layer = l;
  float extinction = scatter.medium.x;
  int count = scatter.march.x;
  float jitter = march_jitter(pixel);
  float weighted = 0.0f;
  for (int i = 0; i < count; ++i) {
    vec3 p = camera + msm_ray_march_distance(s, count, i, jitter) * direction;
    weighted += msm_ray_march_weight(extinction, s, count, i) * light_reaches(p);
  }
  return msm_ray_march_visible_fraction(weighted, extinction, s);
}
#else
// One lookup in light l's prefix sums at the ray's row and reach, reconstructed at the ray's
// rectified depth with the technique's β (kBetaMode: proportional, fixed or §5.3.1's adaptive).
float visible_fraction(int l, ivec2 pixel, vec3 camera, vec3 direction, float s) {
  current_layer = l;
  RectificationUniforms rect = rects[shadow_layer];
  RectificationFrame f = msm_rectification_frame_of(rect);
  RectifiedBounds b = msm_rectified_bounds_of(rect);
  bool spot = kSpotLights && msm_rectification_is_spot(rect);
  vec3 end = camera + s * direction;
  vec3 lookup = spot ? msm_spot_view_lookup(f, b, rect.spot.x, end, rect.map.x)
                     : msm_rectified_view_lookup(f, b, end, rect.map.x);
  // The sampler repeats: u and, unless φ spans the full circle (rows 0 and height − 1 neighbours,
  // rectification.h), v are clamped to the texel centres at the edges here.
  bool full_circle = b.phi_span >= MSM_TWO_PI;
  // App. D.5, where the prefix sums have mips: the level of the pixel's footprint (derivatives here,
  // in uniform control flow: the lights' loop and the medium's test are uniform).
  float lod = 0.0f;
  if (kPrefixSumMips)
    lod = min(msm_prefix_sum_lod(vec2(dFdx(lookup.x), dFdy(lookup.x)), vec2(dFdx(lookup.y), dFdy(lookup.y)),
                                 vec2(rect.map.x, rect.map.y), full_circle),
              float(textureQueryLevels(prefix_sums) - 1));
  // Clamped to the texel centres of the coarser of the two levels read (trilinear).
  vec2 half_texel = 0.5f * exp2(ceil(lod)) / vec2(rect.map.x, rect.map.y);
  vec2 uv = vec2(clamp(lookup.x, half_texel.x, 1.0f - half_texel.x),
                 full_circle ? lookup.y : clamp(lookup.y, half_texel.y, 1.0f - half_texel.y));
  // Transmittance layers: the two that bracket the ray's own step, mixed (1 − t, t) as stored vectors
  // (a convex combination of prefix sums; the affine storage transforms commute with it).
  float layer0 = float(shadow_layer * kLayers), mix_t = 0.0f;
  if (kLayers > 1) {
    vec2 range = msm_transmittance_layer_range(b, scatter.medium.x, rect.map.x);
    vec2 k =
        msm_transmittance_layer_lookup(range, msm_rectified_view_ray_step(f, b, direction, rect.map.x), float(kLayers));
    layer0 += k.x;
    mix_t = k.y;
  }
#define MSM_LAYERED_LOOKUP(image, layer)                                                                               \
  (kLayers > 1                                                                                                         \
       ? mix(textureLod(image, vec3(uv, (layer)), lod), textureLod(image, vec3(uv, (layer) + 1.0f), lod), mix_t)       \
       : textureLod(image, vec3(uv, (layer)), lod))
#ifdef MSM_CSM
  CsmMoments m = CsmMoments(mat4(0.0f), mat4(0.0f));
  for (int t = 0; t < MSM_CSM_MAX_TEXELS; ++t) {
    // Layer k + 1's term t is 8 image layers after layer k's.
    vec4 texel = msm_csm_from_unorm(
        kLayers > 1
            ? mix(textureLod(prefix_sums, vec3(uv, float(MSM_CSM_MAX_TEXELS) * layer0 + float(t)), lod),
                  textureLod(prefix_sums, vec3(uv, float(MSM_CSM_MAX_TEXELS) * (layer0 + 1.0f) + float(t)), lod), mix_t)
            : textureLod(prefix_sums, vec3(uv, float(MSM_CSM_MAX_TEXELS * shadow_layer + t)), lod));
    if (t < 4)
      m.lo[t] = texel;
    else
      m.hi[t - 4] = texel;
  }
  return msm_scattering_visibility_csm(m, msm_saturate(lookup.z), msm_csm_scattering_params());
#else
  vec4 stored = MSM_LAYERED_LOOKUP(prefix_sums, layer0);
  float zf = msm_signed_depth(lookup.z);
#ifdef MSM_SIX_MOMENTS
  // march.y: the storage (MSM_REP6_*); 10 bits keep the odd and the even moments in one image each.
  int representation = scatter.march.y;
  vec4 stored1 = MSM_LAYERED_LOOKUP(prefix_sums1, layer0);
  Moments6 m = representation == MSM_REP6_UNORM10
                   ? Moments6(vec3(stored.x, stored.y, stored.z), vec3(stored1.x, stored1.y, stored1.z))
                   : Moments6(vec3(stored.x, stored.y, stored.z), vec3(stored.w, stored1.x, stored1.y));
  vec2 bounds = msm_scattering_shadow_bounds6(m, representation, zf);
#else
  vec2 bounds = msm_scattering_shadow_bounds4(stored, MSM_REP_SIGNED_THETA4, zf);
#endif
  // kBetaMode (the technique's parameter z): a fixed β = y, §5.3.1's adaptive β or the proportional β.
  // A spot light's epipole is the direction from the camera to the light.
  vec3 towards_light = spot ? -vec3(f.z_axis) : lights[shadow_layer].towards_light.xyz;
  float adaptive = msm_scattering_beta_adaptive(towards_light, direction);
  return msm_scattering_visibility_between(bounds,
                                           msm_scattering_beta(kBetaMode, bounds, frame.technique_params.y, adaptive));
#endif // MSM_CSM
}
#endif

#ifdef MSM_SCATTER_PREFILTERED
// Spot light l's in-scattering along the ray, added to sum: the visible fraction of its prefix sums
// times its unshadowed in-scattering, integrated over the light's angle ψ (scattering.h).
ScatteringSum add_spot_light(ScatteringSum sum, int l, ivec2 pixel, vec3 camera, vec3 direction, float s) {
  float extinction = scatter.medium.x;
  vec3 unshadowed = msm_spot_unshadowed_inscattering(
      camera, direction, s, lights[l].spot_position.xyz, lights[l].spot_axis.xyz, lights[l].irradiance.rgb,
      lights[l].spot_position.w, lights[l].spot_cone.x, lights[l].spot_cone.y, extinction, scatter.medium.y,
      scatter.medium.z, MSM_SPOT_INSCATTERING_SAMPLES);
  float total = msm_transmittance_integral(extinction, 0.0f, s);
  return msm_scattering_add_light(sum, total > 0.0f ? unshadowed / total : vec3(0.0f), extinction, 1.0f, s,
                                  visible_fraction(l, pixel, camera, direction, s));
}
#endif

// Light l's in-scattering along the view ray, added to sum.
ScatteringSum add_light(ScatteringSum sum, int l, ivec2 pixel, vec3 camera, vec3 direction, float s) {
  if (is_spot(l)) return add_spot_light(sum, l, pixel, camera, direction, s);
  float extinction = scatter.medium.x;
  float phase =
      msm_scattering_phase_term(extinction, scatter.medium.y, scatter.medium.z, lights[l].towards_light.xyz, direction);
  return msm_scattering_add_light(sum, lights[l].irradiance.rgb, extinction, phase, s,
                                  visible_fraction(l, pixel, camera, direction, s));
}

void main() {
  ivec2 pixel = ivec2(gl_FragCoord.xy);
  vec3 surface = texelFetch(surface_radiance, pixel, 0).rgb;
  float depth = texelFetch(camera_depth, pixel, 0).x;
  vec2 ndc = (vec2(pixel) + 0.5f) / vec2(textureSize(camera_depth, 0)) * 2.0f - 1.0f;
  vec4 end = scatter.inverse_view_projection * vec4(ndc, depth, 1.0f);
  vec3 camera = scatter.camera.xyz;
  vec3 ray = end.xyz / end.w - camera;
  float s = length(ray);
  vec3 direction = s > 0.0f ? ray / s : vec3(0.0f, 0.0f, -1.0f);

  vec3 radiance = surface, inscattered = vec3(0.0f);
  float visible = 1.0f;
  if (scatter.medium.w != 0.0f) {
    float extinction = scatter.medium.x;
    ScatteringSum sum = msm_scattering_sum_none();
    // One light: one pass through the body, no loop (light_loop.glsl).
    int l = 0;
    do { sum = add_light(sum, l, pixel, camera, direction, s); } while (!kOneLight && ++l < kLightCount);
    radiance = msm_scattering_sum_radiance(surface, extinction, s, sum);
    inscattered = sum.inscattered;
    visible = msm_scattering_sum_visible(sum);
  }
  out_color = vec4(msm_aces(radiance * frame.shading.y), 1.0f);
  out_scattering = vec4(inscattered, visible);
}
