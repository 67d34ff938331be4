#include "msm/reference/settings_schema.h"

#include "msm/filter.h"

#include <cstdint>
#include <optional>
#include <string>
#include <type_traits>

namespace msm::reference {
namespace {

using json = nlohmann::json;

// Accessors of a member, made from its pointer: plain values, optional ones (null: unset), and
// enums by name (to_string and parse_*: the choices below).
template <auto member>
json get_value(const Settings& s) {
  return s.*member;
}
template <auto member>
void set_value(Settings& s, const json& v) {
  using T = std::remove_cvref_t<decltype(s.*member)>;
  s.*member = v.get<T>();
}
template <auto member>
json get_optional(const Settings& s) {
  const auto& value = s.*member;
  return value ? json(*value) : json();
}
template <auto member>
void set_optional(Settings& s, const json& v) {
  using T = typename std::remove_cvref_t<decltype(s.*member)>::value_type;
  if (v.is_null())
    (s.*member).reset();
  else
    s.*member = v.get<T>();
}

json get_effect(const Settings& s) { return std::string(to_string(s.effect)); }
void set_effect(Settings& s, const json& v) { s.effect = *parse_effect(v.get<std::string>()); }
json get_sampler(const Settings& s) { return std::string(to_string(s.sampler)); }
void set_sampler(Settings& s, const json& v) { s.sampler = *parse_sampler(v.get<std::string>()); }
json get_light_shape(const Settings& s) {
  return s.light_shape ? json(std::string(to_string(*s.light_shape))) : json();
}
void set_light_shape(Settings& s, const json& v) {
  if (v.is_null())
    s.light_shape.reset();
  else
    s.light_shape = *parse_light_shape(v.get<std::string>());
}

constexpr std::string_view kEffects[] = {"hard", "filtered", "soft", "translucent", "scattering", "environment"};
constexpr std::string_view kSamplers[] = {"stratified", "independent"};
constexpr std::string_view kLightShapes[] = {"disc", "rectangle"};

const SettingDeclaration kSettings[] = {
    {.key = "effect",
     .type = SettingType::choice,
     .help = "What is traced: hard, filtered, soft, translucent, scattering or environment",
     .choices = kEffects,
     .get = get_effect,
     .set = set_effect},
    {.key = "width",
     .type = SettingType::integer,
     .help = "Image width in pixels",
     .min = 1,
     .max = kMaxSide,
     .get = get_value<&Settings::width>,
     .set = set_value<&Settings::width>},
    {.key = "height",
     .type = SettingType::integer,
     .help = "Image height in pixels",
     .min = 1,
     .max = kMaxSide,
     .get = get_value<&Settings::height>,
     .set = set_value<&Settings::height>},
    {.key = "samples",
     .type = SettingType::integer,
     .help = "Samples per pixel of filtered, soft, scattering and environment",
     .min = 1,
     .max = kMaxSamples,
     .scale = SettingScale::logarithmic,
     .get = get_value<&Settings::samples>,
     .set = set_value<&Settings::samples>},
    {.key = "seed",
     .type = SettingType::integer,
     .help = "Seed of the per-pixel generators",
     .min = 0,
     .max = 0x1p53, // every seed exact in JSON
     .get = get_value<&Settings::seed>,
     .set = set_value<&Settings::seed>},
    {.key = "sampler",
     .type = SettingType::choice,
     .help = "stratified (a jittered grid of floor(sqrt(N))² samples) or independent",
     .choices = kSamplers,
     .get = get_sampler,
     .set = set_sampler},
    {.key = "shadow_size",
     .type = SettingType::integer,
     .help = "Shadow map texels per side, filtered: the renderer's",
     .min = 1,
     .max = kMaxShadowSize,
     .get = get_value<&Settings::shadow_size>,
     .set = set_value<&Settings::shadow_size>},
    {.key = "filter_size",
     .type = SettingType::integer,
     .help = "Gaussian taps per axis (odd; 1 = no blur), filtered",
     .min = 1,
     .max = MSM_FILTER_MAX_TAPS,
     .get = get_value<&Settings::filter_size>,
     .set = set_value<&Settings::filter_size>},
    {.key = "filter_sigma",
     .type = SettingType::number,
     .help = "Gaussian standard deviation in texels, filtered",
     .min = MSM_FILTER_MIN_SIGMA,
     .max = MSM_FILTER_MAX_SIGMA,
     .get = get_value<&Settings::filter_sigma>,
     .set = set_value<&Settings::filter_sigma>},
    {.key = "light_extent_deg",
     .type = SettingType::number,
     .help = "Angular diameter of the light in degrees, soft: the light becomes a disc of this diameter, as msm "
             "render --light-extent-deg makes it (default: the scene's light as it declares it)",
     .min = 0,
     .max = 89,
     .nullable = true,
     .get = get_optional<&Settings::light_extent_deg>,
     .set = set_optional<&Settings::light_extent_deg>},
    {.key = "light_shape",
     .type = SettingType::choice,
     .help = "soft: the light's shape, disc or rectangle (default: the scene light's own)",
     .choices = kLightShapes,
     .nullable = true,
     .get = get_light_shape,
     .set = set_light_shape},
    {.key = "light_width_deg",
     .type = SettingType::number,
     .help = "Angular width in degrees of a rectangular light, soft (default: the light's extent)",
     .min = 0,
     .max = 89,
     .nullable = true,
     .get = get_optional<&Settings::light_width_deg>,
     .set = set_optional<&Settings::light_width_deg>},
    {.key = "light_height_deg",
     .type = SettingType::number,
     .help = "Angular height in degrees of a rectangular light, soft, as msm render --light-height-deg (default: "
             "the light's own, else its extent)",
     .min = 0,
     .max = 89,
     .nullable = true,
     .get = get_optional<&Settings::light_height_deg>,
     .set = set_optional<&Settings::light_height_deg>},
    {.key = "max_crossings",
     .type = SettingType::integer,
     .help = "translucent: surfaces counted per light ray",
     .min = 1,
     .max = kMaxCrossings,
     .get = get_value<&Settings::max_crossings>,
     .set = set_value<&Settings::max_crossings>},
    {.key = "extracted_lights",
     .type = SettingType::flag,
     .help = "environment: light with the probe's extracted area lights (uniform cones) instead of the full probe",
     .get = get_value<&Settings::probe_lights>,
     .set = set_value<&Settings::probe_lights>},
};

} // namespace

std::span<const SettingDeclaration> setting_declarations() { return kSettings; }

const SettingDeclaration& find_setting(std::string_view key) { return msm::find_setting(setting_declarations(), key); }

nlohmann::ordered_json settings_json(const Settings& settings) {
  nlohmann::ordered_json out = nlohmann::ordered_json::object();
  for (const SettingDeclaration& s : kSettings) out[std::string(s.key)] = s.get(settings);
  return out;
}

void apply_settings_json(Settings& settings, const json& object) {
  msm::apply_settings_json(setting_declarations(), settings, object);
}

} // namespace msm::reference
