#include "light_kinds.h"

#include "commands.h"

#include <fmt/format.h>

namespace msm::tool {

scene::Scene scene_under_light_kind(const scene::Scene& scene, scene::LightKind kind) {
  if (scene.lights.empty())
    throw UsageError(fmt::format("scene '{}' has no directional light to place the other kinds by", scene.name));
  scene::Scene lit = scene;
  lit.probe.reset(); // its area lights are directional lights of `lights`, replaced below
  const scene::DirectionalLight sun = scene.light();
  lit.lights.clear();
  lit.local_lights.clear();
  if (kind == scene::LightKind::directional) {
    lit.lights.push_back(sun);
    return lit;
  }
  const glm::vec3 target = scene.camera.target;
  const float distance = glm::length(scene.camera.position - target);
  scene::LocalLight light;
  light.kind = kind;
  light.position = target + distance * sun.towards_light;
  light.direction = -sun.towards_light;
  light.inner_cone_deg = 35.0f;
  light.outer_cone_deg = 40.0f;
  const scene::Bounds b = scene.bounds();
  light.range = distance + glm::length(b.max - b.min);
  light.intensity = sun.irradiance * distance * distance;
  lit.local_lights.push_back(light);
  return lit;
}

} // namespace msm::tool
