// One scene under each light kind in turn (scene::light_kinds()), for the comparisons between kinds
// of msm bench --light-kinds and msm demo's light-kinds part: the scene's first directional light
// replaced by one light of a kind, placed where that light comes from.
#pragma once

#include "msm/scene/scene.h"

namespace msm::tool {

// The scene lit by one light of `kind` in place of all of its lights: a directional light is the
// scene's first; a spot or point light stands on that light's direction from the camera's target,
// as far from it as the camera is, with the intensity that gives the target the directional
// light's irradiance; a spot aims at the target with a 40° outer cone (35° inner). Its range ends
// past the farthest point of the scene. UsageError where the scene has no directional light.
scene::Scene scene_under_light_kind(const scene::Scene& scene, scene::LightKind kind);

} // namespace msm::tool
