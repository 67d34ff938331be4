// Every filtered-shadow technique as three per-texel steps, shared by the CPU pipeline
// (src/core/techniques.cpp) and the renderer's shaders (src/render/shaders): generation of the
// filterable channels for one depth sample, and the reconstruction of the shadow intensity from
// the filtered, stored and reloaded channels. What lies between (MSAA resolve, blur, mips,
// bilinear lookup, storage rounding) is linear filtering plus the texel format, which the GPU
// does with images and the CPU emulates.
//
// A technique is an int id (MSM_TECH_*), a compile-time constant in shaders (a specialization
// constant: the switch folds away), a runtime value on the CPU. Its parameters travel as one vec4
// (msm_technique_default_params gives the papers' values):
//   x: moment bias alpha (MSM, TMSM, 6MSM)          y: exponent c (ESM) or c+ (EVSM)
//   z: exponent c- (EVSM4)                          w: minimum variance (VSM, EVSM)
// Depth conventions: unit_depth and unit_zf are shadow-map depths in [0,1]; techniques on
// [-1,1] map them with msm_signed_depth.
//
// Channel layout of a texel: a = channels 0..3, b = channels 4..7 (6MSM: a = (b1, b3, b5, b2),
// b = (b4, b6, 0, 0), i.e. the odd then the even moments in channel order).
#ifndef MSM_TECHNIQUES_H
#define MSM_TECHNIQUES_H
#include "msm/msm.h"
MSM_BEGIN

// Depth-based techniques (no filterable channels: they read the depth map itself).
const int MSM_TECH_PLAIN = 0; // one depth comparison per fragment
const int MSM_TECH_PCF = 1;   // Gaussian-weighted depth comparisons, the filtered reference
// Baselines.
const int MSM_TECH_VSM32 = 2;     // 2 x UNORM16 after θ2, [0,1]
const int MSM_TECH_VSM64 = 3;     // 2 x float, [0,1]
const int MSM_TECH_ESM32 = 4;     // 1 x float, exp(c z), [0,1]
const int MSM_TECH_EVSM2_32 = 5;  // 2 x half, positive warp, [-1,1]
const int MSM_TECH_EVSM2_64 = 6;  // 2 x float, positive warp c+ = 40
const int MSM_TECH_EVSM4_64 = 7;  // 4 x half, both warps c = 5.54
const int MSM_TECH_EVSM4_128 = 8; // 4 x float, c+ = 40, c- = 5.54
// Four power moments.
const int MSM_TECH_HAMBURGER_128_UNIT = 10;  // 4 x float, [0,1] (2015)
const int MSM_TECH_HAMBURGER_128 = 11;       // 4 x float, [-1,1] (JCGT)
const int MSM_TECH_HAMBURGER_64_THETA4 = 12; // 4 x UNORM16 after θ4, [0,1] (2015)
const int MSM_TECH_HAMBURGER_64 = 13;        // 4 x UNORM16 after Θ4*, [-1,1] (JCGT)
const int MSM_TECH_HAUSDORFF_128_UNIT = 14;
const int MSM_TECH_HAUSDORFF_128 = 15;
const int MSM_TECH_HAUSDORFF_64_THETA4 = 16;
const int MSM_TECH_HAUSDORFF_64 = 17;
// Other bases.
const int MSM_TECH_TMSM_128 = 18; // trigonometric, 4 x float, [0,1]
const int MSM_TECH_MSM6_192 = 19; // six moments, 6 x float, [-1,1]
const int MSM_TECH_MSM6_96 = 20;  // six moments, 6 x UNORM16 after Θ6*
// Non-linearly quantized four moments (HPG 2017), [-1,1]: filtered float moments -> Φ -> storage.
const int MSM_TECH_NL64 = 21; // RGBA16_UNORM: y1, y2, v2, Ψ4(ξ4)
const int MSM_TECH_NL32 = 22; // R32_UINT: folded 10-bit depths, √v2, Ψ4 (HPG §3.5)
// Soft shadows of a directional area light (soft.h). Moment soft shadows (JCGT §4): moments in
// integer summed-area tables (sat.h); VSSM: the same pipeline with two moments; PCSS: the
// depth map itself, every texel of the blocker search and of the filter region.
const int MSM_TECH_MSSM4 = 23; // Θ4*, [-1,1], one table
const int MSM_TECH_MSSM6 = 24; // Θ6*, [-1,1], two tables (Kneiphof §4.2), layout of MSM_TECH_MSM6_96
const int MSM_TECH_VSSM = 25;  // (z, z²) of [0,1] depth, one table (naive variance soft shadows)
const int MSM_TECH_PCSS = 26;  // percentage-closer soft shadows [Fernando 2005]: depth-based
// Single scattering in the scene's medium (JCGT §5, scattering.h), composited over surfaces shaded
// with PCF. Ray marching (ray_march.h): equidistant jittered samples of the hard depth map.
const int MSM_TECH_SCATTER_MARCH32 = 27;
const int MSM_TECH_SCATTER_MARCH128 = 28;
// Prefiltered single scattering (JCGT §5.1.1-5.3): the depth map resampled into the rectified map
// (rectification.h), transmittance-weighted prefix sums along its rows, one lookup per pixel.
const int MSM_TECH_SCATTER_MSM4_64 = 29;  // four moments, Θ4* in 4 x UNORM16, adaptive β
const int MSM_TECH_SCATTER_MSM6_64 = 30;  // six moments (§5.4), Θ6* in 6 x 10 bits (two RGB10A2)
const int MSM_TECH_SCATTER_MSM6_96 = 31;  // Θ6* in 6 x 16 bits (RGBA16 + RG16)
const int MSM_TECH_SCATTER_MSM6_192 = 32; // Θ6* in 6 x 32-bit float (RGBA32F + RG32F)
// Klehm et al. 2014: the same passes with a convolution shadow map of 16 sin/cos terms (32
// coefficients) in 8 bits each (eight RGBA8 layers), [0,1] rectified depth, no β (scattering.h).
const int MSM_TECH_SCATTER_CSM32 = 33;
// Convolution soft shadow maps (Annen et al. 2008; cssm.h), the baseline of Kneiphof's comparison:
// CSM's Fourier basis, the basis times depth and the depth in one integer summed-area table of
// stacked tiles.
const int MSM_TECH_CSSM8 = 35;  // 4 frequencies: 17 values in 5 RGBA tiles
const int MSM_TECH_CSSM16 = 36; // 8 frequencies: 33 values in 9 RGBA tiles

// Soft shadows from summed-area tables instead of a filtered map.
MSM_FN bool msm_technique_is_cssm(int t) { return t == MSM_TECH_CSSM8 || t == MSM_TECH_CSSM16; }
MSM_FN bool msm_technique_is_soft(int t) {
  return t == MSM_TECH_MSSM4 || t == MSM_TECH_MSSM6 || t == MSM_TECH_VSSM || msm_technique_is_cssm(t);
}
// CSM frequencies of the CSSM techniques (0 for the others); their moment image holds
// msm_technique_tiles tiles of the shadow map's size stacked along y (1 for every other).
MSM_FN int msm_technique_cssm_frequencies(int t) {
  return t == MSM_TECH_CSSM8 ? msm_cssm_frequencies(8) : (t == MSM_TECH_CSSM16 ? msm_cssm_frequencies(16) : 0);
}
MSM_FN int msm_technique_tiles(int t) {
  return msm_technique_is_cssm(t) ? msm_cssm_tiles(msm_technique_cssm_frequencies(t)) : 1;
}
// Six moments: the texel's b half (techniques.h layout) goes to a second image.
MSM_FN bool msm_technique_is_six_moments(int t) {
  return t == MSM_TECH_MSM6_192 || t == MSM_TECH_MSM6_96 || t == MSM_TECH_MSSM6;
}
// Every technique whose penumbra follows the light's extent (the others filter with a fixed kernel).
MSM_FN bool msm_technique_is_area_light(int t) { return msm_technique_is_soft(t) || t == MSM_TECH_PCSS; }

struct MsmTexel {
  vec4 a;
  vec4 b;
};

// Single scattering techniques: a scattering pass after the shading (src/render).
MSM_FN bool msm_technique_is_prefiltered_scattering(int t) {
  return (t >= MSM_TECH_SCATTER_MSM4_64 && t <= MSM_TECH_SCATTER_MSM6_192) || t == MSM_TECH_SCATTER_CSM32;
}
// The six-moment storage (MSM_REP6_* of bias.h) of a prefiltered technique; -1 for four moments.
MSM_FN int msm_technique_scatter_representation6(int t) {
  return t == MSM_TECH_SCATTER_MSM6_64    ? MSM_REP6_UNORM10
         : t == MSM_TECH_SCATTER_MSM6_96  ? MSM_REP6_UNORM16
         : t == MSM_TECH_SCATTER_MSM6_192 ? MSM_REP6_FLOAT
                                          : -1;
}
// Bytes per rectified texel of a prefiltered technique's two maps (src/render/passes/
// prefiltered_scattering_passes.cpp): x the float rectified map (RGBA32F; six moments two; CSM
// eight RGBA16F layers), y the stored prefix sums (Θ4* RGBA16; Θ6* 2 x RGB10A2, RGBA16 + RG16,
// RGBA32F + RG32F; CSM eight RGBA8). The prefix sums read x and write y per texel. Per light: every
// light of the frame has its own two maps (the renderer's memory estimate counts them per light).
MSM_FN ivec2 msm_technique_scatter_map_bytes(int t) {
  return t == MSM_TECH_SCATTER_MSM6_64    ? ivec2(32, 8)
         : t == MSM_TECH_SCATTER_MSM6_96  ? ivec2(32, 12)
         : t == MSM_TECH_SCATTER_MSM6_192 ? ivec2(32, 24)
         : t == MSM_TECH_SCATTER_CSM32    ? ivec2(64, 32)
                                          : ivec2(16, 8);
}
MSM_FN bool msm_technique_is_scattering(int t) {
  return t == MSM_TECH_SCATTER_MARCH32 || t == MSM_TECH_SCATTER_MARCH128 || msm_technique_is_prefiltered_scattering(t);
}
// Samples per view ray of the ray-marching techniques (0 for the others).
MSM_FN int msm_technique_march_samples(int t) {
  return t == MSM_TECH_SCATTER_MARCH32 ? 32 : (t == MSM_TECH_SCATTER_MARCH128 ? 128 : 0);
}

// True for the techniques that read the depth map instead of filterable channels (the scattering
// ones shade their surfaces with PCF).
MSM_FN bool msm_technique_is_depth_based(int t) {
  return t == MSM_TECH_PLAIN || t == MSM_TECH_PCF || t == MSM_TECH_PCSS || msm_technique_is_scattering(t);
}

// The non-linear techniques store Φ of the filtered moments: they filter before storage (the
// one-pass filter) and decode before any interpolation.
MSM_FN bool msm_technique_is_nonlinear(int t) { return t == MSM_TECH_NL64 || t == MSM_TECH_NL32; }

MSM_FN bool msm_technique_is_signed(int t) {
  return msm_technique_is_nonlinear(t) || t == MSM_TECH_EVSM2_32 || t == MSM_TECH_EVSM2_64 || t == MSM_TECH_EVSM4_64 ||
         t == MSM_TECH_EVSM4_128 || t == MSM_TECH_HAMBURGER_128 || t == MSM_TECH_HAMBURGER_64 ||
         t == MSM_TECH_HAUSDORFF_128 || t == MSM_TECH_HAUSDORFF_64 || t == MSM_TECH_MSM6_192 || t == MSM_TECH_MSM6_96 ||
         t == MSM_TECH_MSSM4 || t == MSM_TECH_MSSM6;
}

// The papers' parameters (config.h, baselines.h); see the vec4 layout above.
MSM_FN vec4 msm_technique_default_params(int t) {
  if (t == MSM_TECH_VSM32) return vec4(0.0f, 0.0f, 0.0f, MSM_VSM_MIN_VARIANCE_UNORM16);
  if (t == MSM_TECH_VSM64) return vec4(0.0f, 0.0f, 0.0f, MSM_VSM_MIN_VARIANCE_FLOAT);
  if (t == MSM_TECH_ESM32) return vec4(0.0f, MSM_ESM_C_DEFAULT, 0.0f, 0.0f);
  if (t == MSM_TECH_EVSM2_32 || t == MSM_TECH_EVSM4_64)
    return vec4(0.0f, MSM_EVSM_C_64BIT, MSM_EVSM_C_64BIT, MSM_EVSM_MIN_VARIANCE_HALF);
  if (t == MSM_TECH_EVSM2_64 || t == MSM_TECH_EVSM4_128)
    return vec4(0.0f, MSM_EVSM_C_POS_128BIT, MSM_EVSM_C_NEG_128BIT, MSM_EVSM_MIN_VARIANCE_FLOAT);
  if (t == MSM_TECH_HAMBURGER_128_UNIT || t == MSM_TECH_HAUSDORFF_128_UNIT)
    return vec4(MSM_ALPHA_UNIT_FLOAT, 0.0f, 0.0f, 0.0f);
  if (t == MSM_TECH_HAMBURGER_128 || t == MSM_TECH_HAUSDORFF_128) return vec4(MSM_ALPHA_SIGNED_FLOAT, 0.0f, 0.0f, 0.0f);
  if (t == MSM_TECH_HAMBURGER_64_THETA4 || t == MSM_TECH_HAUSDORFF_64_THETA4)
    return vec4(MSM_ALPHA_UNIT_16BIT, 0.0f, 0.0f, 0.0f);
  if (t == MSM_TECH_HAMBURGER_64 || t == MSM_TECH_HAUSDORFF_64) return vec4(MSM_ALPHA_SIGNED_16BIT, 0.0f, 0.0f, 0.0f);
  if (t == MSM_TECH_TMSM_128) return vec4(MSM_TRIG_ALPHA_DEFAULT, 0.0f, 0.0f, 0.0f);
  if (t == MSM_TECH_MSM6_192) return vec4(MSM_ALPHA6_FLOAT, 0.0f, 0.0f, 0.0f);
  if (t == MSM_TECH_MSM6_96) return vec4(MSM_ALPHA6_16BIT, 0.0f, 0.0f, 0.0f);
  // Moment soft shadows: x = δ1 (ε of Eq. 4), y = δ2, z = 1 for Kneiphof's upper-bound blocker
  // depth (Eq. 19, the mass at zf clamped to [δ1, δ2]), 0 for JCGT Eq. (4).
  if (t == MSM_TECH_MSSM4) return vec4(MSM_BLOCKER_EPSILON, MSM_BLOCKER_EPSILON, 0.0f, 0.0f);
  if (t == MSM_TECH_MSSM6) return vec4(MSM_BLOCKER_EPSILON, MSM_SOFT6_DELTA2, 1.0f, 0.0f);
  if (t == MSM_TECH_VSSM) return vec4(0.0f, 0.0f, 0.0f, MSM_VSSM_MIN_VARIANCE);
  // CSSM: x damping, y scale, z offset of CSM (baselines.h), w the blockers' least share (cssm.h).
  if (msm_technique_is_cssm(t))
    return vec4(MSM_CSM_DAMPING_DEFAULT, MSM_CSM_SCALE_DEFAULT, MSM_CSM_OFFSET_DEFAULT, MSM_CSSM_MIN_BLOCKER_SHARE);
  return vec4(0.0f);
}

// Filterable channels of one depth sample, already in the storage basis (θ2, θ4, Θ4*, Θ6*), so
// that the UNORM16 formats hold them; every transform is affine and commutes with filtering.
MSM_FN MsmTexel msm_technique_generate(int t, float unit_depth, vec4 params) {
  float z = msm_signed_depth(unit_depth);
  vec4 zero = vec4(0.0f);
  if (t == MSM_TECH_VSM32) return MsmTexel(vec4(msm_vsm_moments_theta2(unit_depth), 0.0f, 0.0f), zero);
  if (t == MSM_TECH_VSM64 || t == MSM_TECH_VSSM) return MsmTexel(vec4(msm_vsm_moments(unit_depth), 0.0f, 0.0f), zero);
  if (t == MSM_TECH_ESM32) return MsmTexel(vec4(msm_esm_moment(unit_depth, params.y), 0.0f, 0.0f, 0.0f), zero);
  if (t == MSM_TECH_EVSM2_32 || t == MSM_TECH_EVSM2_64)
    return MsmTexel(vec4(msm_evsm2_moments(z, params.y), 0.0f, 0.0f), zero);
  if (t == MSM_TECH_EVSM4_64 || t == MSM_TECH_EVSM4_128)
    return MsmTexel(msm_evsm4_moments(z, params.y, params.z), zero);
  if (t == MSM_TECH_HAMBURGER_128_UNIT || t == MSM_TECH_HAUSDORFF_128_UNIT)
    return MsmTexel(msm_moments4(unit_depth), zero);
  if (t == MSM_TECH_HAMBURGER_128 || t == MSM_TECH_HAUSDORFF_128 || msm_technique_is_nonlinear(t))
    return MsmTexel(msm_moments4(z), zero);
  if (t == MSM_TECH_HAMBURGER_64_THETA4 || t == MSM_TECH_HAUSDORFF_64_THETA4)
    return MsmTexel(msm_theta4(msm_moments4(unit_depth)), zero);
  if (t == MSM_TECH_HAMBURGER_64 || t == MSM_TECH_HAUSDORFF_64 || t == MSM_TECH_MSSM4)
    return MsmTexel(msm_theta4_star(msm_moments4(z)), zero);
  if (t == MSM_TECH_TMSM_128) return MsmTexel(msm_trig_moments(unit_depth), zero);
  if (t == MSM_TECH_MSM6_192 || t == MSM_TECH_MSM6_96 || t == MSM_TECH_MSSM6) {
    Moments6 m = msm_moments6(z);
    if (t != MSM_TECH_MSM6_192) m = msm_theta6_star(m);
    return MsmTexel(vec4(m.odd, m.even.x), vec4(m.even.y, m.even.z, 0.0f, 0.0f));
  }
  return MsmTexel(vec4(unit_depth, 0.0f, 0.0f, 0.0f), zero); // depth-based: the depth itself
}

// Non-linear storage of filtered (unbiased, float) moments, and its decoding. The 64-bit texel is
// the four UNORM16 values of msm_nl_pack64 as floats (k / 65535: an RGBA16_UNORM write stores
// exactly k).
MSM_FN vec4 msm_nl64_encode(vec4 filtered) {
  uvec2 p = msm_nl_pack64(msm_nl_from_filtered(filtered));
  return vec4(unpackUnorm2x16(p.x), unpackUnorm2x16(p.y));
}
MSM_FN NonLinearMoments msm_nl64_decode(vec4 texel) {
  return msm_nl_unpack64(uvec2(packUnorm2x16(vec2(texel.x, texel.y)), packUnorm2x16(vec2(texel.z, texel.w))));
}
MSM_FN uint msm_nl32_encode(vec4 filtered) { return msm_nl_pack32(msm_nl_from_filtered(filtered)); }

MSM_FN float msm_technique_shadow_4moments(int t, vec4 stored, float unit_zf, float alpha) {
  float zf = msm_signed_depth(unit_zf);
  if (t == MSM_TECH_HAMBURGER_128_UNIT)
    return msm_hamburger4_lower(msm_apply_bias(stored, alpha, MSM_BSTAR_UNIT), unit_zf);
  if (t == MSM_TECH_HAMBURGER_128)
    return msm_hamburger4_lower(msm_apply_bias(stored, alpha, MSM_BSTAR_SIGNED_FLOAT), zf);
  // 2015 θ4 16-bit: D2 raised to the representation's floor (config.h, MSM_MIN_D2_UNIT_16BIT).
  if (t == MSM_TECH_HAMBURGER_64_THETA4)
    return msm_hamburger4_lower(
        msm_raise_d2(msm_apply_bias(msm_theta4_inverse(stored), alpha, MSM_BSTAR_UNIT), MSM_MIN_D2_UNIT_16BIT),
        unit_zf);
  if (t == MSM_TECH_HAMBURGER_64)
    return msm_hamburger4_lower(msm_apply_bias(msm_theta4_star_inverse(stored), alpha, MSM_BSTAR_SIGNED_16BIT), zf);
  if (t == MSM_TECH_HAUSDORFF_128_UNIT)
    return msm_hausdorff4_lower(msm_apply_bias(stored, alpha, MSM_BSTAR_UNIT), unit_zf, 0.0f, 1.0f);
  if (t == MSM_TECH_HAUSDORFF_128)
    return msm_hausdorff4_lower(msm_apply_bias(stored, alpha, MSM_BSTAR_SIGNED_FLOAT), zf, -1.0f, 1.0f);
  if (t == MSM_TECH_HAUSDORFF_64_THETA4)
    return msm_hausdorff4_lower(
        msm_raise_d2(msm_apply_bias(msm_theta4_inverse(stored), alpha, MSM_BSTAR_UNIT), MSM_MIN_D2_UNIT_16BIT), unit_zf,
        0.0f, 1.0f);
  // MSM_TECH_HAUSDORFF_64
  return msm_hausdorff4_lower(msm_apply_bias(msm_theta4_star_inverse(stored), alpha, MSM_BSTAR_SIGNED_16BIT), zf, -1.0f,
                              1.0f);
}

// Shadow intensity in [0,1] (1 = fully shadowed) at fragment depth unit_zf from the filtered
// channels as the texture returns them. Not for the depth-based techniques (returns 0).
MSM_FN float msm_technique_shadow(int t, MsmTexel stored, float unit_zf, vec4 params) {
  float zf = msm_signed_depth(unit_zf);
  vec2 a2 = vec2(stored.a.x, stored.a.y);
  if (t == MSM_TECH_VSM32) return msm_vsm_shadow_theta2(a2, unit_zf, params.w);
  if (t == MSM_TECH_VSM64) return msm_vsm_shadow(a2, unit_zf, params.w);
  if (t == MSM_TECH_ESM32) return msm_esm_shadow(stored.a.x, unit_zf, params.y);
  if (t == MSM_TECH_EVSM2_32 || t == MSM_TECH_EVSM2_64) return msm_evsm2_shadow(a2, zf, params.y, params.w);
  if (t == MSM_TECH_EVSM4_64 || t == MSM_TECH_EVSM4_128)
    return msm_evsm4_shadow(stored.a, zf, params.y, params.z, params.w);
  if (t >= MSM_TECH_HAMBURGER_128_UNIT && t <= MSM_TECH_HAUSDORFF_64)
    return msm_technique_shadow_4moments(t, stored.a, unit_zf, params.x);
  if (t == MSM_TECH_TMSM_128) return msm_trig_lower(msm_trig_bias(stored.a, params.x), unit_zf);
  if (t == MSM_TECH_MSM6_192 || t == MSM_TECH_MSM6_96) {
    Moments6 m = Moments6(vec3(stored.a.x, stored.a.y, stored.a.z), vec3(stored.a.w, stored.b.x, stored.b.y));
    if (t == MSM_TECH_MSM6_96) m = msm_theta6_star_inverse(m);
    MomentBias6 bias = msm_moment_bias6(t == MSM_TECH_MSM6_96 ? MSM_REP6_UNORM16 : MSM_REP6_FLOAT);
    bias.alpha = params.x;
    return msm_hamburger6_lower(msm_apply_bias6(m, bias), zf);
  }
  return 0.0f;
}

MSM_END
#endif // MSM_TECHNIQUES_H
