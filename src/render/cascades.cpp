// How many cascades a frame's directional lights get (RenderSettings::cascades resolved).
#include "msm/render/renderer.h"
#include "msm/techniques.h"

#include <fmt/format.h>

#include <algorithm>

namespace msm::render {

std::optional<std::string> cascades_unsupported(const RenderSettings& s, const scene::Scene& scene) {
  const Technique& technique = find_rendered_technique(s.technique);
  if (scene.shadow.mode != scene::ShadowFraming::Mode::fit)
    return std::string("a shadow map framed by \"fit_scene\" or \"explicit\" (cascades follow the camera: \"fit\")");
  if (technique.soft() || msm_technique_is_area_light(technique.id)) return std::string("soft shadows");
  if (technique.scatters()) return std::string("scattering");
  const std::vector<scene::DirectionalLight>& lights = s.lights.empty() ? scene.lights : s.lights;
  if (std::ranges::any_of(lights, [](const scene::DirectionalLight& l) { return !l.sub_lights.empty(); }))
    return std::string("sub-lights");
  return std::nullopt;
}

bool one_map_too_coarse(const RenderSettings& s, const scene::Scene& scene) {
  return !scene.lights.empty() &&
         scene::shadow_texel_coverage(scene, s.width, s.height, s.shadow_size).pixels_per_texel >
             scene::kMaxPixelsPerTexel;
}

int resolved_cascades(const RenderSettings& s, const scene::Scene& scene, std::optional<bool> too_coarse) {
  const std::optional<std::string> unsupported = cascades_unsupported(s, scene);
  if (s.cascades) {
    if (*s.cascades > 1 && unsupported)
      throw RenderError(fmt::format("{} cascades with {}: the renderer draws cascaded shadow maps for the hard and "
                                    "filtered shadows of directional lights (use --cascades 1)",
                                    *s.cascades, *unsupported));
    return *s.cascades;
  }
  if (unsupported) return 1;
  return too_coarse.value_or(one_map_too_coarse(s, scene)) ? kDefaultCascades : 1;
}

scene::CascadeOptions cascade_options(const RenderSettings& s, const scene::Scene& scene) {
  scene::CascadeOptions options{.lambda = s.cascade_lambda, .stabilize = s.cascade_stabilize};
  try {
    options.count = resolved_cascades(s, scene);
  } catch (const RenderError&) { options.count = 1; }
  return options;
}

} // namespace msm::render
