// The renderer's view of the technique table (msm/cpu/techniques.h) and the validation of its
// settings.
#include "frame_config.h"
#include "msm/rectification.h"
#include "msm/render/renderer.h"
#include "msm/render/settings_schema.h"
#include "msm/techniques.h"
#include "msm/util/limits.h"

#include <cmath>
#include <fmt/format.h>

#include <limits>
#include <stdexcept>
#include <vector>

namespace msm::render {
std::vector<const Technique*> rendered_techniques() {
  std::vector<const Technique*> out;
  for (const Technique& t : techniques())
    if (t.rendered()) out.push_back(&t);
  return out;
}

const Technique& find_rendered_technique(std::string_view name) {
  std::string_view canonical = canonical_technique_name(name);
  // A technique of the table that only the CPU runs (msm techniques lists it) is known, not unknown.
  for (const Technique& t : techniques())
    if (t.name == canonical && !t.rendered())
      throw RenderError(
          fmt::format("{} runs on the CPU only (msm reconstruct -t {}); the renderer does not draw it", name, t.name));
  std::string valid;
  std::vector<std::string_view> names;
  for (const Technique* t : rendered_techniques()) {
    if (t->name == canonical) return *t;
    valid += (valid.empty() ? "" : ", ") + std::string(t->name);
    names.push_back(t->name);
  }
  throw RenderError(fmt::format("unknown technique '{}'{}; valid: {} (aliases: msm techniques)", name,
                                technique_suggestion(name, names), valid));
}

bool supports_translucency(const Technique& t) { return t.translucency; }

int RenderSettings::resolved_soft_kernel() const {
  if (soft_kernel != 0) return soft_kernel;
  const Technique& t = find_rendered_technique(technique);
  return t.area_light ? t.default_soft_kernel : kSatKernelDefault;
}

float RenderSettings::resolved_depth_bias() const {
  return depth_bias ? *depth_bias : find_rendered_technique(technique).depth_bias;
}

float RenderSettings::resolved_receiver_plane_bias(bool cascade) const {
  return receiver_plane_bias ? *receiver_plane_bias : cascade ? 1.0f : 0.0f;
}

glm::vec4 RenderSettings::parameter_vector() const {
  return msm::parameter_vector(find_rendered_technique(technique), parameters);
}

float RenderSettings::parameter(std::string_view name) const {
  return parameter_value(find_rendered_technique(technique), parameters, name);
}

void RenderSettings::set_parameter(std::string_view name, float value) {
  parameters[std::string(find_rendered_technique(technique).parameter(name).name)] = value;
}

void RenderSettings::reset_parameters() { parameters.clear(); }

std::string RenderSettings::parameter_text(std::string_view name) const {
  return find_rendered_technique(technique).parameter(name).value_text(parameter(name));
}

void RenderSettings::validate() const {
  find_rendered_technique(technique);
  // Each setting in its declared range or choices: the ranges are stated in the declarations only
  // (msm/render/settings_schema.h). The technique's parameters are checked against its own below.
  for (const SettingDeclaration& setting : setting_declarations()) {
    if (setting.type == SettingType::technique || setting.type == SettingType::parameters) continue;
    try {
      check_setting(setting, setting.get(*this));
    } catch (const SettingError& e) { throw RenderError(fmt::format("{}: {}", setting.key, e.what())); }
  }
  // What a range cannot say: rules of one setting's values, and of settings together.
  if (static_cast<long long>(width) * height > kMaxImagePixels)
    throw RenderError(fmt::format("{} x {} pixels is more than the {} allowed", width, height, kMaxImagePixels));
  if (filter_size % 2 == 0) throw RenderError(fmt::format("filter size = {} must be odd", filter_size));
  const Technique& t = find_rendered_technique(technique);
  bool nonlinear = t.nonlinear();
  if (one_pass && !*one_pass && nonlinear)
    throw RenderError(fmt::format("{} needs the one-pass filter (it stores Φ of the filtered moments)", technique));
  bool uses_one_pass = one_pass.value_or(t.one_pass_default());
  if (uses_one_pass && t.soft())
    throw RenderError(fmt::format("{} builds a summed-area table: no one-pass filter", technique));
  if (front_back_depth && !t.soft())
    throw RenderError(fmt::format("front-and-back-face depth applies to the moment soft shadows (mssm4, mssm6, "
                                  "vssm, cssm8, cssm16), not to {}",
                                  technique));
  if (soft_kernel != 0 && t.area_light && soft_kernel > t.max_soft_kernel && t.max_soft_kernel < kSatKernelMax &&
      t.recipe == Recipe::summed_area_tables)
    // Moment tables: the bias that covers their rounding (log2((2^32 - 1) / W²) bits) keeps a plane
    // of one depth reconstructible up to the row's max_soft_kernel only (soft.h).
    throw RenderError(fmt::format(
        "soft kernel = {} is outside [3, {}] for {}: its 32-bit summed-area tables keep log2((2^32 - 1) / W²) = "
        "{:.1f} bits per moment at W = {}, a rounding coarser than its moment bias covers (a plane of one depth is "
        "not reconstructed above W = {})",
        soft_kernel, t.max_soft_kernel, technique,
        std::log2(4294967295.0 / (double(soft_kernel) * double(soft_kernel))), soft_kernel, t.max_soft_kernel));
  if (soft_kernel != 0 && (soft_kernel < 3 || soft_kernel > (t.area_light ? t.max_soft_kernel : kSatKernelMax)))
    throw RenderError(fmt::format("soft kernel = {} is outside [3, {}] for {}", soft_kernel,
                                  t.area_light ? t.max_soft_kernel : kSatKernelMax, technique));
  if (uses_one_pass && (t.formats[0] == TexelFormat::none || t.formats[1] != TexelFormat::none))
    throw RenderError(fmt::format("the one-pass filter is for techniques with one moment image, not {}", technique));
  if (uses_one_pass && filter_size > kMaxOnePassTaps)
    throw RenderError(
        fmt::format("filter size = {}: the one-pass filter takes at most {} taps", filter_size, kMaxOnePassTaps));
  for (const auto& [name, value] : parameters) {
    try {
      t.parameter(name);
    } catch (const std::invalid_argument& e) { throw RenderError(e.what()); }
  }
  for (const Parameter* p : t.parameter_list())
    if (float v = parameter(p->name); !p->accepts(v))
      throw RenderError(
          fmt::format("{}: parameter {} = {} is outside {}", technique, p->name, p->value_text(v), p->range_text()));
  // The blocker estimators count the mass at the fragment's depth between δ1 and δ2.
  if (t.has_parameter("delta2") && !(parameter("delta1") <= parameter("delta2")))
    throw RenderError(fmt::format("{}: parameters need delta1 <= delta2 (got {} and {})", technique,
                                  parameter("delta1"), parameter("delta2")));
  // The blur does not guard against non-finite texels: the resolve must not make any. The warps are
  // monotone in depth, so the ends of the depth range bound every texel.
  if (!t.depth_based() && !nonlinear) {
    glm::vec4 p = parameter_vector();
    for (float depth : {0.0f, 1.0f}) {
      MsmTexel texel = msm_technique_generate(t.id, depth, p);
      for (int image = 0; image < 2; ++image) {
        TexelFormat f = t.formats[size_t(image)];
        float largest = f == TexelFormat::rg16_float || f == TexelFormat::rgba16_float ? 65504.0f
                        : f == TexelFormat::r32_float || f == TexelFormat::rg32_float || f == TexelFormat::rgba32_float
                            ? std::numeric_limits<float>::max()
                            : 0.0f; // UNORM clamps, the rest has no image
        for (int c = 0; c < 4 && largest > 0.0f; ++c) {
          float v = (image == 0 ? texel.a : texel.b)[c];
          if (!std::isfinite(v) || std::abs(v) > largest)
            throw RenderError(fmt::format("{}: parameters {},{},{},{} make moments of {} at depth {}, beyond the "
                                          "storage format's largest value {}",
                                          technique, p.x, p.y, p.z, p.w, v, depth, largest));
        }
      }
    }
  }
}

namespace {

std::uint64_t texel_bytes(TexelFormat f) {
  switch (f) {
  case TexelFormat::none: return 0;
  case TexelFormat::r32_float:
  case TexelFormat::rg16_unorm:
  case TexelFormat::rg16_float:
  case TexelFormat::r32_uint: return 4;
  case TexelFormat::rg32_float:
  case TexelFormat::rgba16_unorm:
  case TexelFormat::rgba16_float: return 8;
  case TexelFormat::rgba32_float: return 16;
  }
  return 16;
}

} // namespace

int transmittance_layers(const RenderSettings& s) {
  const Technique& t = find_rendered_technique(s.technique);
  if (!t.prefiltered_scattering()) return 1;
  const float layers = s.parameter("layers");
  return layers == 0.0f ? kDefaultTransmittanceLayers : int(layers);
}

std::uint64_t estimated_bytes(const RenderSettings& s, std::uint64_t triangles, std::size_t scene_lights) {
  const Technique& t = find_rendered_technique(s.technique);
  const std::uint64_t moment_bytes =
      (texel_bytes(t.formats[0]) + texel_bytes(t.formats[1])) * std::uint64_t(msm_technique_tiles(t.id));
  // Each cascade is a map of its own (the default, unset, counted as one: the renderer's check
  // counts the cascades it resolves).
  const std::uint64_t lights =
      (s.lights.empty() ? scene_lights : s.lights.size()) * std::uint64_t(s.cascades.value_or(1));
  // Prefiltered scattering: every light's rectified map and prefix sums (K transmittance layers),
  // shadow size² each.
  glm::ivec2 scatter = t.prefiltered_scattering() ? msm_technique_scatter_map_bytes(t.id) : glm::ivec2(0);
  scatter.y *= transmittance_layers(s);
  return triangles * limits::kRendererBytesPerTriangle +
         std::uint64_t(s.width) * std::uint64_t(s.height) * limits::kRendererBytesPerPixel +
         std::uint64_t(s.shadow_size) * std::uint64_t(s.shadow_size) * std::uint64_t(scatter.x + scatter.y) * lights +
         limits::shadow_map_bytes(std::uint64_t(s.shadow_size), lights, std::uint64_t(s.msaa), moment_bytes, s.mipmaps,
                                  s.coloured_translucency ? 3 : 1);
}

void check_limits(const RenderSettings& s, std::uint64_t triangles, std::size_t scene_lights) {
  limits::check_triangles(triangles);
  const std::size_t lights = s.lights.empty() ? scene_lights : s.lights.size();
  limits::check_bytes(fmt::format("rendering {} at {}x{} with a {}² shadow map ({}x MSAA, {} light{})", s.technique,
                                  s.width, s.height, s.shadow_size, s.msaa, lights, lights == 1 ? "" : "s"),
                      estimated_bytes(s, triangles, scene_lights));
}

} // namespace msm::render
