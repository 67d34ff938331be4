// A cylinder of 16 flat facets on a ground under one light, for the tests of the receiver plane
// (its vertex normals are the round cylinder's, so the interpolated normal turns by up to 11.25
// degrees across a facet), and the checks those tests share.
#pragma once
#include "msm/image/image.h"
#include "msm/render/renderer.h"
#include "msm/scene/scene.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <string_view>

namespace msm::test {

inline constexpr int kFacetedCylinderObject = 1; // the ground is object 0

// The scene with `light_json` (one entry of "lights") seen from the cylinder's lit side.
inline scene::Scene faceted_cylinder_scene(std::string_view light_json) {
  return scene::load_scene_json(fmt::format(R"({{"msm_scene": 1,
    "camera": {{"position": [0.6, 1.5, 2.6], "target": [0, 0.5, 0], "fov_y_deg": 40}},
    "lights": [{}],
    "objects": [{{"primitive": {{"type": "plane", "size": [4, 4]}}}},
                {{"primitive": {{"type": "cylinder", "radius": 0.3, "height": 1.0, "segments": 16}},
                 "transform": {{"translate": [0, 0.5, 0]}}}}]}})",
                                            light_json),
                                std::filesystem::current_path(), "cylinder.json");
}

// A mask (1 = masked) of every pixel whose "object" channel is not `object`.
inline image::Image all_but_object(const image::Image& object_channel, int object) {
  image::Image mask(object_channel.width(), object_channel.height(), 1);
  for (int y = 0; y < mask.height(); ++y)
    for (int x = 0; x < mask.width(); ++x) mask.at(x, y) = object_channel.at(x, y) == float(object) ? 0.0f : 1.0f;
  return mask;
}

// The largest difference of the visibility between forward and deferred shading of `s`.
inline double forward_deferred_difference(render::Renderer& renderer, render::RenderSettings s) {
  s.deferred_shading = false;
  const image::Image forward = renderer.render(s).shadow.channel("visibility");
  s.deferred_shading = true;
  const image::Image deferred = renderer.render(s).shadow.channel("visibility");
  double worst = 0;
  for (size_t i = 0; i < forward.pixels().size(); ++i)
    worst = std::max(worst, double(std::abs(forward.pixels()[i] - deferred.pixels()[i])));
  return worst;
}

} // namespace msm::test
