#include "vocabulary.h"

#include <stdexcept>

namespace msm::tool {
namespace {

constexpr std::string_view kTechniquesOther[] = {"--technique-list", "--techs", "--methods"};
constexpr std::string_view kOutOther[] = {"--output", "--output-dir", "--out-dir", "--outdir", "--dir"};
constexpr std::string_view kSceneOther[] = {"--scene-file", "--scenes"};
constexpr std::string_view kDeviceOther[] = {"--gpu", "--vulkan-device"};
constexpr std::string_view kLightsOther[] = {"--count", "--light-count", "--num-lights", "--probe-lights"};
constexpr std::string_view kSubLightsOther[] = {"--sublights", "--sub-light-count"};
constexpr std::string_view kProbeOther[] = {"--probe-file", "--environment-map", "--envmap"};
constexpr std::string_view kRotationOther[] = {"--rotation-speed", "--probe-speed"};
constexpr std::string_view kFrameOther[] = {"--animation-frame", "--object-frame"};
constexpr std::string_view kThreadsOther[] = {"--jobs", "--workers"};
constexpr std::string_view kJsonOther[] = {"--print-json"};
constexpr std::string_view kFilterSizeOther[] = {"--filter", "--taps", "--kernel-size"};
constexpr std::string_view kFilterSigmaOther[] = {"--sigma"};
constexpr std::string_view kShadowSizeOther[] = {"--shadow-map-size", "--map-size"};
constexpr std::string_view kLightExtentOther[] = {"--light-extent", "--light-diameter"};
constexpr std::string_view kLightHeightOther[] = {"--light-height"};
constexpr std::string_view kLightWidthOther[] = {"--light-width"};

const Term kVocabulary[] = {
    {"--techniques", "-t", "Techniques or aliases, comma-separated (msm techniques lists them)", kTechniquesOther},
    {"--technique", "-t", "A technique or alias (msm techniques lists them)", {}},
    {"--out", "-o", "Output directory", kOutOther},
    {"--scene", "", "Built-in scene (msm scenes) or scene file", kSceneOther},
    {"--device", "", "Vulkan device: cpu, gpu, an index or a name (default: MSM_DEVICE, else a GPU)", kDeviceOther},
    {"--lights", "", "The number of area lights a light probe is cut into (median-cut regions), 1 to 256",
     kLightsOther},
    {"--sub-lights", "", "Each area light's sub-lights: a finer cut into this many regions inside its own (0: none)",
     kSubLightsOther},
    {"--probe", "",
     "A light probe: an equirectangular EXR, a cube-map cross, six faces named by a path with \"{face}\", "
     "or 'sky'",
     kProbeOther},
    {"--probe-rotation-speed", "", "Degrees the scene's light probe turns about +Y per frame", kRotationOther},
    {"--frame", "", "Frame K of a dynamic scene: its animated objects moved K times (an object's \"motion\")",
     kFrameOther},
    {"--threads", "", "Worker threads", kThreadsOther},
    {"--progress",
     "",
     "Progress bar on stderr (default: when stderr is a terminal; otherwise a line per tenth once "
     "the run has taken 2 s)",
     {}},
    {"--json", "", "Print JSON on stdout", kJsonOther},
    // The render settings shared with msm reference and msm evaluate (msm/render/settings_schema.h).
    {"--width", "", "Image width in pixels", {}},
    {"--height", "", "Image height in pixels", {}},
    {"--shadow-size", "", "Shadow map texels per side", kShadowSizeOther},
    {"--filter-size", "", "Gaussian taps per axis (odd; 1 = no blur)", kFilterSizeOther},
    {"--filter-sigma", "", "Gaussian standard deviation in texels", kFilterSigmaOther},
    {"--light-extent-deg", "", "Angular diameter of the light in degrees", kLightExtentOther},
    {"--light-width-deg", "", "Angular width in degrees of a rectangular light", kLightWidthOther},
    {"--light-height-deg", "", "Angular height in degrees of a rectangular light", kLightHeightOther},
};

} // namespace

std::span<const Term> vocabulary() { return kVocabulary; }

const Term& term(std::string_view name) {
  for (const Term& t : kVocabulary)
    if (t.name == name) return t;
  throw std::invalid_argument("no term " + std::string(name));
}

std::string option_names(const Term& t) {
  return t.short_name.empty() ? std::string(t.name) : std::string(t.short_name) + "," + std::string(t.name);
}

CLI::Option* add_term_flag(CLI::App* cmd, std::string_view name, bool& target, std::string detail) {
  const Term& t = term(name);
  return cmd->add_flag(option_names(t), target, std::string(t.meaning) + detail);
}

} // namespace msm::tool
