// The viewer's light editing (msm/viewer/lights.h): edits checked by the scene's own rules, new
// lights placed where the camera looks, the view file's lights, and, drawn by the renderer
// (Renderer::set_lights, what the viewer calls), a spot light added and moved whose shadow moves
// the other way.
#include "msm/viewer/lights.h"

#include "msm/render/renderer.h"
#include "msm/test/render_settings.h"
#include "msm/test/vulkan_test.h"
#include "msm/viewer/view_file.h"

#include <gtest/gtest.h>

#include <cstdio>
#include <filesystem>
#include <string>

namespace msm::viewer {
namespace {

// A 0.5 m box on a 6 m plane under a directional light (or the plane alone); the camera looks down
// at the box.
scene::Scene box_scene(bool with_box = true) {
  const std::string box =
      R"(, {"primitive": {"type": "box", "size": [0.5, 0.5, 0.5]}, "transform": {"translate": [0, 0.25, 0]}})";
  return scene::load_scene_json(R"({"msm_scene": 1,
    "camera": {"position": [0, 5, 3], "target": [0, 0, 0], "fov_y_deg": 40},
    "light": {"towards_light": [0.3, 1, 0.2]},
    "objects": [{"primitive": {"type": "plane", "size": [6, 6]}})" +
                                    (with_box ? box : "") + "]}",
                                std::filesystem::current_path(), "box.json");
}

std::string refusal(const scene::DeclaredLight& light, const std::string& key, const nlohmann::json& value) {
  try {
    with_light_key(light, key, value);
  } catch (const ViewError& e) { return e.what(); }
  return "(accepted)";
}

TEST(ViewerLightsTest, EditsAreCheckedByTheScenesRules) {
  const scene::DeclaredLight spot = new_light(scene::LightKind::spot, box_scene().camera);
  EXPECT_EQ(refusal(spot, "inner_cone_deg", 50),
            "/inner_cone_deg: 50 degrees is wider than outer_cone_deg 35: the inner cone (full intensity) lies "
            "within the outer one");
  EXPECT_NE(refusal(spot, "range", 0).find("/range: must be in (0, "), std::string::npos);
  EXPECT_NE(refusal(spot, "range", -2).find("/range: must be in (0, "), std::string::npos);
  EXPECT_NE(refusal(spot, "outer_cone_deg", 90).find("/outer_cone_deg: must be in (0, 90)"), std::string::npos);
  // A key of another kind: the scene's message lists the kind's own.
  EXPECT_NE(refusal(spot, "towards_light", nlohmann::json::array({0, 1, 0})).find("unknown key of a spot light"),
            std::string::npos);
  const scene::DeclaredLight wider = with_light_key(spot, "outer_cone_deg", 60);
  EXPECT_EQ(wider.local.outer_cone_deg, 60.0f);
  EXPECT_EQ(with_light_key(wider, "range", nullptr).local.range, scene::LocalLight::kInfiniteRange);
  EXPECT_THROW(moved_light(new_light(scene::LightKind::directional, box_scene().camera), {0, 1, 0}), ViewError);
}

TEST(ViewerLightsTest, NewLightsArePlacedWhereTheCameraLooks) {
  const scene::Camera camera = box_scene().camera;
  const float height = 0.5f * glm::length(camera.target - camera.position);
  const scene::DeclaredLight spot = new_light(scene::LightKind::spot, camera);
  ASSERT_EQ(spot.kind, scene::LightKind::spot);
  EXPECT_EQ(spot.local.position, camera.target + glm::vec3(0, height, 0));
  EXPECT_EQ(spot.local.direction, glm::vec3(0, -1, 0));
  // An irradiance of 3 at the target, as the default directional light's.
  EXPECT_NEAR(spot.local.irradiance_at(camera.target).x, 3.0f, 1e-4f);
  const scene::DeclaredLight point = new_light(scene::LightKind::point, camera);
  EXPECT_EQ(point.local.position, spot.local.position);
  EXPECT_NEAR(point.local.irradiance_at(camera.target).x, 3.0f, 1e-4f);
  const scene::DeclaredLight sun = new_light(scene::LightKind::directional, camera);
  EXPECT_GT(sun.directional.towards_light.y, 0.5f);
}

TEST(ViewerLightsTest, ViewFilesKeepEveryLightOnAndOff) {
  const scene::Scene scene = box_scene();
  View view = default_view("fence", scene);
  std::vector<ViewLight> lights = scene_view_lights(scene, {});
  lights.front().on = false;
  lights.push_back({moved_light(new_light(scene::LightKind::spot, scene.camera), {1, 2, 0}), true});
  view.lights = lights;
  const View back = parse_view(view_json(view).dump(), "view.json");
  ASSERT_TRUE(back.lights.has_value());
  ASSERT_EQ(back.lights->size(), 2u);
  EXPECT_FALSE(back.lights->at(0).on);
  EXPECT_EQ(back.lights->at(1).light.local.position, glm::vec3(1, 2, 0));
  EXPECT_TRUE(back.settings.lights.empty()); // the directional light is off
  scene::Scene drawn = scene;
  apply_view_lights(*back.lights, drawn);
  EXPECT_TRUE(drawn.lights.empty());
  ASSERT_EQ(drawn.local_lights.size(), 1u);
  EXPECT_EQ(drawn.local_lights[0].kind, scene::LightKind::spot);
  // Entries without "type" (older files): directional lights in place of the scene's only.
  const View old = parse_view(R"({"msm_view": 1, "lights": [{"towards_light": [0, 1, 0]}]})", "old.json");
  EXPECT_FALSE(old.lights.has_value());
  EXPECT_EQ(old.settings.lights.size(), 1u);
  EXPECT_THROW(parse_view(R"({"msm_view": 1, "lights": [{"type": "spot", "position": [0, 1, 0], "direction": [0, -1, 0],
                              "inner_cone_deg": 40, "outer_cone_deg": 30}]})",
                          "bad.json"),
               ViewError);
}

class ViewerLightsRenderTest : public vk::test::VulkanTest {};

constexpr int kWidth = 160, kHeight = 120;

// The mean image column of the box's shadow, the pixels of visibility below one half that the
// lights reach without the box (inside a spot's cone), and their count.
std::pair<double, int> shadow_centroid(const render::RenderResult& r, const render::RenderResult& without_box) {
  const image::Image visibility = r.shadow.channel("visibility"), reached = without_box.shadow.channel("visibility");
  double sum = 0;
  int count = 0;
  for (int y = 0; y < kHeight; ++y)
    for (int x = 0; x < kWidth; ++x)
      if (visibility.at(x, y) < 0.5f && reached.at(x, y) >= 0.5f) sum += x, ++count;
  return {count > 0 ? sum / count : 0.0, count};
}

TEST_F(ViewerLightsRenderTest, AMovedSpotLightMovesTheShadowTheOtherWay) {
  const scene::Scene scene = box_scene();
  ASSERT_EQ(scene.lights.size(), 1u);
  render::Renderer renderer(ctx(), scene), plane(ctx(), box_scene(false));
  std::vector<ViewLight> lights = scene_view_lights(scene, {});
  lights.front().on = false;
  lights.push_back({new_light(scene::LightKind::spot, scene.camera), true});
  render::RenderSettings s = test::render_settings("pcf", kWidth, kHeight, 256);
  ASSERT_EQ(s.lights.size(), 0u);
  const auto draw = [&] {
    const DrawnLights drawn = drawn_lights(lights);
    renderer.set_lights(drawn.directional, drawn.local);
    plane.set_lights(drawn.directional, drawn.local);
    return shadow_centroid(renderer.render(s), plane.render(s));
  };
  const auto [above, shadowed_above] = draw();
  lights.back().light = moved_light(lights.back().light, lights.back().light.local.position + glm::vec3(1, 0, 0));
  const auto [beside, shadowed_beside] = draw();
  std::printf("the box's shadow: %d pixels, mean column %.2f with the spot above it; %d, %.2f 1 m to +x\n",
              shadowed_above, above, shadowed_beside, beside);
  // Straight above the box, its shadow is a thin rim around it; 1 m to +x, a band on its -x side.
  EXPECT_GT(shadowed_above, 20);
  EXPECT_GT(shadowed_beside, shadowed_above);
  EXPECT_LT(beside, above - 3.0) << "the shadow's centroid, column " << above << " then " << beside;
  // The renderer's refusal of a kind it does not draw leaves its lights as they were.
  for (const scene::LightKindInfo& kind : scene::light_kinds()) {
    if (kind.rendered) continue;
    std::vector<ViewLight> refused = lights;
    refused.push_back({new_light(kind.kind, scene.camera), true});
    const DrawnLights drawn = drawn_lights(refused);
    EXPECT_THROW(renderer.set_lights(drawn.directional, drawn.local), render::RenderError) << kind.name;
    const auto [again, shadowed_again] = shadow_centroid(renderer.render(s), plane.render(s));
    EXPECT_EQ(again, beside);
    EXPECT_EQ(shadowed_again, shadowed_beside);
  }
  EXPECT_THROW(renderer.set_lights({}, {}), render::RenderError);
}

} // namespace
} // namespace msm::viewer
