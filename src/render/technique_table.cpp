// The renderer's techniques: names, storage formats and the meaning of their parameters; the
// per-texel math is msm/techniques.h. Settings validation lives here too (it needs the table).
#include "msm/render/renderer.h"
#include "msm/techniques.h"

#include <vulkan/vulkan.h>

#include <cmath>
#include <fmt/format.h>

namespace msm::render {
namespace {

constexpr int kNone = VK_FORMAT_UNDEFINED;
constexpr std::string_view kMoment = "x: moment bias alpha";
constexpr std::string_view kVsm = "w: minimum variance";
constexpr std::string_view kEsm = "y: exponent c";
constexpr std::string_view kEvsm = "y: c+, z: c- (EVSM4), w: minimum variance in depth units";

constexpr Technique kTechniques[] = {
    {"plain", "Shadow map, one depth comparison per fragment (receiver plane at the texel centre)", MSM_TECH_PLAIN,
     16, {kNone, kNone}, ""},
    {"pcf", "PCF with the Gaussian kernel of the blur (taps x taps, sigma), bilinear, every MSAA sample: the "
            "reference for filtered hard shadows (2015)", MSM_TECH_PCF, 16, {kNone, kNone}, ""},
    {"vsm-32", "VSM, 2 x 16-bit UNORM after θ2, depth in [0,1] (2015)", MSM_TECH_VSM32, 32,
     {VK_FORMAT_R16G16_UNORM, kNone}, kVsm},
    {"vsm-64", "VSM, 2 x float", MSM_TECH_VSM64, 64, {VK_FORMAT_R32G32_SFLOAT, kNone}, kVsm},
    {"esm-32", "ESM, 1 x float, c = 80 on [0,1]", MSM_TECH_ESM32, 32, {VK_FORMAT_R32_SFLOAT, kNone}, kEsm},
    {"evsm2-32", "EVSM, positive warp, 2 x half, c = 5.54 on [-1,1]", MSM_TECH_EVSM2_32, 32,
     {VK_FORMAT_R16G16_SFLOAT, kNone}, kEvsm},
    {"evsm2-64", "EVSM, positive warp, 2 x float, c+ = 40 on [-1,1]", MSM_TECH_EVSM2_64, 64,
     {VK_FORMAT_R32G32_SFLOAT, kNone}, kEvsm},
    {"evsm4-64", "EVSM, both warps, 4 x half, c = 5.54 (JCGT Fig. 4a)", MSM_TECH_EVSM4_64, 64,
     {VK_FORMAT_R16G16B16A16_SFLOAT, kNone}, kEvsm},
    {"evsm4-128", "EVSM, both warps, 4 x float, c+ = 40, c- = 5.54 (JCGT Fig. 4e)", MSM_TECH_EVSM4_128, 128,
     {VK_FORMAT_R32G32B32A32_SFLOAT, kNone}, kEvsm},
    {"msm-hamburger-128-unit", "Hamburger 4MSM, 4 x float, depth in [0,1] (2015)", MSM_TECH_HAMBURGER_128_UNIT, 128,
     {VK_FORMAT_R32G32B32A32_SFLOAT, kNone}, kMoment},
    {"msm-hamburger-128", "Hamburger 4MSM, 4 x float, depth in [-1,1] (JCGT 2017)", MSM_TECH_HAMBURGER_128, 128,
     {VK_FORMAT_R32G32B32A32_SFLOAT, kNone}, kMoment},
    {"msm-hamburger-64-theta4", "Hamburger 4MSM, 4 x 16-bit UNORM after θ4, depth in [0,1] (2015)",
     MSM_TECH_HAMBURGER_64_THETA4, 64, {VK_FORMAT_R16G16B16A16_UNORM, kNone}, kMoment},
    {"msm-hamburger-64", "Hamburger 4MSM, 4 x 16-bit UNORM after Θ4*, depth in [-1,1] (JCGT 2017)",
     MSM_TECH_HAMBURGER_64, 64, {VK_FORMAT_R16G16B16A16_UNORM, kNone}, kMoment},
    {"msm-hausdorff-128-unit", "Hausdorff 4MSM on [0,1], 4 x float (2015)", MSM_TECH_HAUSDORFF_128_UNIT, 128,
     {VK_FORMAT_R32G32B32A32_SFLOAT, kNone}, kMoment},
    {"msm-hausdorff-128", "Hausdorff 4MSM on [-1,1], 4 x float (JCGT 2017 depth)", MSM_TECH_HAUSDORFF_128, 128,
     {VK_FORMAT_R32G32B32A32_SFLOAT, kNone}, kMoment},
    {"msm-hausdorff-64-theta4", "Hausdorff 4MSM on [0,1], 4 x 16-bit UNORM after θ4 (2015)",
     MSM_TECH_HAUSDORFF_64_THETA4, 64, {VK_FORMAT_R16G16B16A16_UNORM, kNone}, kMoment},
    {"msm-hausdorff-64", "Hausdorff 4MSM on [-1,1], 4 x 16-bit UNORM after Θ4* (JCGT 2017 storage)",
     MSM_TECH_HAUSDORFF_64, 64, {VK_FORMAT_R16G16B16A16_UNORM, kNone}, kMoment},
    {"tmsm-128", "Trigonometric MSM, 4 x float, depth in [0,1] (2015)", MSM_TECH_TMSM_128, 128,
     {VK_FORMAT_R32G32B32A32_SFLOAT, kNone}, kMoment},
    {"msm6-192", "Hamburger 6MSM, 6 x float, depth in [-1,1] (JCGT §5.4)", MSM_TECH_MSM6_192, 192,
     {VK_FORMAT_R32G32B32A32_SFLOAT, VK_FORMAT_R32G32_SFLOAT}, kMoment},
    {"msm6-96", "Hamburger 6MSM, 6 x 16-bit UNORM after Θ6* (JCGT §5.4.3)", MSM_TECH_MSM6_96, 96,
     {VK_FORMAT_R16G16B16A16_UNORM, VK_FORMAT_R16G16_UNORM}, kMoment},
    {"msm-nl64", "Non-linearly quantized 4MSM, RGBA16 UNORM (y1, y2, v2, Ψ4(ξ4)), one-pass filter, dithered lookup "
                 "(HPG 2017)", MSM_TECH_NL64, 64, {VK_FORMAT_R16G16B16A16_UNORM, kNone}, ""},
    {"mssm4", "Moment soft shadow mapping (JCGT §4): Θ4* moments in a 32-bit integer summed-area table, blocker "
              "search, nine-region filter over the penumbra of a directional area light (--light-extent)",
     MSM_TECH_MSSM4, 128, {VK_FORMAT_R32G32B32A32_SFLOAT, kNone}, ""},
    {"msm-nl32", "Non-linearly quantized 4MSM, R32 UINT (folded 10-bit depths, √v2, Ψ4), one-pass filter, dithered "
                 "lookup (HPG 2017)", MSM_TECH_NL32, 32, {VK_FORMAT_R32_UINT, kNone}, ""},
};

} // namespace

std::span<const Technique> techniques() { return kTechniques; }

const Technique& find_technique(std::string_view name) {
  std::string valid;
  for (const Technique& t : kTechniques) {
    if (t.name == name) return t;
    valid += (valid.empty() ? "" : ", ") + std::string(t.name);
  }
  throw RenderError(fmt::format("unknown technique '{}'; valid: {}", name, valid));
}

bool supports_translucency(const Technique& t) {
  return !msm_technique_is_depth_based(t.id) && !msm_technique_is_nonlinear(t.id) && !msm_technique_is_soft(t.id) &&
         t.formats[1] == 0;
}

glm::vec4 default_params(const Technique& technique) { return msm_technique_default_params(technique.id); }

void RenderSettings::validate() const {
  find_technique(technique);
  auto range = [](std::string_view what, long long v, long long lo, long long hi) {
    if (v < lo || v > hi) throw RenderError(fmt::format("{} = {} is outside [{}, {}]", what, v, lo, hi));
  };
  range("width", width, 1, kMaxImageSide);
  range("height", height, 1, kMaxImageSide);
  if (static_cast<long long>(width) * height > kMaxImagePixels)
    throw RenderError(fmt::format("{} x {} pixels is more than the {} allowed", width, height, kMaxImagePixels));
  range("shadow size", shadow_size, 16, kMaxShadowSize);
  if (msaa != 1 && msaa != 4 && msaa != 8) throw RenderError(fmt::format("msaa = {}: use 1, 4 or 8", msaa));
  range("filter size", filter_size, 1, kMaxFilterTaps);
  if (filter_size % 2 == 0) throw RenderError(fmt::format("filter size = {} must be odd", filter_size));
  auto finite = [](std::string_view what, float v, float lo, float hi) {
    if (!std::isfinite(v) || v < lo || v > hi) throw RenderError(fmt::format("{} = {} is outside [{}, {}]", what, v, lo, hi));
  };
  finite("filter sigma", filter_sigma, 1e-3f, 1e3f);
  finite("over-darkening factor", overdarken, 0.5f, 1.0f);
  finite("normal offset", normal_offset, 0.0f, 100.0f);
  finite("exposure", exposure, 1e-6f, 1e6f);
  if (depth_bias) finite("depth bias", *depth_bias, -1.0f, 1.0f);
  const Technique& t = find_technique(technique);
  bool nonlinear = msm_technique_is_nonlinear(t.id);
  if (one_pass && !*one_pass && nonlinear)
    throw RenderError(fmt::format("{} needs the one-pass filter (it stores Φ of the filtered moments)", technique));
  bool uses_one_pass = one_pass.value_or(nonlinear);
  if (uses_one_pass && msm_technique_is_soft(t.id))
    throw RenderError(fmt::format("{} builds a summed-area table: no one-pass filter", technique));
  if (light_extent_deg) finite("light extent", *light_extent_deg, 0.0f, 89.0f);
  range("soft kernel", soft_kernel, 3, 255);
  if (uses_one_pass && (t.formats[0] == 0 || t.formats[1] != 0))
    throw RenderError(fmt::format("the one-pass filter is for techniques with one moment image, not {}", technique));
  if (uses_one_pass && filter_size > kMaxOnePassTaps)
    throw RenderError(fmt::format("filter size = {}: the one-pass filter takes at most {} taps", filter_size,
                                  kMaxOnePassTaps));
  if (frame < 0) throw RenderError(fmt::format("frame = {} is negative", frame));
  finite("translucent alpha threshold", translucent_alpha_threshold, 0.0f, 1.0f);
  if (params)
    for (int i = 0; i < 4; ++i)
      if (!std::isfinite((*params)[i])) throw RenderError("technique parameters must be finite");
}

} // namespace msm::render
