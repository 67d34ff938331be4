#include "msm/cpu/techniques.h"

#include "msm/msm.h"
#include "msm/techniques.h"
#include "msm/util/spelling.h"

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

// Name, description, MSM_TECH id, bits per texel, channels, the renderer's storage, parameter meaning,
// in the renderer, and the CPU pipeline (generate, storage round trip, reconstruction).
constexpr Technique kTechniques[] = {
    {"plain",
     "Shadow map, one depth comparison per fragment (receiver plane at the texel centre)",
     MSM_TECH_PLAIN,
     16,
     0,
     {TexelFormat::none, TexelFormat::none},
     "",
     true,
     nullptr,
     nullptr,
     nullptr},
    {"pcf",
     "PCF with the Gaussian kernel of the blur (taps x taps, sigma), bilinear, every MSAA sample: the reference for "
     "filtered hard shadows (2015)",
     MSM_TECH_PCF,
     16,
     0,
     {TexelFormat::none, TexelFormat::none},
     "",
     true,
     nullptr,
     nullptr,
     nullptr},
    {"vsm-32",
     "VSM, 2 x 16-bit UNORM after θ2, depth in [0,1] (2015)",
     MSM_TECH_VSM32,
     32,
     2,
     {TexelFormat::rg16_unorm, TexelFormat::none},
     kVsm,
     true,
     generate<MSM_TECH_VSM32>,
     unorm16x2,
     shade<MSM_TECH_VSM32>},
    {"vsm-64",
     "VSM, 2 x float",
     MSM_TECH_VSM64,
     64,
     2,
     {TexelFormat::rg32_float, TexelFormat::none},
     kVsm,
     true,
     generate<MSM_TECH_VSM64>,
     identity,
     shade<MSM_TECH_VSM64>},
    {"esm-32",
     "ESM, 1 x float, c = 80 on [0,1]",
     MSM_TECH_ESM32,
     32,
     1,
     {TexelFormat::r32_float, TexelFormat::none},
     kEsm,
     true,
     generate<MSM_TECH_ESM32>,
     identity,
     shade<MSM_TECH_ESM32>},
    {"evsm2-32",
     "EVSM, positive warp, 2 x half, c = 5.54 on [-1,1]",
     MSM_TECH_EVSM2_32,
     32,
     2,
     {TexelFormat::rg16_float, TexelFormat::none},
     kEvsm,
     true,
     generate<MSM_TECH_EVSM2_32>,
     half2,
     shade<MSM_TECH_EVSM2_32>},
    {"evsm2-64",
     "EVSM, positive warp, 2 x float, c+ = 40 on [-1,1]",
     MSM_TECH_EVSM2_64,
     64,
     2,
     {TexelFormat::rg32_float, TexelFormat::none},
     kEvsm,
     true,
     generate<MSM_TECH_EVSM2_64>,
     identity,
     shade<MSM_TECH_EVSM2_64>},
    {"evsm4-64",
     "EVSM, both warps, 4 x half, c = 5.54 (JCGT Fig. 4a)",
     MSM_TECH_EVSM4_64,
     64,
     4,
     {TexelFormat::rgba16_float, TexelFormat::none},
     kEvsm,
     true,
     generate<MSM_TECH_EVSM4_64>,
     half4,
     shade<MSM_TECH_EVSM4_64>},
    {"evsm4-128",
     "EVSM, both warps, 4 x float, c+ = 40, c- = 5.54 (JCGT Fig. 4e)",
     MSM_TECH_EVSM4_128,
     128,
     4,
     {TexelFormat::rgba32_float, TexelFormat::none},
     kEvsm,
     true,
     generate<MSM_TECH_EVSM4_128>,
     identity,
     shade<MSM_TECH_EVSM4_128>},
    {"csm-4",
     "Convolution shadow map, 4 Fourier terms in 8 floats, damped",
     -1,
     256,
     8,
     {TexelFormat::none, TexelFormat::none},
     "",
     false,
     csm4,
     identity,
     csm4_shade},
    {"msm-hamburger-128-unit",
     "Hamburger 4MSM, 4 x float, depth in [0,1] (2015)",
     MSM_TECH_HAMBURGER_128_UNIT,
     128,
     4,
     {TexelFormat::rgba32_float, TexelFormat::none},
     kMoment,
     true,
     generate<MSM_TECH_HAMBURGER_128_UNIT>,
     identity,
     shade<MSM_TECH_HAMBURGER_128_UNIT>},
    {"msm-hamburger-128",
     "Hamburger 4MSM, 4 x float, depth in [-1,1] (JCGT 2017)",
     MSM_TECH_HAMBURGER_128,
     128,
     4,
     {TexelFormat::rgba32_float, TexelFormat::none},
     kMoment,
     true,
     generate<MSM_TECH_HAMBURGER_128>,
     identity,
     shade<MSM_TECH_HAMBURGER_128>},
    {"msm-hamburger-64-theta4",
     "Hamburger 4MSM, 4 x 16-bit UNORM after θ4, depth in [0,1] (2015)",
     MSM_TECH_HAMBURGER_64_THETA4,
     64,
     4,
     {TexelFormat::rgba16_unorm, TexelFormat::none},
     kMoment,
     true,
     generate<MSM_TECH_HAMBURGER_64_THETA4>,
     unorm16,
     shade<MSM_TECH_HAMBURGER_64_THETA4>},
    {"msm-hamburger-64",
     "Hamburger 4MSM, 4 x 16-bit UNORM after Θ4*, depth in [-1,1] (JCGT 2017)",
     MSM_TECH_HAMBURGER_64,
     64,
     4,
     {TexelFormat::rgba16_unorm, TexelFormat::none},
     kMoment,
     true,
     generate<MSM_TECH_HAMBURGER_64>,
     unorm16,
     shade<MSM_TECH_HAMBURGER_64>},
    {"msm-hausdorff-128-unit",
     "Hausdorff 4MSM on [0,1], 4 x float (2015)",
     MSM_TECH_HAUSDORFF_128_UNIT,
     128,
     4,
     {TexelFormat::rgba32_float, TexelFormat::none},
     kMoment,
     true,
     generate<MSM_TECH_HAUSDORFF_128_UNIT>,
     identity,
     shade<MSM_TECH_HAUSDORFF_128_UNIT>},
    {"msm-hausdorff-128",
     "Hausdorff 4MSM on [-1,1], 4 x float (JCGT 2017 depth)",
     MSM_TECH_HAUSDORFF_128,
     128,
     4,
     {TexelFormat::rgba32_float, TexelFormat::none},
     kMoment,
     true,
     generate<MSM_TECH_HAUSDORFF_128>,
     identity,
     shade<MSM_TECH_HAUSDORFF_128>},
    {"msm-hausdorff-64-theta4",
     "Hausdorff 4MSM on [0,1], 4 x 16-bit UNORM after θ4 (2015)",
     MSM_TECH_HAUSDORFF_64_THETA4,
     64,
     4,
     {TexelFormat::rgba16_unorm, TexelFormat::none},
     kMoment,
     true,
     generate<MSM_TECH_HAUSDORFF_64_THETA4>,
     unorm16,
     shade<MSM_TECH_HAUSDORFF_64_THETA4>},
    {"msm-hausdorff-64",
     "Hausdorff 4MSM on [-1,1], 4 x 16-bit UNORM after Θ4* (JCGT 2017 storage)",
     MSM_TECH_HAUSDORFF_64,
     64,
     4,
     {TexelFormat::rgba16_unorm, TexelFormat::none},
     kMoment,
     true,
     generate<MSM_TECH_HAUSDORFF_64>,
     unorm16,
     shade<MSM_TECH_HAUSDORFF_64>},
    {"tmsm-128",
     "Trigonometric MSM, 4 x float, depth in [0,1] (2015)",
     MSM_TECH_TMSM_128,
     128,
     4,
     {TexelFormat::rgba32_float, TexelFormat::none},
     kMoment,
     true,
     generate<MSM_TECH_TMSM_128>,
     identity,
     shade<MSM_TECH_TMSM_128>},
    {"msm6-192",
     "Hamburger 6MSM, 6 x float, depth in [-1,1] (JCGT §5.4)",
     MSM_TECH_MSM6_192,
     192,
     6,
     {TexelFormat::rgba32_float, TexelFormat::rg32_float},
     kMoment,
     true,
     generate<MSM_TECH_MSM6_192>,
     identity,
     shade<MSM_TECH_MSM6_192>},
    {"msm6-96",
     "Hamburger 6MSM, 6 x 16-bit UNORM after Θ6* (JCGT §5.4.3)",
     MSM_TECH_MSM6_96,
     96,
     6,
     {TexelFormat::rgba16_unorm, TexelFormat::rg16_unorm},
     kMoment,
     true,
     generate<MSM_TECH_MSM6_96>,
     m6_unorm16,
     shade<MSM_TECH_MSM6_96>},
    {"msm6-64",
     "Hamburger 6MSM, 6 x 10-bit UNORM after Θ6* (JCGT §5.4.3)",
     -1,
     64,
     6,
     {TexelFormat::none, TexelFormat::none},
     "",
     false,
     generate<MSM_TECH_MSM6_96>,
     m6_unorm10,
     m6_10_shade},
    {"msm-nl64",
     "Non-linearly quantized 4MSM, 4 x 16-bit (y1, y2, v2, Ψ4(ξ4)) (HPG 2017)",
     MSM_TECH_NL64,
     64,
     4,
     {TexelFormat::rgba16_unorm, TexelFormat::none},
     "",
     true,
     moments_signed,
     nl64_store,
     nl_shade},
    {"mssm4",
     "Moment soft shadow mapping (JCGT §4): Θ4* moments in a 32-bit integer summed-area table, blocker search, "
     "nine-region filter over the penumbra of a directional area light (--light-extent)",
     MSM_TECH_MSSM4,
     128,
     4,
     {TexelFormat::rgba32_float, TexelFormat::none},
     kSoftMoments,
     true,
     nullptr,
     nullptr,
     nullptr},
    {"msm-nl32",
     "Non-linearly quantized 4MSM, 32-bit packed (HPG 2017)",
     MSM_TECH_NL32,
     32,
     4,
     {TexelFormat::r32_uint, TexelFormat::none},
     "",
     true,
     moments_signed,
     nl32_store,
     nl_shade},
    {"mssm6",
     "Moment soft shadows with six moments (Kneiphof §4.2): Θ6* in two 32-bit integer summed-area tables, "
     "upper-bound blocker depth (Eq. 19, clamp [δ1, δ2]), nine-region filter",
     MSM_TECH_MSSM6,
     192,
     6,
     {TexelFormat::rgba32_float, TexelFormat::rg32_float},
     kSoftMoments,
     true,
     nullptr,
     nullptr,
     nullptr},
    {"vssm",
     "Naive variance soft shadow mapping (Yang et al. 2010): the mssm4 pipeline with two moments (z, z²), "
     "Chebyshev blocker estimate and filter (the baseline of JCGT §4)",
     MSM_TECH_VSSM,
     64,
     2,
     {TexelFormat::rg32_float, TexelFormat::none},
     "w: minimum variance",
     true,
     nullptr,
     nullptr,
     nullptr},
    {"pcss",
     "Percentage-closer soft shadows (Fernando 2005): every texel of a search region up to 15², then PCF over "
     "the penumbra, every MSAA sample against the receiver plane (the baseline of JCGT §4)",
     MSM_TECH_PCSS,
     16,
     0,
     {TexelFormat::none, TexelFormat::none},
     "",
     true,
     nullptr,
     nullptr,
     nullptr},
    {"scatter-march-32",
     "Single scattering in the scene's medium by ray marching (JCGT §5.5.1's baseline): 32 equidistant samples "
     "of the 16-bit depth map per pixel, one blue-noise jitter per pixel; surfaces shaded with PCF",
     MSM_TECH_SCATTER_MARCH32,
     16,
     0,
     {TexelFormat::none, TexelFormat::none},
     "",
     true,
     nullptr,
     nullptr,
     nullptr},
    {"scatter-march-128",
     "Single scattering by ray marching as scatter-march-32, with 128 samples per pixel",
     MSM_TECH_SCATTER_MARCH128,
     16,
     0,
     {TexelFormat::none, TexelFormat::none},
     "",
     true,
     nullptr,
     nullptr,
     nullptr},
    {"scatter-msm4-64",
     "Prefiltered single scattering with four moments (JCGT §5.3): the depth map resampled without filtering into "
     "the rectified map (§5.1.1), transmittance-weighted prefix sums along its rows stored as Θ4* in 4 x 16 bits, "
     "one bilinear lookup per pixel, sharp bounds blended by the proportional β (§5.3.1 adapted); surfaces shaded with "
     "PCF",
     MSM_TECH_SCATTER_MSM4_64,
     64,
     4,
     {TexelFormat::none, TexelFormat::none},
     "x: 1 = resampling with filtering (JCGT §5.2: a trilinear sample of the blurred, mipmapped 4-moment map at the "
     "texel's footprint, Algorithm 2), 2 = from the unblurred depth map's bilinear moments, 0 = without (default); "
     "z: 1 = a fixed β = y in [0, 1] (§5.3.1), 2 = the adaptive β of §5.3.1, 0 = the proportional β (default: the "
     "undecided weight shared as the bounds share the rest, falling to 0 towards the epipole); "
     "w: transmittance layers K = 1..16 (1 = the paper's single Δ per row), 0 = the default",
     true,
     nullptr,
     nullptr,
     nullptr},
    {"scatter-msm6-64",
     "Prefiltered single scattering with six moments (JCGT §5.4): as scatter-msm4-64, Θ6* prefix sums in 6 x 10 bits "
     "(two RGB10A2 images, alpha 4e-3), "
     "Blinn's cubic and the divided-difference weights, proportional β",
     MSM_TECH_SCATTER_MSM6_64,
     64,
     6,
     {TexelFormat::none, TexelFormat::none},
     "x: 1 = resampling with filtering (JCGT §5.2: a trilinear sample of the blurred, mipmapped 4-moment map at the "
     "texel's footprint, Algorithm 2), 2 = from the unblurred depth map's bilinear moments, 0 = without (default); "
     "z: 1 = a fixed β = y in [0, 1] (§5.3.1), 2 = the adaptive β of §5.3.1, 0 = the proportional β (default: the "
     "undecided weight shared as the bounds share the rest, falling to 0 towards the epipole); "
     "w: transmittance layers K = 1..16 (1 = the paper's single Δ per row), 0 = the default",
     true,
     nullptr,
     nullptr,
     nullptr},
    {"scatter-msm6-96",
     "Prefiltered single scattering with six moments (JCGT §5.4): as scatter-msm4-64, Θ6* prefix sums in 2 + 4 x 16 "
     "bits (alpha 8e-5), "
     "Blinn's cubic and the divided-difference weights, proportional β",
     MSM_TECH_SCATTER_MSM6_96,
     96,
     6,
     {TexelFormat::none, TexelFormat::none},
     "x: 1 = resampling with filtering (JCGT §5.2: a trilinear sample of the blurred, mipmapped 4-moment map at the "
     "texel's footprint, Algorithm 2), 2 = from the unblurred depth map's bilinear moments, 0 = without (default); "
     "z: 1 = a fixed β = y in [0, 1] (§5.3.1), 2 = the adaptive β of §5.3.1, 0 = the proportional β (default: the "
     "undecided weight shared as the bounds share the rest, falling to 0 towards the epipole); "
     "w: transmittance layers K = 1..16 (1 = the paper's single Δ per row), 0 = the default",
     true,
     nullptr,
     nullptr,
     nullptr},
    {"scatter-msm6-192",
     "Prefiltered single scattering with six moments (JCGT §5.4): as scatter-msm4-64, Θ6* prefix sums in 6 x 32-bit "
     "float (alpha 5e-6), "
     "Blinn's cubic and the divided-difference weights, proportional β",
     MSM_TECH_SCATTER_MSM6_192,
     192,
     6,
     {TexelFormat::none, TexelFormat::none},
     "x: 1 = resampling with filtering (JCGT §5.2: a trilinear sample of the blurred, mipmapped 4-moment map at the "
     "texel's footprint, Algorithm 2), 2 = from the unblurred depth map's bilinear moments, 0 = without (default); "
     "z: 1 = a fixed β = y in [0, 1] (§5.3.1), 2 = the adaptive β of §5.3.1, 0 = the proportional β (default: the "
     "undecided weight shared as the bounds share the rest, falling to 0 towards the epipole); "
     "w: transmittance layers K = 1..16 (1 = the paper's single Δ per row), 0 = the default",
     true,
     nullptr,
     nullptr,
     nullptr},
    {"scatter-csm-32",
     "Prefiltered single scattering with a convolution shadow map (Klehm et al. 2014): the passes of "
     "scatter-msm4-64, 16 sin/cos terms of the rectified depth (32 coefficients) whose prefix sums are stored in 8 "
     "bits each (eight RGBA8 layers), the plain Fourier reconstruction with damping (no bounds, no β); surfaces "
     "shaded with PCF",
     MSM_TECH_SCATTER_CSM32,
     256,
     32,
     {TexelFormat::none, TexelFormat::none},
     "x: 1 = resampling with filtering (JCGT §5.2: a trilinear sample of the blurred, mipmapped 4-moment map at the "
     "texel's footprint, Algorithm 2), 2 = from the unblurred depth map's bilinear moments, 0 = without (default); "
     "w: transmittance layers K = 1..16 (1 = the paper's single Δ per row), 0 = the default",
     true,
     nullptr,
     nullptr,
     nullptr},
    {"cssm8",
     "Convolution soft shadow maps (Annen et al. 2008), Kneiphof's CSSM8: CSM of 4 frequencies, the basis times "
     "depth and the depth (17 values) in a 32-bit integer summed-area table of stacked tiles; blocker depth "
     "E[z f] / E[f], nine-region filter",
     MSM_TECH_CSSM8,
     640,
     17,
     {TexelFormat::rgba32_float, TexelFormat::none},
     kCssmParams,
     true,
     nullptr,
     nullptr,
     nullptr},
    {"cssm16",
     "Convolution soft shadow maps (Annen et al. 2008), Kneiphof's CSSM16: CSM of 8 frequencies (33 values in "
     "9 tiles of one summed-area table)",
     MSM_TECH_CSSM16,
     1152,
     33,
     {TexelFormat::rgba32_float, TexelFormat::none},
     kCssmParams,
     true,
     nullptr,
     nullptr,
     nullptr},
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
