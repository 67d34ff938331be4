#include "msm/cpu/techniques.h"

#include "msm/msm.h"
#include "msm/techniques.h"
#include "msm/util/spelling.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <limits>
#include <stdexcept>
#include <string>
#include <vector>

namespace msm {
namespace {

using cpu::Texel;

constexpr std::string_view kMoment = "x: moment bias alpha";
constexpr std::string_view kVsm = "w: minimum variance";
constexpr std::string_view kEsm = "y: exponent c";
constexpr std::string_view kEvsm = "y: c+, z: c- (EVSM4), w: minimum variance in depth units";
constexpr std::string_view kSoftMoments =
    "x: δ1 (ε of JCGT Eq. 4), y: δ2, z: 1 = Kneiphof's upper-bound blocker depth (Eq. 19) with the mass at zf "
    "clamped to [δ1, δ2], 0 = JCGT Eq. 4";
constexpr std::string_view kCssmParams = "x: CSM damping, y: CSM scale, z: CSM offset, w: least blocker share";

Texel from(vec4 v) { return {v.x, v.y, v.z, v.w, 0, 0, 0, 0}; }
vec4 to_vec4(const Texel& t) { return vec4(t[0], t[1], t[2], t[3]); }
Texel identity(const Texel& t) { return t; }
Texel unorm16(const Texel& t) { return from(msm_quantize_unorm16(to_vec4(t))); }

// ---- Techniques of the shared table (include/msm/techniques.h), with the papers' parameters ----
Texel from(MsmTexel t) { return {t.a.x, t.a.y, t.a.z, t.a.w, t.b.x, t.b.y, t.b.z, t.b.w}; }
MsmTexel to_texel(const Texel& t) { return MsmTexel(vec4(t[0], t[1], t[2], t[3]), vec4(t[4], t[5], t[6], t[7])); }
template <int Id>
Texel generate(float d) {
  return from(msm_technique_generate(Id, d, msm_technique_default_params(Id)));
}
template <int Id>
float shade(const Texel& t, float zf) {
  return msm_technique_shadow(Id, to_texel(t), zf, msm_technique_default_params(Id));
}
Texel moments_signed(float d) { return from(msm_moments4(msm_signed_depth(d))); }

// ---- Storage round trips of the texel formats ----
Texel unorm16x2(const Texel& t) {
  vec2 q = msm_quantize_unorm16x2(vec2(t[0], t[1]));
  return {q.x, q.y, 0, 0, 0, 0, 0, 0};
}
Texel half2(const Texel& t) {
  vec2 q = msm_quantize_half2(vec2(t[0], t[1]));
  return {q.x, q.y, 0, 0, 0, 0, 0, 0};
}
Texel half4(const Texel& t) { return from(msm_quantize_half4(to_vec4(t))); }

// ---- Non-linearly quantized MSM (HPG 2017): filtered float moments -> Φ -> 64/32 bits ----
Texel from(NonLinearMoments m) { return {m.y1, m.y2, m.v2, m.xi4, 0, 0, 0, 0}; }
NonLinearMoments to_nl(const Texel& t) { return NonLinearMoments(t[0], t[1], t[2], t[3]); }
Texel nl64_store(const Texel& t) { return from(msm_nl_quantize64(msm_nl_from_filtered(to_vec4(t)))); }
Texel nl32_store(const Texel& t) { return from(msm_nl_quantize32(msm_nl_from_filtered(to_vec4(t)))); }
float nl_shade(const Texel& t, float zf) { return msm_nl_shadow(to_nl(t), msm_signed_depth(zf)); }

// Convolution shadow map with 4 Fourier terms (8 float channels), damped and scaled to a lower bound;
// the basis on MSM_CSM_BASIS_RANGE of the depth range, as CSSM's (baselines.h: on the whole range a
// receiver at depth 1 behind an occluder at depth 0 got no shadow).
Texel csm4(float d) {
  const float u = msm_csm_basis_depth(d);
  vec4 a = msm_csm_basis_texel(u, 0), b = msm_csm_basis_texel(u, 1);
  return {a.x, a.y, a.z, a.w, b.x, b.y, b.z, b.w};
}
float csm4_shade(const Texel& t, float zf) {
  CsmParams p = msm_csm_default_params();
  p.terms = 4;
  float xf = msm_csm_ranged_receiver(zf, p);
  float sum = msm_csm_texel_terms(vec4(t[0], t[1], t[2], t[3]), xf, 0, p) +
              msm_csm_texel_terms(vec4(t[4], t[5], t[6], t[7]), xf, 1, p);
  return msm_csm_resolve(sum, p);
}

// ---- Six moments in 10-bit UNORM (JCGT §5.4.3): CPU only (the renderer has no 6 x 10-bit format) ----
Moments6 to_m6(const Texel& t) { return Moments6(vec3(t[0], t[1], t[2]), vec3(t[3], t[4], t[5])); }
Texel from(Moments6 m) { return {m.odd.x, m.odd.y, m.odd.z, m.even.x, m.even.y, m.even.z, 0, 0}; }
Texel m6_unorm16(const Texel& t) { return from(msm_quantize_unorm16(to_m6(t))); }
Texel m6_unorm10(const Texel& t) { return from(msm_quantize_unorm10(to_m6(t))); }
float m6_10_shade(const Texel& t, float zf) {
  Moments6 b = msm_theta6_star_inverse(to_m6(t));
  return msm_hamburger6_lower(msm_apply_bias6(b, msm_moment_bias6(MSM_REP6_UNORM10)), msm_signed_depth(zf));
}

// ---- Parameters (the shader reads each from the slot of the technique's parameter vec4) ----
constexpr float kUnbounded = std::numeric_limits<float>::infinity();

constexpr Parameter moment_bias(float default_value) {
  return {.name = "moment_bias",
          .slot = 0,
          .default_value = default_value,
          .min = 0.0f,
          .max = 1.0f,
          .meaning = "α of the moment bias b' = (1 - α) b + α b* (JCGT §2.5): more hides storage rounding, less keeps "
                     "shadows dark"};
}
constexpr Parameter min_variance(float default_value, std::string_view meaning) {
  return {.name = "min_variance",
          .slot = 3,
          .default_value = default_value,
          .min = 0.0f,
          .max = 1.0f,
          .min_open = true,
          .meaning = meaning};
}
constexpr std::string_view kVarianceMeaning =
    "least variance of the filtered depths in Chebyshev's bound, against the shadow acne of rounding";
constexpr std::string_view kWarpedVarianceMeaning =
    "least variance of each warped depth in Chebyshev's bound, in [-1,1] depth units";
constexpr Parameter esm_exponent(float default_value) {
  return {.name = "exponent",
          .slot = 1,
          .default_value = default_value,
          .min = 0.0f,
          .max = kUnbounded,
          .min_open = true,
          .meaning = "c of exp(c z): sharper shadows the larger, up to what the storage format holds"};
}
constexpr Parameter evsm_positive(float default_value) {
  return {.name = "positive_exponent",
          .slot = 1,
          .default_value = default_value,
          .min = 0.0f,
          .max = kUnbounded,
          .min_open = true,
          .meaning = "c+ of the positive warp exp(c+ z), up to what the storage format holds"};
}
constexpr Parameter evsm_negative(float default_value) {
  return {.name = "negative_exponent",
          .slot = 2,
          .default_value = default_value,
          .min = 0.0f,
          .max = kUnbounded,
          .min_open = true,
          .meaning = "c- of the negative warp -exp(-c- z), up to what the storage format holds"};
}

// Moment soft shadows: the blocker depth's estimate.
constexpr ParameterChoice kBlockerEstimates[] = {
    {"jcgt", 0.0f, "JCGT Eq. 4: the fragment depth weighted by δ1"},
    {"upper-bound", 1.0f, "Kneiphof's upper-bound blocker depth (Eq. 19), the mass at zf clamped to [δ1, δ2]"},
};
std::array<Parameter, 4> soft_moment_parameters(float delta2, float estimate) {
  return {Parameter{.name = "delta1",
                    .slot = 0,
                    .default_value = MSM_BLOCKER_EPSILON,
                    .min = 0.0f,
                    .max = 1.0f,
                    .min_open = true,
                    .meaning = "δ1, the least mass at the fragment's depth in the blocker search (ε of JCGT Eq. 4)"},
          Parameter{.name = "delta2",
                    .slot = 1,
                    .default_value = delta2,
                    .min = 0.0f,
                    .max = 1.0f,
                    .min_open = true,
                    .meaning = "δ2 >= δ1, the most mass at the fragment's depth the upper-bound estimate counts"},
          Parameter{.name = "blocker_estimate",
                    .type = ParameterType::choice,
                    .slot = 2,
                    .default_value = estimate,
                    .choices = kBlockerEstimates,
                    .meaning = "how the average blocker depth is estimated from the search region's moments"}};
}

const std::array<Parameter, 4> kCssmParameters = {
    Parameter{.name = "damping",
              .slot = 0,
              .default_value = MSM_CSM_DAMPING_DEFAULT,
              .min = 0.0f,
              .max = kUnbounded,
              .meaning = "damping of the higher Fourier terms (CSM), against ringing"},
    Parameter{.name = "scale",
              .slot = 1,
              .default_value = MSM_CSM_SCALE_DEFAULT,
              .min = 1.0f,
              .max = kUnbounded,
              .meaning = "scale of the reconstructed step (CSM), darkening the shadow towards a lower bound"},
    Parameter{.name = "offset",
              .slot = 2,
              .default_value = MSM_CSM_OFFSET_DEFAULT,
              .min = 0.0f,
              .max = 1.0f,
              .max_open = true,
              .meaning = "offset of the reconstructed step (CSM)"},
    Parameter{.name = "min_blocker_share",
              .slot = 3,
              .default_value = MSM_CSSM_MIN_BLOCKER_SHARE,
              .min = 0.0f,
              .max = 1.0f,
              .max_open = true,
              .meaning = "below this share of blockers a search region holds none and the fragment is lit"}};

// Prefiltered single scattering.
constexpr ParameterChoice kResamplings[] = {
    {"none", 0.0f, "the depth map resampled into the rectified map without filtering"},
    {"filtered", 1.0f,
     "JCGT §5.2: a trilinear sample of the blurred, mipmapped 4-moment map at the texel's footprint (Algorithm 2)"},
    {"bilinear-moments", 2.0f, "from the unblurred depth map's bilinear moments"},
};
constexpr ParameterChoice kBetas[] = {
    {"proportional", float(MSM_SCATTERING_BETA_PROPORTIONAL),
     "the undecided weight shared as the bounds share the rest, falling to 0 towards the epipole"},
    {"fixed", float(MSM_SCATTERING_BETA_FIXED), "the fixed_beta parameter (§5.3.1)"},
    {"adaptive", float(MSM_SCATTERING_BETA_ADAPTIVE), "the adaptive β of §5.3.1"},
};
constexpr Parameter kResampling = {.name = "resampling",
                                   .type = ParameterType::choice,
                                   .slot = 0,
                                   .choices = kResamplings,
                                   .meaning = "how the depth map is resampled into the rectified map (JCGT §5.2)"};
constexpr Parameter kLayers = {.name = "layers",
                               .type = ParameterType::integer,
                               .slot = 3,
                               .min = 0.0f,
                               .max = float(MSM_RECT_MAX_LAYERS),
                               .meaning = "transmittance layers K (1: the paper's single Δ per row; 0: the default)"};
constexpr std::array<Parameter, 4> kScatterMomentParameters = {
    kResampling,
    Parameter{.name = "fixed_beta",
              .slot = 1,
              .min = 0.0f,
              .max = 1.0f,
              .meaning = "β of beta = fixed: the weight of the upper bound between the shadow's sharp bounds"},
    Parameter{.name = "beta",
              .type = ParameterType::choice,
              .slot = 2,
              .default_value = float(MSM_SCATTERING_BETA_PROPORTIONAL),
              .choices = kBetas,
              .meaning = "how the shadow's sharp lower and upper bounds are blended (JCGT §5.3.1)"},
    kLayers};
constexpr std::array<Parameter, 4> kScatterCsmParameters = {kResampling, kLayers};

// ---- The table: what every part of msm knows of a technique ----
const Technique kTechniques[] = {
    {.name = "plain",
     .description = "Shadow map, one depth comparison per fragment (receiver plane at the texel centre)",
     .id = MSM_TECH_PLAIN,
     .bits_per_texel = 16,
     .recipe = Recipe::depth_map,
     .shading = ShadingVariant::depth,
     .depth_bias = MSM_DEPTH_BIAS_DEPTH_MAP},
    {.name = "pcf",
     .description = "PCF with the Gaussian kernel of the blur (taps x taps, sigma), bilinear, every MSAA sample: the "
                    "reference for filtered hard shadows (2015)",
     .id = MSM_TECH_PCF,
     .bits_per_texel = 16,
     .recipe = Recipe::depth_map,
     .shading = ShadingVariant::depth,
     .deferred_shading_default = true,
     .depth_bias = MSM_DEPTH_BIAS_DEPTH_MAP},
    {.name = "vsm-32",
     .description = "VSM, 2 x 16-bit UNORM after θ2, depth in [0,1] (2015)",
     .id = MSM_TECH_VSM32,
     .bits_per_texel = 32,
     .channels = 2,
     .formats = {TexelFormat::rg16_unorm, TexelFormat::none},
     .recipe = Recipe::filtered_moments,
     .shading = ShadingVariant::moments,
     .translucency = true,
     .depth_bias = MSM_DEPTH_BIAS_FILTERED,
     .parameters = {min_variance(MSM_VSM_MIN_VARIANCE_UNORM16, kVarianceMeaning)},
     .generate = generate<MSM_TECH_VSM32>,
     .store_load = unorm16x2,
     .shade = shade<MSM_TECH_VSM32>},
    {.name = "vsm-64",
     .description = "VSM, 2 x float",
     .id = MSM_TECH_VSM64,
     .bits_per_texel = 64,
     .channels = 2,
     .formats = {TexelFormat::rg32_float, TexelFormat::none},
     .recipe = Recipe::filtered_moments,
     .shading = ShadingVariant::moments,
     .translucency = true,
     .depth_bias = MSM_DEPTH_BIAS_FILTERED,
     .parameters = {min_variance(MSM_VSM_MIN_VARIANCE_FLOAT, kVarianceMeaning)},
     .generate = generate<MSM_TECH_VSM64>,
     .store_load = identity,
     .shade = shade<MSM_TECH_VSM64>},
    {.name = "esm-32",
     .description = "ESM, 1 x float, c = 80 on [0,1]",
     .id = MSM_TECH_ESM32,
     .bits_per_texel = 32,
     .channels = 1,
     .formats = {TexelFormat::r32_float, TexelFormat::none},
     .recipe = Recipe::filtered_moments,
     .shading = ShadingVariant::moments,
     .translucency = true,
     .depth_bias = MSM_DEPTH_BIAS_FILTERED,
     .parameters = {esm_exponent(MSM_ESM_C_DEFAULT)},
     .generate = generate<MSM_TECH_ESM32>,
     .store_load = identity,
     .shade = shade<MSM_TECH_ESM32>},
    {.name = "evsm2-32",
     .description = "EVSM, positive warp, 2 x half, c = 5.54 on [-1,1]",
     .id = MSM_TECH_EVSM2_32,
     .bits_per_texel = 32,
     .channels = 2,
     .formats = {TexelFormat::rg16_float, TexelFormat::none},
     .recipe = Recipe::filtered_moments,
     .shading = ShadingVariant::moments,
     .translucency = true,
     .depth_bias = MSM_DEPTH_BIAS_FILTERED,
     .parameters = {evsm_positive(MSM_EVSM_C_64BIT), min_variance(MSM_EVSM_MIN_VARIANCE_HALF, kWarpedVarianceMeaning)},
     .generate = generate<MSM_TECH_EVSM2_32>,
     .store_load = half2,
     .shade = shade<MSM_TECH_EVSM2_32>},
    {.name = "evsm2-64",
     .description = "EVSM, positive warp, 2 x float, c+ = 40 on [-1,1]",
     .id = MSM_TECH_EVSM2_64,
     .bits_per_texel = 64,
     .channels = 2,
     .formats = {TexelFormat::rg32_float, TexelFormat::none},
     .recipe = Recipe::filtered_moments,
     .shading = ShadingVariant::moments,
     .translucency = true,
     .depth_bias = MSM_DEPTH_BIAS_FILTERED,
     .parameters = {evsm_positive(MSM_EVSM_C_POS_128BIT),
                    min_variance(MSM_EVSM_MIN_VARIANCE_FLOAT, kWarpedVarianceMeaning)},
     .generate = generate<MSM_TECH_EVSM2_64>,
     .store_load = identity,
     .shade = shade<MSM_TECH_EVSM2_64>},
    {.name = "evsm4-64",
     .description = "EVSM, both warps, 4 x half, c = 5.54 (JCGT Fig. 4a)",
     .id = MSM_TECH_EVSM4_64,
     .bits_per_texel = 64,
     .channels = 4,
     .formats = {TexelFormat::rgba16_float, TexelFormat::none},
     .recipe = Recipe::filtered_moments,
     .shading = ShadingVariant::moments,
     .translucency = true,
     .depth_bias = MSM_DEPTH_BIAS_FILTERED,
     .parameters = {evsm_positive(MSM_EVSM_C_64BIT), evsm_negative(MSM_EVSM_C_64BIT),
                    min_variance(MSM_EVSM_MIN_VARIANCE_HALF, kWarpedVarianceMeaning)},
     .generate = generate<MSM_TECH_EVSM4_64>,
     .store_load = half4,
     .shade = shade<MSM_TECH_EVSM4_64>},
    {.name = "evsm4-128",
     .description = "EVSM, both warps, 4 x float, c+ = 40, c- = 5.54 (JCGT Fig. 4e)",
     .id = MSM_TECH_EVSM4_128,
     .bits_per_texel = 128,
     .channels = 4,
     .formats = {TexelFormat::rgba32_float, TexelFormat::none},
     .recipe = Recipe::filtered_moments,
     .shading = ShadingVariant::moments,
     .translucency = true,
     .depth_bias = MSM_DEPTH_BIAS_FILTERED,
     .parameters = {evsm_positive(MSM_EVSM_C_POS_128BIT), evsm_negative(MSM_EVSM_C_NEG_128BIT),
                    min_variance(MSM_EVSM_MIN_VARIANCE_FLOAT, kWarpedVarianceMeaning)},
     .generate = generate<MSM_TECH_EVSM4_128>,
     .store_load = identity,
     .shade = shade<MSM_TECH_EVSM4_128>},
    {.name = "csm-4",
     .description = "Convolution shadow map, 4 Fourier terms in 8 floats, damped",
     .bits_per_texel = 256,
     .channels = 8,
     .generate = csm4,
     .store_load = identity,
     .shade = csm4_shade},
    {.name = "msm-hamburger-128-unit",
     .description = "Hamburger 4MSM, 4 x float, depth in [0,1] (2015)",
     .id = MSM_TECH_HAMBURGER_128_UNIT,
     .bits_per_texel = 128,
     .channels = 4,
     .formats = {TexelFormat::rgba32_float, TexelFormat::none},
     .recipe = Recipe::filtered_moments,
     .shading = ShadingVariant::moments,
     .translucency = true,
     .depth_bias = MSM_DEPTH_BIAS_FILTERED,
     .parameters = {moment_bias(MSM_ALPHA_UNIT_FLOAT)},
     .generate = generate<MSM_TECH_HAMBURGER_128_UNIT>,
     .store_load = identity,
     .shade = shade<MSM_TECH_HAMBURGER_128_UNIT>},
    {.name = "msm-hamburger-128",
     .description = "Hamburger 4MSM, 4 x float, depth in [-1,1] (JCGT 2017)",
     .id = MSM_TECH_HAMBURGER_128,
     .bits_per_texel = 128,
     .channels = 4,
     .formats = {TexelFormat::rgba32_float, TexelFormat::none},
     .recipe = Recipe::filtered_moments,
     .shading = ShadingVariant::moments,
     .translucency = true,
     .depth_bias = MSM_DEPTH_BIAS_FILTERED,
     .parameters = {moment_bias(MSM_ALPHA_SIGNED_FLOAT)},
     .generate = generate<MSM_TECH_HAMBURGER_128>,
     .store_load = identity,
     .shade = shade<MSM_TECH_HAMBURGER_128>},
    {.name = "msm-hamburger-64-theta4",
     .description = "Hamburger 4MSM, 4 x 16-bit UNORM after θ4, depth in [0,1] (2015)",
     .id = MSM_TECH_HAMBURGER_64_THETA4,
     .bits_per_texel = 64,
     .channels = 4,
     .formats = {TexelFormat::rgba16_unorm, TexelFormat::none},
     .recipe = Recipe::filtered_moments,
     .shading = ShadingVariant::moments,
     .translucency = true,
     .depth_bias = MSM_DEPTH_BIAS_FILTERED,
     .parameters = {moment_bias(MSM_ALPHA_UNIT_16BIT)},
     .generate = generate<MSM_TECH_HAMBURGER_64_THETA4>,
     .store_load = unorm16,
     .shade = shade<MSM_TECH_HAMBURGER_64_THETA4>},
    {.name = "msm-hamburger-64",
     .description = "Hamburger 4MSM, 4 x 16-bit UNORM after Θ4*, depth in [-1,1] (JCGT 2017)",
     .id = MSM_TECH_HAMBURGER_64,
     .bits_per_texel = 64,
     .channels = 4,
     .formats = {TexelFormat::rgba16_unorm, TexelFormat::none},
     .recipe = Recipe::filtered_moments,
     .shading = ShadingVariant::moments,
     .translucency = true,
     .depth_bias = MSM_DEPTH_BIAS_FILTERED,
     .parameters = {moment_bias(MSM_ALPHA_SIGNED_16BIT)},
     .generate = generate<MSM_TECH_HAMBURGER_64>,
     .store_load = unorm16,
     .shade = shade<MSM_TECH_HAMBURGER_64>},
    {.name = "msm-hausdorff-128-unit",
     .description = "Hausdorff 4MSM on [0,1], 4 x float (2015)",
     .id = MSM_TECH_HAUSDORFF_128_UNIT,
     .bits_per_texel = 128,
     .channels = 4,
     .formats = {TexelFormat::rgba32_float, TexelFormat::none},
     .recipe = Recipe::filtered_moments,
     .shading = ShadingVariant::moments,
     .translucency = true,
     .depth_bias = MSM_DEPTH_BIAS_FILTERED,
     .parameters = {moment_bias(MSM_ALPHA_UNIT_FLOAT)},
     .generate = generate<MSM_TECH_HAUSDORFF_128_UNIT>,
     .store_load = identity,
     .shade = shade<MSM_TECH_HAUSDORFF_128_UNIT>},
    {.name = "msm-hausdorff-128",
     .description = "Hausdorff 4MSM on [-1,1], 4 x float (JCGT 2017 depth)",
     .id = MSM_TECH_HAUSDORFF_128,
     .bits_per_texel = 128,
     .channels = 4,
     .formats = {TexelFormat::rgba32_float, TexelFormat::none},
     .recipe = Recipe::filtered_moments,
     .shading = ShadingVariant::moments,
     .translucency = true,
     .depth_bias = MSM_DEPTH_BIAS_FILTERED,
     .parameters = {moment_bias(MSM_ALPHA_SIGNED_FLOAT)},
     .generate = generate<MSM_TECH_HAUSDORFF_128>,
     .store_load = identity,
     .shade = shade<MSM_TECH_HAUSDORFF_128>},
    {.name = "msm-hausdorff-64-theta4",
     .description = "Hausdorff 4MSM on [0,1], 4 x 16-bit UNORM after θ4 (2015)",
     .id = MSM_TECH_HAUSDORFF_64_THETA4,
     .bits_per_texel = 64,
     .channels = 4,
     .formats = {TexelFormat::rgba16_unorm, TexelFormat::none},
     .recipe = Recipe::filtered_moments,
     .shading = ShadingVariant::moments,
     .translucency = true,
     .depth_bias = MSM_DEPTH_BIAS_FILTERED,
     .parameters = {moment_bias(MSM_ALPHA_UNIT_16BIT)},
     .generate = generate<MSM_TECH_HAUSDORFF_64_THETA4>,
     .store_load = unorm16,
     .shade = shade<MSM_TECH_HAUSDORFF_64_THETA4>},
    {.name = "msm-hausdorff-64",
     .description = "Hausdorff 4MSM on [-1,1], 4 x 16-bit UNORM after Θ4* (JCGT 2017 storage)",
     .id = MSM_TECH_HAUSDORFF_64,
     .bits_per_texel = 64,
     .channels = 4,
     .formats = {TexelFormat::rgba16_unorm, TexelFormat::none},
     .recipe = Recipe::filtered_moments,
     .shading = ShadingVariant::moments,
     .translucency = true,
     .depth_bias = MSM_DEPTH_BIAS_FILTERED,
     .parameters = {moment_bias(MSM_ALPHA_SIGNED_16BIT)},
     .generate = generate<MSM_TECH_HAUSDORFF_64>,
     .store_load = unorm16,
     .shade = shade<MSM_TECH_HAUSDORFF_64>},
    {.name = "tmsm-128",
     .description = "Trigonometric MSM, 4 x float, depth in [0,1] (2015)",
     .id = MSM_TECH_TMSM_128,
     .bits_per_texel = 128,
     .channels = 4,
     .formats = {TexelFormat::rgba32_float, TexelFormat::none},
     .recipe = Recipe::filtered_moments,
     .shading = ShadingVariant::moments,
     .translucency = true,
     .depth_bias = MSM_DEPTH_BIAS_FILTERED,
     .parameters = {moment_bias(MSM_TRIG_ALPHA_DEFAULT)},
     .generate = generate<MSM_TECH_TMSM_128>,
     .store_load = identity,
     .shade = shade<MSM_TECH_TMSM_128>},
    {.name = "msm6-192",
     .description = "Hamburger 6MSM, 6 x float, depth in [-1,1] (JCGT §5.4)",
     .id = MSM_TECH_MSM6_192,
     .bits_per_texel = 192,
     .channels = 6,
     .formats = {TexelFormat::rgba32_float, TexelFormat::rg32_float},
     .recipe = Recipe::filtered_moments,
     .shading = ShadingVariant::moments,
     .six_moments = true,
     .depth_bias = MSM_DEPTH_BIAS_FILTERED,
     .parameters = {moment_bias(MSM_ALPHA6_FLOAT)},
     .generate = generate<MSM_TECH_MSM6_192>,
     .store_load = identity,
     .shade = shade<MSM_TECH_MSM6_192>},
    {.name = "msm6-96",
     .description = "Hamburger 6MSM, 6 x 16-bit UNORM after Θ6* (JCGT §5.4.3)",
     .id = MSM_TECH_MSM6_96,
     .bits_per_texel = 96,
     .channels = 6,
     .formats = {TexelFormat::rgba16_unorm, TexelFormat::rg16_unorm},
     .recipe = Recipe::filtered_moments,
     .shading = ShadingVariant::moments,
     .six_moments = true,
     .depth_bias = MSM_DEPTH_BIAS_FILTERED,
     .parameters = {moment_bias(MSM_ALPHA6_16BIT)},
     .generate = generate<MSM_TECH_MSM6_96>,
     .store_load = m6_unorm16,
     .shade = shade<MSM_TECH_MSM6_96>},
    {.name = "msm6-64",
     .description = "Hamburger 6MSM, 6 x 10-bit UNORM after Θ6* (JCGT §5.4.3)",
     .bits_per_texel = 64,
     .channels = 6,
     .generate = generate<MSM_TECH_MSM6_96>,
     .store_load = m6_unorm10,
     .shade = m6_10_shade},
    {.name = "msm-nl64",
     .description = "Non-linearly quantized 4MSM, 4 x 16-bit (y1, y2, v2, Ψ4(ξ4)) (HPG 2017)",
     .id = MSM_TECH_NL64,
     .bits_per_texel = 64,
     .channels = 4,
     .formats = {TexelFormat::rgba16_unorm, TexelFormat::none},
     .recipe = Recipe::nonlinear_moments,
     .shading = ShadingVariant::nl64,
     .depth_bias = MSM_DEPTH_BIAS_NONLINEAR,
     .generate = moments_signed,
     .store_load = nl64_store,
     .shade = nl_shade},
    {.name = "mssm4",
     .description = "Moment soft shadow mapping (JCGT §4): Θ4* moments in a 32-bit integer summed-area table, "
                    "blocker search, nine-region filter over the penumbra of a directional area light "
                    "(--light-extent-deg)",
     .id = MSM_TECH_MSSM4,
     .bits_per_texel = 128,
     .channels = 4,
     .formats = {TexelFormat::rgba32_float, TexelFormat::none},
     .recipe = Recipe::summed_area_tables,
     .shading = ShadingVariant::soft,
     .area_light = true,
     .deferred_shading_default = true,
     .default_soft_kernel = kSatKernelDefault,
     .max_soft_kernel = MSM_SOFT_MAX_KERNEL_WIDTH4,
     .depth_bias = MSM_DEPTH_BIAS_AREA_LIGHT,
     .parameters = soft_moment_parameters(MSM_BLOCKER_EPSILON, 0.0f)},
    {.name = "msm-nl32",
     .description = "Non-linearly quantized 4MSM, 32-bit packed (HPG 2017)",
     .id = MSM_TECH_NL32,
     .bits_per_texel = 32,
     .channels = 4,
     .formats = {TexelFormat::r32_uint, TexelFormat::none},
     .recipe = Recipe::nonlinear_moments,
     .shading = ShadingVariant::nl32,
     .depth_bias = MSM_DEPTH_BIAS_NONLINEAR,
     .generate = moments_signed,
     .store_load = nl32_store,
     .shade = nl_shade},
    {.name = "mssm6",
     .description = "Moment soft shadows with six moments (Kneiphof §4.2): Θ6* in two 32-bit integer summed-area "
                    "tables, upper-bound blocker depth (Eq. 19, clamp [δ1, δ2]), nine-region filter",
     .id = MSM_TECH_MSSM6,
     .bits_per_texel = 192,
     .channels = 6,
     .formats = {TexelFormat::rgba32_float, TexelFormat::rg32_float},
     .recipe = Recipe::summed_area_tables,
     .shading = ShadingVariant::soft,
     .area_light = true,
     .six_moments = true,
     .deferred_shading_default = true,
     .default_soft_kernel = kSatKernelDefault,
     .max_soft_kernel = MSM_SOFT_MAX_KERNEL_WIDTH6,
     .depth_bias = MSM_DEPTH_BIAS_AREA_LIGHT,
     .parameters = soft_moment_parameters(MSM_SOFT6_DELTA2, 1.0f)},
    {.name = "vssm",
     .description = "Naive variance soft shadow mapping (Yang et al. 2010): the mssm4 pipeline with two moments (z, "
                    "z²), Chebyshev blocker estimate and filter (the baseline of JCGT §4)",
     .id = MSM_TECH_VSSM,
     .bits_per_texel = 64,
     .channels = 2,
     .formats = {TexelFormat::rg32_float, TexelFormat::none},
     .recipe = Recipe::summed_area_tables,
     .shading = ShadingVariant::soft,
     .area_light = true,
     .deferred_shading_default = true,
     .default_soft_kernel = kSatKernelDefault,
     .max_soft_kernel = kSatKernelMax,
     .depth_bias = MSM_DEPTH_BIAS_AREA_LIGHT,
     .parameters = {min_variance(MSM_VSSM_MIN_VARIANCE, kVarianceMeaning)}},
    {.name = "pcss",
     .description = "Percentage-closer soft shadows (Fernando 2005): every texel of a search region up to 15², then "
                    "PCF over the penumbra, every MSAA sample against the receiver plane (the baseline of JCGT §4)",
     .id = MSM_TECH_PCSS,
     .bits_per_texel = 16,
     .recipe = Recipe::depth_map,
     .shading = ShadingVariant::depth,
     .area_light = true,
     .deferred_shading_default = true,
     .default_soft_kernel = kPcssKernelDefault,
     .max_soft_kernel = kPcssKernelMax,
     .depth_bias = MSM_DEPTH_BIAS_AREA_LIGHT},
    {.name = "scatter-march-32",
     .description = "Single scattering in the scene's medium by ray marching (JCGT §5.5.1's baseline): 32 "
                    "equidistant samples of the 16-bit depth map per pixel, one blue-noise jitter per pixel; "
                    "surfaces shaded with PCF",
     .id = MSM_TECH_SCATTER_MARCH32,
     .bits_per_texel = 16,
     .recipe = Recipe::depth_map,
     .shading = ShadingVariant::depth,
     .scattering = Scattering::march,
     .depth_bias = MSM_DEPTH_BIAS_DEPTH_MAP},
    {.name = "scatter-march-128",
     .description = "Single scattering by ray marching as scatter-march-32, with 128 samples per pixel",
     .id = MSM_TECH_SCATTER_MARCH128,
     .bits_per_texel = 16,
     .recipe = Recipe::depth_map,
     .shading = ShadingVariant::depth,
     .scattering = Scattering::march,
     .depth_bias = MSM_DEPTH_BIAS_DEPTH_MAP},
    {.name = "scatter-msm4-64",
     .description = "Prefiltered single scattering with four moments (JCGT §5.3): the depth map resampled without "
                    "filtering into the rectified map (§5.1.1), transmittance-weighted prefix sums along its rows "
                    "stored as Θ4* in 4 x 16 bits, one bilinear lookup per pixel, sharp bounds blended by the "
                    "proportional β (§5.3.1 adapted); surfaces shaded with PCF",
     .id = MSM_TECH_SCATTER_MSM4_64,
     .bits_per_texel = 64,
     .channels = 4,
     .recipe = Recipe::depth_map,
     .shading = ShadingVariant::depth,
     .scattering = Scattering::prefiltered_moments,
     .depth_bias = MSM_DEPTH_BIAS_DEPTH_MAP,
     .parameters = kScatterMomentParameters},
    {.name = "scatter-msm6-64",
     .description = "Prefiltered single scattering with six moments (JCGT §5.4): as scatter-msm4-64, Θ6* prefix "
                    "sums in 6 x 10 bits (two RGB10A2 images, alpha 4e-3), Blinn's cubic and the divided-difference "
                    "weights, proportional β",
     .id = MSM_TECH_SCATTER_MSM6_64,
     .bits_per_texel = 64,
     .channels = 6,
     .recipe = Recipe::depth_map,
     .shading = ShadingVariant::depth,
     .scattering = Scattering::prefiltered_moments,
     .depth_bias = MSM_DEPTH_BIAS_DEPTH_MAP,
     .parameters = kScatterMomentParameters},
    {.name = "scatter-msm6-96",
     .description = "Prefiltered single scattering with six moments (JCGT §5.4): as scatter-msm4-64, Θ6* prefix "
                    "sums in 2 + 4 x 16 bits (alpha 8e-5), Blinn's cubic and the divided-difference weights, "
                    "proportional β",
     .id = MSM_TECH_SCATTER_MSM6_96,
     .bits_per_texel = 96,
     .channels = 6,
     .recipe = Recipe::depth_map,
     .shading = ShadingVariant::depth,
     .scattering = Scattering::prefiltered_moments,
     .depth_bias = MSM_DEPTH_BIAS_DEPTH_MAP,
     .parameters = kScatterMomentParameters},
    {.name = "scatter-msm6-192",
     .description = "Prefiltered single scattering with six moments (JCGT §5.4): as scatter-msm4-64, Θ6* prefix "
                    "sums in 6 x 32-bit float (alpha 5e-6), Blinn's cubic and the divided-difference weights, "
                    "proportional β",
     .id = MSM_TECH_SCATTER_MSM6_192,
     .bits_per_texel = 192,
     .channels = 6,
     .recipe = Recipe::depth_map,
     .shading = ShadingVariant::depth,
     .scattering = Scattering::prefiltered_moments,
     .depth_bias = MSM_DEPTH_BIAS_DEPTH_MAP,
     .parameters = kScatterMomentParameters},
    {.name = "scatter-csm-32",
     .description = "Prefiltered single scattering with a convolution shadow map (Klehm et al. 2014): the passes of "
                    "scatter-msm4-64, 16 sin/cos terms of the rectified depth (32 coefficients) whose prefix sums "
                    "are stored in 8 bits each (eight RGBA8 layers), the plain Fourier reconstruction with damping "
                    "(no bounds, no β); surfaces shaded with PCF",
     .id = MSM_TECH_SCATTER_CSM32,
     .bits_per_texel = 256,
     .channels = 32,
     .recipe = Recipe::depth_map,
     .shading = ShadingVariant::depth,
     .scattering = Scattering::prefiltered_csm,
     .depth_bias = MSM_DEPTH_BIAS_DEPTH_MAP,
     .parameters = kScatterCsmParameters},
    {.name = "cssm8",
     .description = "Convolution soft shadow maps (Annen et al. 2008), Kneiphof's CSSM8: CSM of 4 frequencies, the "
                    "basis times depth and the depth (17 values) in a 32-bit integer summed-area table of stacked "
                    "tiles; blocker depth E[z f] / E[f], nine-region filter",
     .id = MSM_TECH_CSSM8,
     .bits_per_texel = 640,
     .channels = 17,
     .formats = {TexelFormat::rgba32_float, TexelFormat::none},
     .recipe = Recipe::summed_area_tables,
     .shading = ShadingVariant::soft,
     .area_light = true,
     .deferred_shading_default = true,
     .default_soft_kernel = kSatKernelDefault,
     .max_soft_kernel = kSatKernelMax,
     .depth_bias = MSM_DEPTH_BIAS_AREA_LIGHT,
     .parameters = kCssmParameters},
    {.name = "cssm16",
     .description = "Convolution soft shadow maps (Annen et al. 2008), Kneiphof's CSSM16: CSM of 8 frequencies (33 "
                    "values in 9 tiles of one summed-area table)",
     .id = MSM_TECH_CSSM16,
     .bits_per_texel = 1152,
     .channels = 33,
     .formats = {TexelFormat::rgba32_float, TexelFormat::none},
     .recipe = Recipe::summed_area_tables,
     .shading = ShadingVariant::soft,
     .area_light = true,
     .deferred_shading_default = true,
     .default_soft_kernel = kSatKernelDefault,
     .max_soft_kernel = kSatKernelMax,
     .depth_bias = MSM_DEPTH_BIAS_AREA_LIGHT,
     .parameters = kCssmParameters},
};

// One short name per family, for its recommended storage: the JCGT 2017 64-bit MSM, the 2015
// comparison's 32-bit VSM and ESM, EVSM4 at 64 bits (JCGT Fig. 4a), the HPG 2017 64-bit map, 6MSM
// in 96 bits (JCGT §5.4.3), moment soft shadows with four moments.
constexpr TechniqueAlias kAliases[] = {
    {"msm", "msm-hamburger-64"}, {"vsm", "vsm-32"},   {"esm", "esm-32"}, {"evsm", "evsm4-64"},
    {"msm-nl", "msm-nl64"},      {"msm6", "msm6-96"}, {"mssm", "mssm4"},
};

} // namespace

std::span<const Technique> techniques() { return kTechniques; }

std::span<const TechniqueAlias> technique_aliases() { return kAliases; }

std::string_view canonical_technique_name(std::string_view name) {
  for (const TechniqueAlias& a : kAliases)
    if (a.alias == name) return a.technique;
  return name;
}

std::string technique_alias_list(std::string_view technique) {
  std::string out;
  for (const TechniqueAlias& a : kAliases)
    if (a.technique == technique) out += (out.empty() ? "" : ", ") + std::string(a.alias);
  return out;
}

std::string technique_suggestion(std::string_view unknown, std::span<const std::string_view> names) {
  std::vector<std::string> candidates(names.begin(), names.end());
  for (const TechniqueAlias& a : kAliases)
    for (std::string_view n : names)
      if (a.technique == n) candidates.emplace_back(a.alias);
  return util::did_you_mean(unknown, candidates);
}

glm::vec4 Technique::default_params() const { return id >= 0 ? msm_technique_default_params(id) : glm::vec4(0.0f); }

std::vector<const Parameter*> Technique::parameter_list() const {
  std::vector<const Parameter*> out;
  for (const Parameter& p : parameters)
    if (p.declared()) out.push_back(&p);
  return out;
}

bool Technique::has_parameter(std::string_view wanted) const {
  return std::any_of(parameters.begin(), parameters.end(),
                     [&](const Parameter& p) { return p.declared() && p.name == wanted; });
}

const Parameter& Technique::parameter(std::string_view wanted) const {
  std::vector<std::string> names;
  for (const Parameter* p : parameter_list()) {
    if (p->name == wanted) return *p;
    names.emplace_back(p->name);
  }
  if (names.empty())
    throw std::invalid_argument(std::string(name) + " has no parameters (asked for '" + std::string(wanted) + "')");
  std::string valid;
  for (const std::string& n : names) valid += (valid.empty() ? "" : ", ") + n;
  throw std::invalid_argument("unknown parameter '" + std::string(wanted) + "' of " + std::string(name) +
                              util::did_you_mean(wanted, names) + "; it has: " + valid + " (msm techniques " +
                              std::string(name) + ")");
}

namespace {

std::string number_text(float v) {
  if (std::isinf(v)) return v > 0 ? "inf" : "-inf";
  char buffer[32];
  std::snprintf(buffer, sizeof buffer, "%g", double(v));
  return buffer;
}

bool same_text(std::string_view a, std::string_view b) {
  return a.size() == b.size() && std::equal(a.begin(), a.end(), b.begin(), [](char x, char y) {
           return std::tolower(static_cast<unsigned char>(x)) == std::tolower(static_cast<unsigned char>(y));
         });
}

} // namespace

bool Parameter::accepts(float v) const {
  if (!std::isfinite(v)) return false;
  switch (type) {
  case ParameterType::flag: return v == 0.0f || v == 1.0f;
  case ParameterType::choice:
    return std::any_of(choices.begin(), choices.end(), [v](const ParameterChoice& c) { return c.value == v; });
  case ParameterType::integer:
    if (v != std::floor(v)) return false;
    break;
  case ParameterType::number: break;
  }
  return (min_open ? v > min : v >= min) && (max_open ? v < max : v <= max);
}

std::string Parameter::range_text() const {
  switch (type) {
  case ParameterType::flag: return "on or off";
  case ParameterType::choice: {
    std::string out;
    for (size_t i = 0; i < choices.size(); ++i)
      out += (i == 0 ? "" : i + 1 == choices.size() ? " or " : ", ") + std::string(choices[i].name);
    return out;
  }
  case ParameterType::integer:
  case ParameterType::number: break;
  }
  std::string interval = std::string(min_open ? "(" : "[") + number_text(min) + ", " +
                         (std::isinf(max) ? "inf)" : number_text(max) + (max_open ? ")" : "]"));
  return type == ParameterType::integer ? "integer in " + interval : interval;
}

std::string Parameter::value_text(float v) const {
  if (type == ParameterType::flag) return v != 0.0f ? "on" : "off";
  if (type == ParameterType::choice)
    for (const ParameterChoice& c : choices)
      if (c.value == v) return std::string(c.name);
  return number_text(v);
}

float Parameter::parse(std::string_view text) const {
  const std::string what = std::string(name) + " = '" + std::string(text) + "'";
  if (type == ParameterType::choice) {
    std::vector<std::string> names;
    for (const ParameterChoice& c : choices) {
      if (same_text(c.name, text)) return c.value;
      names.emplace_back(c.name);
    }
    throw std::invalid_argument(what + " is not one of " + range_text() + util::did_you_mean(text, names));
  }
  if (type == ParameterType::flag) {
    for (std::string_view on : {"on", "true", "1", "yes"})
      if (same_text(text, on)) return 1.0f;
    for (std::string_view off : {"off", "false", "0", "no"})
      if (same_text(text, off)) return 0.0f;
    throw std::invalid_argument(what + ": use on or off");
  }
  const std::string s(text);
  char* end = nullptr;
  const float v = s.empty() ? 0.0f : std::strtof(s.c_str(), &end);
  if (s.empty() || end != s.c_str() + s.size()) throw std::invalid_argument(what + " is not a number");
  if (!accepts(v)) throw std::invalid_argument(what + " is outside " + range_text());
  return v;
}

glm::vec4 parameter_vector(const Technique& technique, const ParameterValues& values) {
  glm::vec4 v = technique.default_params();
  for (const auto& [name, value] : values) {
    const Parameter& p = technique.parameter(name);
    if (!p.accepts(value))
      throw std::invalid_argument(std::string(technique.name) + ": " + std::string(p.name) + " = " +
                                  p.value_text(value) + " is outside " + p.range_text());
    v[p.slot] = value;
  }
  return v;
}

float parameter_value(const Technique& technique, const ParameterValues& values, std::string_view name) {
  const Parameter& p = technique.parameter(name);
  auto it = values.find(name);
  return it != values.end() ? it->second : p.default_value;
}

void set_parameter(const Technique& technique, ParameterValues& values, std::string_view assignment) {
  const size_t equals = assignment.find('=');
  if (equals == std::string_view::npos)
    throw std::invalid_argument("'" + std::string(assignment) + "': write NAME=VALUE (msm techniques " +
                                std::string(technique.name) + " lists the names)");
  const Parameter& p = technique.parameter(assignment.substr(0, equals));
  values[std::string(p.name)] = p.parse(assignment.substr(equals + 1));
}

const Technique& find_technique(std::string_view name) {
  std::string_view canonical = canonical_technique_name(name);
  std::string valid;
  std::vector<std::string_view> names;
  for (const Technique& t : kTechniques) {
    if (t.name == canonical) return t;
    valid += (valid.empty() ? "" : ", ") + std::string(t.name);
    names.push_back(t.name);
  }
  throw std::invalid_argument("unknown technique '" + std::string(name) + "'" + technique_suggestion(name, names) +
                              "; valid: " + valid + " (aliases: msm techniques)");
}

const Technique& technique_by_id(int id) {
  for (const Technique& t : kTechniques)
    if (t.id == id && id >= 0) return t;
  throw std::invalid_argument("no technique has the id " + std::to_string(id));
}

namespace cpu {

float filtered_shadow(const Technique& technique, std::span<const float> depths, std::span<const float> weights,
                      float unit_zf) {
  if (!technique.on_cpu())
    throw std::invalid_argument("filtered_shadow: " + std::string(technique.name) + " has no CPU pipeline");
  if (depths.size() != weights.size() || depths.empty())
    throw std::invalid_argument("filtered_shadow: need as many weights as depths, at least one");
  Texel sum{};
  float total = 0.0f;
  for (size_t i = 0; i < depths.size(); ++i) {
    Texel t = technique.generate(depths[i]);
    for (int c = 0; c < technique.channels; ++c) sum[c] += weights[i] * t[c];
    total += weights[i];
  }
  if (!(total > 0.0f)) throw std::invalid_argument("filtered_shadow: weights must have a positive sum");
  for (int c = 0; c < technique.channels; ++c) sum[c] /= total;
  return technique.shade(technique.store_load(sum), unit_zf);
}

float percentage_closer(std::span<const float> depths, std::span<const float> weights, float unit_zf) {
  float shadow = 0.0f, total = 0.0f;
  for (size_t i = 0; i < depths.size(); ++i) {
    if (depths[i] < unit_zf) shadow += weights[i];
    total += weights[i];
  }
  return shadow / total;
}

} // namespace cpu
} // namespace msm
