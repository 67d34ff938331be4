#include "msm/render/settings_schema.h"

#include "msm/techniques.h"
#include "msm/util/spelling.h"

#include <fmt/format.h>

#include <algorithm>
#include <cerrno>
#include <climits>
#include <cmath>
#include <cstdlib>
#include <iterator>
#include <type_traits>

namespace msm::render {
namespace {

using json = nlohmann::json;

// Accessors of a member, made from its pointer: plain values, optional ones (null: unset), enums
// whose values are the choices' indices, and an optional<bool> whose choices are "auto", then the
// name of `first`, then the name of its negation.
template <auto member>
json get_value(const RenderSettings& s) {
  return s.*member;
}
template <auto member>
void set_value(RenderSettings& s, const json& v) {
  using T = std::remove_cvref_t<decltype(s.*member)>;
  s.*member = v.get<T>();
}
template <auto member>
json get_optional(const RenderSettings& s) {
  const auto& value = s.*member;
  return value ? json(*value) : json();
}
template <auto member>
void set_optional(RenderSettings& s, const json& v) {
  using T = typename std::remove_cvref_t<decltype(s.*member)>::value_type;
  if (v.is_null())
    (s.*member).reset();
  else
    s.*member = v.get<T>();
}
template <auto member, const auto& choices>
json get_enum(const RenderSettings& s) {
  return std::string(choices[size_t(s.*member)]);
}
template <auto member, const auto& choices>
void set_enum(RenderSettings& s, const json& v) {
  using E = std::remove_cvref_t<decltype(s.*member)>;
  s.*member = E(std::find(std::begin(choices), std::end(choices), v.get<std::string>()) - std::begin(choices));
}
template <auto member, const auto& choices, bool first>
json get_auto_bool(const RenderSettings& s) {
  const std::optional<bool>& value = s.*member;
  return std::string(choices[!value ? 0 : *value == first ? 1 : 2]);
}
template <auto member, const auto& choices, bool first>
void set_auto_bool(RenderSettings& s, const json& v) {
  const size_t i =
      size_t(std::find(std::begin(choices), std::end(choices), v.get<std::string>()) - std::begin(choices));
  if (i == 0)
    (s.*member).reset();
  else
    s.*member = i == 1 ? first : !first;
}

json get_technique(const RenderSettings& s) { return s.technique; }
void check_technique(const json& v) {
  try {
    find_rendered_technique(canonical_technique_name(v.get<std::string>()));
  } catch (const RenderError& e) { throw SettingError(e.what()); }
}
void set_technique(RenderSettings& s, const json& v) {
  s.technique = std::string(find_rendered_technique(canonical_technique_name(v.get<std::string>())).name);
}

// The technique's parameters by name (msm techniques NAME): numbers, integers, true/false, a
// choice by its name.
json get_parameters(const RenderSettings& s) {
  json out = json::object();
  for (const Parameter* p : find_rendered_technique(s.technique).parameter_list()) {
    const float v = s.parameter(p->name);
    json& value = out[std::string(p->name)];
    if (p->type == ParameterType::number)
      value = v;
    else if (p->type == ParameterType::integer)
      value = int(v);
    else if (p->type == ParameterType::flag)
      value = v != 0.0f;
    else
      value = p->value_text(v);
  }
  return out;
}

// The inverse, validated against the technique's declarations (the technique is set first). Null:
// every default.
void set_parameters(RenderSettings& s, const json& v) {
  if (v.is_null()) return s.reset_parameters();
  const Technique& t = find_rendered_technique(s.technique);
  ParameterValues values;
  for (const auto& [name, value] : v.items()) {
    const std::string text = value.is_string()    ? value.get<std::string>()
                             : value.is_boolean() ? (value.get<bool>() ? "on" : "off")
                                                  : value.dump();
    try {
      set_parameter(t, values, name + "=" + text);
    } catch (const std::invalid_argument& e) { throw SettingError(e.what(), "/" + name); }
  }
  s.parameters = values;
}

using R = RenderSettings;
constexpr std::string_view kMsaaCounts[] = {"1", "4", "8"};
constexpr std::string_view kLookups[] = {"auto", "bilinear", "nearest", "dither"}; // R::Lookup's order
constexpr std::string_view kFilterModes[] = {"auto", "one-pass", "three-pass"};
constexpr std::string_view kShadings[] = {"auto", "forward", "deferred"};
constexpr std::string_view kPrefixSums[] = {"rows", "appendix-c"};      // R::PrefixSums's order
constexpr std::string_view kCascadeDepthBounds[] = {"reduce", "scene"}; // R::CascadeDepthBounds's order

const SettingDeclaration kSettings[] = {
    {.key = "technique",
     .type = SettingType::technique,
     .help = "Technique or alias (msm techniques lists them)",
     .check = check_technique,
     .get = get_technique,
     .set = set_technique},
    {.key = "width",
     .type = SettingType::integer,
     .help = "Image width in pixels",
     .min = 1,
     .max = kMaxImageSide,
     .get = get_value<&R::width>,
     .set = set_value<&R::width>},
    {.key = "height",
     .type = SettingType::integer,
     .help = "Image height in pixels",
     .min = 1,
     .max = kMaxImageSide,
     .get = get_value<&R::height>,
     .set = set_value<&R::height>},
    {.key = "shadow_size",
     .type = SettingType::integer,
     .help = "Shadow map texels per side",
     .min = 16,
     .max = kMaxShadowSize,
     .control_min = 256,
     .control_max = 4096,
     .scale = SettingScale::logarithmic,
     .get = get_value<&R::shadow_size>,
     .set = set_value<&R::shadow_size>},
    {.key = "msaa",
     .type = SettingType::integer,
     .help = "Shadow depth samples: 1, 4 or 8",
     .min = 1,
     .max = 8,
     .choices = kMsaaCounts,
     .get = get_value<&R::msaa>,
     .set = set_value<&R::msaa>},
    {.key = "filter_size",
     .type = SettingType::integer,
     .help = "Gaussian taps per axis (odd; 1 = no blur)",
     .min = 1,
     .max = MSM_FILTER_MAX_TAPS,
     .control_step = 2, // odd
     .get = get_value<&R::filter_size>,
     .set = set_value<&R::filter_size>},
    {.key = "filter_sigma",
     .type = SettingType::number,
     .help = "Gaussian standard deviation in texels",
     .min = MSM_FILTER_MIN_SIGMA,
     .max = MSM_FILTER_MAX_SIGMA,
     .control_min = 0.1,
     .control_max = 16,
     .get = get_value<&R::filter_sigma>,
     .set = set_value<&R::filter_sigma>},
    {.key = "mipmaps",
     .type = SettingType::flag,
     .help = "A mip chain of the moment images (trilinear lookups)",
     .get = get_value<&R::mipmaps>,
     .set = set_value<&R::mipmaps>},
    {.key = "parameters",
     .type = SettingType::parameters,
     .help = "The technique's parameters by name (msm techniques NAME lists them: type, range, default, meaning)",
     .get = get_parameters,
     .set = set_parameters},
    {.key = "overdarken",
     .type = SettingType::number,
     .help = "Over-darkening factor (1 = off)",
     .min = 0.5,
     .max = 1,
     .get = get_value<&R::overdarken>,
     .set = set_value<&R::overdarken>},
    {.key = "normal_offset",
     .type = SettingType::number,
     .help = "Normal offset in shadow-map texels",
     .min = 0,
     .max = 100,
     .control_max = 4,
     .get = get_value<&R::normal_offset>,
     .set = set_value<&R::normal_offset>},
    {.key = "depth_bias",
     .type = SettingType::number,
     .help = "Depth bias in [0,1] depth (default per technique)",
     .min = -1,
     .max = 1,
     .nullable = true,
     .control_max = 0.05,
     .scale = SettingScale::logarithmic,
     .get = get_optional<&R::depth_bias>,
     .set = set_optional<&R::depth_bias>},
    {.key = "receiver_plane_bias",
     .type = SettingType::number,
     .help = "Receiver-plane (slope-scaled) bias of the filtered techniques, as a fraction of what their bound "
             "needs on a plane (0 = off; default: 1 for cascades, 0 for one map)",
     .min = 0,
     .max = 4,
     .nullable = true,
     .get = get_optional<&R::receiver_plane_bias>,
     .set = set_optional<&R::receiver_plane_bias>},
    {.key = "exposure",
     .type = SettingType::number,
     .help = "Exposure before tone mapping",
     .min = 1e-6,
     .max = 1e6,
     .control_min = 0.1,
     .control_max = 4,
     .get = get_value<&R::exposure>,
     .set = set_value<&R::exposure>},
    {.key = "lookup",
     .type = SettingType::choice,
     .help = "Shadow-map lookup: auto (dither for msm-nl*, else bilinear), bilinear, nearest, dither",
     .choices = kLookups,
     .get = get_enum<&R::lookup, kLookups>,
     .set = set_enum<&R::lookup, kLookups>},
    {.key = "filter_mode",
     .type = SettingType::choice,
     .help = "auto (one-pass for msm-nl*), one-pass (resolve + blur in shared memory), three-pass (resolve, blur "
             "H, blur V)",
     .choices = kFilterModes,
     .get = get_auto_bool<&R::one_pass, kFilterModes, true>,
     .set = set_auto_bool<&R::one_pass, kFilterModes, true>},
    {.key = "shading",
     .type = SettingType::choice,
     .help = "auto (deferred for pcf, pcss and the soft techniques), forward (shadows per shaded fragment), "
             "deferred (a surfaces pass, then shadows once per visible pixel; depth-based and soft techniques "
             "only)",
     .choices = kShadings,
     .get = get_auto_bool<&R::deferred_shading, kShadings, false>,
     .set = set_auto_bool<&R::deferred_shading, kShadings, false>},
    {.key = "prefix_sums",
     .type = SettingType::choice,
     .help = "prefiltered scattering's prefix sums: rows (a thread per row, each texel once) or appendix-c "
             "(JCGT's 8 x 8 scheme; the same sums)",
     .choices = kPrefixSums,
     .get = get_enum<&R::prefix_sums, kPrefixSums>,
     .set = set_enum<&R::prefix_sums, kPrefixSums>},
    {.key = "prefix_sum_mips",
     .type = SettingType::flag,
     .help = "prefiltered scattering: a mip chain of the prefix sums, read at the pixel's footprint across the "
             "rows (JCGT App. D.5)",
     .get = get_value<&R::prefix_sum_mips>,
     .set = set_value<&R::prefix_sum_mips>},
    {.key = "noise_frame",
     .type = SettingType::integer,
     .help = "Blue-noise layer and offset of the dithered lookups",
     .min = 0,
     .max = 1 << 30,
     .control_max = 63,
     .get = get_value<&R::frame>,
     .set = set_value<&R::frame>},
    {.key = "translucent_occluders",
     .type = SettingType::flag,
     .help = "Translucent objects cast shadows (blended into the moment map)",
     .get = get_value<&R::translucent_occluders>,
     .set = set_value<&R::translucent_occluders>},
    {.key = "coloured_translucency",
     .type = SettingType::flag,
     .help = "Coloured translucent shadows: one moment map per colour channel (materials' transmission_color)",
     .get = get_value<&R::coloured_translucency>,
     .set = set_value<&R::coloured_translucency>},
    {.key = "alpha_threshold",
     .type = SettingType::number,
     .help = "Translucent fragments below this opacity are not blended (JCGT: 1%)",
     .min = 0,
     .max = 1,
     .control_max = 0.5,
     .get = get_value<&R::translucent_alpha_threshold>,
     .set = set_value<&R::translucent_alpha_threshold>},
    {.key = "cascades",
     .type = SettingType::integer,
     .help = "Cascaded shadow maps per directional light, each over a slice of the view depth (default: 4 where "
             "one map's texels would span more than 8 pixels and the technique has them, else 1)",
     .min = 1,
     .max = scene::kMaxCascades,
     .nullable = true,
     .get = get_optional<&R::cascades>,
     .set = set_optional<&R::cascades>},
    {.key = "cascade_lambda",
     .type = SettingType::number,
     .help = "The cascades' split scheme: 0 uniform, 1 logarithmic in view depth, between a blend of the two",
     .min = 0,
     .max = 1,
     .get = get_value<&R::cascade_lambda>,
     .set = set_value<&R::cascade_lambda>},
    {.key = "cascade_stabilize",
     .type = SettingType::flag,
     .help = "The cascades' maps snapped to whole texels, their size fixed: no shimmer as the camera moves",
     .get = get_value<&R::cascade_stabilize>,
     .set = set_value<&R::cascade_stabilize>},
    {.key = "cascade_depth_bounds",
     .type = SettingType::choice,
     .help = "The view depths the cascades split: reduce (the nearest and farthest surface in the camera's depth "
             "buffer, by a depth pre-pass and a compute reduction) or scene (the camera's frustum clipped to the "
             "scene's bounds)",
     .choices = kCascadeDepthBounds,
     .get = get_enum<&R::cascade_depth_bounds, kCascadeDepthBounds>,
     .set = set_enum<&R::cascade_depth_bounds, kCascadeDepthBounds>},
    {.key = "light_extent_deg",
     .type = SettingType::number,
     .help = "Angular diameter of the light in degrees, for soft shadows (default: the scene's)",
     .min = 0,
     .max = 89,
     .nullable = true,
     .control_max = 20,
     .get = get_optional<&R::light_extent_deg>,
     .set = set_optional<&R::light_extent_deg>},
    {.key = "light_height_deg",
     .type = SettingType::number,
     .help = "Angular height in degrees of a rectangular light, for soft shadows: every light becomes a "
             "rectangle of this height and the light extent's width (default: each light's own)",
     .min = 0,
     .max = 89,
     .nullable = true,
     .control_max = 20,
     .get = get_optional<&R::light_height_deg>,
     .set = set_optional<&R::light_height_deg>},
    {.key = "soft_kernel",
     .type = SettingType::integer,
     .help = "Largest soft-shadow kernel width W in texels (tables: n_t = W²); 0: the technique's, 27, pcss 15; "
             "at most 127 for mssm4 and 111 for mssm6 (the tables' precision), 63 for pcss",
     .min = 0,
     .max = kSatKernelMax,
     .get = get_value<&R::soft_kernel>,
     .set = set_value<&R::soft_kernel>},
    {.key = "front_back_depth",
     .type = SettingType::flag,
     .help = "Moment soft shadows: the map stores the mean of the nearest front- and back-face depth (Kneiphof "
             "§4.2.3; for closed occluders)",
     .get = get_value<&R::front_back_depth>,
     .set = set_value<&R::front_back_depth>},
};

} // namespace

std::span<const SettingDeclaration> setting_declarations() { return kSettings; }

std::vector<std::string> setting_keys() { return msm::setting_keys(setting_declarations()); }

const SettingDeclaration& find_setting(std::string_view key) { return msm::find_setting(setting_declarations(), key); }

json settings_json(const RenderSettings& settings) { return msm::settings_json(setting_declarations(), settings); }

} // namespace msm::render
