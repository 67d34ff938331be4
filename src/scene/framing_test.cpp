// The "fit" framing (the shadow map covers what the camera sees, not every vertex), the texel
// coverage warning, and the refusal of absurd camera depth ranges.
#include <string>

#include <gtest/gtest.h>

#include "msm/scene/scene.h"

using namespace msm::scene;

namespace {

// A 1 m box on a ground of `ground` metres, seen from 3 m away and 4 m up, looking down at the box
// (49 degrees: the view reaches 5 m beyond it) or along the ground towards the horizon.
std::string ground_scene(float ground, bool horizon, const std::string& framing = "fit") {
  const std::string target = horizon ? "[0, 3.9, -10]" : "[0, 0.5, 0]";
  return R"({"msm_scene": 1, "camera": {"position": [0, 4, 3], "target": )" + target +
         R"(, "fov_y_deg": 45, "near": 0.1, "far": 1000},
            "light": {"towards_light": [0.3, 1, 0.5]}, "shadow_map": {"framing": ")" +
         framing + R"("},
            "objects": [{"name": "ground", "primitive": {"type": "plane", "size": [)" +
         std::to_string(ground) + ", " + std::to_string(ground) + R"(]}},
                        {"name": "box", "primitive": {"type": "box", "size": [1, 1, 1]},
                         "transform": {"translate": [0, 0.5, 0]}}]})";
}

Scene load(const std::string& json) { return load_scene_json(json, ".", "framing.json"); }

glm::vec2 map_extent(const Scene& s) {
  const glm::mat4 p = s.light_projection();
  return {2.0f / std::abs(p[0][0]), 2.0f / std::abs(p[1][1])};
}

bool in_view(const glm::mat4& camera, glm::vec3 p) {
  const glm::vec4 c = camera * glm::vec4(p, 1.0f);
  return c.w > 0.0f && std::abs(c.x) <= c.w && std::abs(c.y) <= c.w && c.z >= 0.0f && c.z <= c.w;
}

} // namespace

// Every point of a surface the camera can see (an image up to kFitMaxAspect wide) maps into the
// shadow map, at a depth in [0, 1] (points checked: a barycentric grid of 153 points on every
// triangle, where inside the view frustum); every vertex over the map lies behind the near plane.
TEST(Framing, FitCoversWhatTheCameraSees) {
  for (const std::string& name : builtin_scene_names()) {
    SCOPED_TRACE(name);
    const Scene s = builtin_scene(name);
    const glm::mat4 light = s.light_view_projection(), camera = s.camera_view_projection(kFitMaxAspect);
    std::size_t checked = 0;
    for (const Object& o : s.objects)
      for (std::size_t t = 0; t < o.mesh.triangle_count(); ++t) {
        const glm::vec3 a = o.mesh.positions[o.mesh.indices[3 * t]], b = o.mesh.positions[o.mesh.indices[3 * t + 1]],
                        c = o.mesh.positions[o.mesh.indices[3 * t + 2]];
        constexpr int steps = 16;
        for (int i = 0; i <= steps; ++i)
          for (int j = 0; i + j <= steps; ++j) {
            const glm::vec3 p = a + (float(i) / steps) * (b - a) + (float(j) / steps) * (c - a);
            const glm::vec4 q = light * glm::vec4(p, 1.0f);
            const bool over_map = std::abs(q.x) <= 1.0f && std::abs(q.y) <= 1.0f;
            if (over_map && (i + j == 0 || i == steps || j == steps)) {
              EXPECT_GE(q.z, -1e-6f) << "a caster over the map in front of the near plane";
            }
            if (!in_view(camera, p)) continue;
            ++checked;
            ASSERT_TRUE(over_map) << "visible point outside the map: " << q.x << ", " << q.y;
            ASSERT_LE(q.z, 1.0f + 1e-6f);
          }
      }
    EXPECT_GT(checked, 100u);
  }
}

// A 1 m box on a 500 m ground seen from 3 m: the map spans what the camera sees (a few metres),
// not the ground (500 m); with fit_scene it spans the ground, as before.
TEST(Framing, LargeGroundKeepsTheShadow) {
  const Scene near = load(ground_scene(500.0f, false));
  const glm::vec2 e = map_extent(near);
  EXPECT_LT(std::max(e.x, e.y), 20.0f) << e.x << " x " << e.y;
  EXPECT_GT(std::min(e.x, e.y), 2.0f); // still covers the box and its shadow
  const glm::vec2 all = map_extent(load(ground_scene(500.0f, false, "fit_scene")));
  EXPECT_GT(std::max(all.x, all.y), 500.0f);
  // The box and the ground under it are inside the map.
  const glm::mat4 light = near.light_view_projection();
  for (const glm::vec3& p : near.objects[1].mesh.positions) {
    const glm::vec4 q = light * glm::vec4(p, 1.0f);
    EXPECT_LE(std::max(std::abs(q.x), std::abs(q.y)), 1.0f);
    EXPECT_GE(q.z, 0.0f);
  }
}

// Where the camera sees nothing of the scene, the fit falls back to every vertex.
TEST(Framing, CameraLookingAwayFitsEverything) {
  const Scene s = load(R"({"msm_scene": 1, "camera": {"position": [0, 2, 3], "target": [0, 5, 10]},
      "light": {"towards_light": [0, 1, 0]}, "objects": [{"primitive": {"type": "box"}}]})");
  const glm::vec2 e = map_extent(s);
  EXPECT_NEAR(e.x, 1.0f, 1e-3f);
  EXPECT_NEAR(e.y, 1.0f, 1e-3f);
}

// The warning: where a texel spans more than kMaxPixelsPerTexel pixels, and nowhere else.
TEST(Framing, CoarseTexelWarning) {
  // None of the built-in scenes at the renderer's defaults (1280x720, 1024 texels) nor at 1920x1080.
  for (const std::string& name : builtin_scene_names()) {
    SCOPED_TRACE(name);
    const Scene s = builtin_scene(name);
    const TexelCoverage c = shadow_texel_coverage(s, 1920, 1080, 1024);
    EXPECT_TRUE(c.visible);
    EXPECT_LT(c.pixels_per_texel, kMaxPixelsPerTexel);
    EXPECT_FALSE(shadow_framing_warning(s, 1280, 720, 1024).has_value());
    EXPECT_FALSE(shadow_framing_warning(s, 1920, 1080, 1024).has_value());
  }
  // The box on the 500 m ground: fine looking down, coarse looking at the horizon (the map then
  // spans hundreds of metres of visible ground) or with the map fitted to the whole ground.
  EXPECT_FALSE(shadow_framing_warning(load(ground_scene(500.0f, false)), 1280, 720, 1024).has_value());
  for (const Scene& s : {load(ground_scene(500.0f, true)), load(ground_scene(500.0f, false, "fit_scene"))}) {
    const auto w = shadow_framing_warning(s, 1280, 720, 1024);
    ASSERT_TRUE(w.has_value());
    EXPECT_NE(w->find("--shadow-size"), std::string::npos) << *w;
    EXPECT_NE(w->find("explicit"), std::string::npos) << *w;
    EXPECT_NE(w->find("cascades"), std::string::npos) << *w;
    EXPECT_GT(shadow_texel_coverage(s, 1280, 720, 1024).pixels_per_texel, kMaxPixelsPerTexel);
  }
  // The measure itself: halving the map's texel count per side doubles it; so does doubling the
  // image's height.
  const Scene fence = builtin_scene("fence");
  const double base = shadow_texel_coverage(fence, 1280, 720, 1024).pixels_per_texel;
  EXPECT_NEAR(shadow_texel_coverage(fence, 1280, 720, 512).pixels_per_texel, 2.0 * base, 1e-9 * base);
  EXPECT_NEAR(shadow_texel_coverage(fence, 2560, 1440, 1024).pixels_per_texel, 2.0 * base, 1e-9 * base);
  // A very small map warns on the built-ins too.
  EXPECT_TRUE(shadow_framing_warning(fence, 1280, 720, 64).has_value());
  // An image wider than the fit covers.
  const auto wide = shadow_framing_warning(fence, 3000, 1000, 1024);
  ASSERT_TRUE(wide.has_value());
  EXPECT_NE(wide->find("wider"), std::string::npos);
}

// An explicit framing (light straight down, the map centred on `center`, extent 2 x 2, depth range
// [-near, far] from the centre along the light) over ground_scene's 20 m ground and 1 m box.
Scene explicit_framing(const std::string& center, const std::string& depth_range = "[-10, 10]") {
  std::string json = ground_scene(20.0f, false);
  const std::string light = R"("light": {"towards_light": [0.3, 1, 0.5]})";
  json.replace(json.find(light), light.size(), R"("light": {"towards_light": [0, 1, 0]})");
  const std::string fit = R"("shadow_map": {"framing": "fit"})";
  json.replace(json.find(fit), fit.size(),
               R"("shadow_map": {"framing": "explicit", "center": )" + center +
                   R"(, "extent": [2, 2], "depth_range": )" + depth_range + "}");
  return load(json);
}

// Explicit framing that holds none of the visible receivers, or no caster: warned (naming the
// framing and what it misses); a framing around the box, and the fitted ones, not.
TEST(Framing, ExplicitFramingThatMissesTheSceneWarns) {
  // Around the box: receivers and casters.
  const Scene around = explicit_framing("[0, 0.5, 0]");
  EXPECT_TRUE(shadow_framing_misses(around, 1280, 720).empty());
  EXPECT_FALSE(shadow_framing_warning(around, 1280, 720, 1024).has_value());
  // 100 m beside the scene: nothing at all in the map.
  const Scene beside = explicit_framing("[100, 0, 100]");
  const std::vector<FramingMiss> misses = shadow_framing_misses(beside, 1280, 720);
  ASSERT_EQ(misses.size(), 1u);
  EXPECT_TRUE(misses[0].receivers);
  EXPECT_TRUE(misses[0].casters);
  const std::vector<std::string> warnings = shadow_framing_warnings(beside, 1280, 720, 1024);
  ASSERT_EQ(warnings.size(), 1u);
  EXPECT_NE(warnings[0].find("explicit shadow-map framing (center [100, 0, 100]"), std::string::npos) << warnings[0];
  EXPECT_NE(warnings[0].find("none of the visible surfaces and no shadow caster"), std::string::npos) << warnings[0];
  // On the ground 9 m away, behind the camera (it looks down at the box from z = 3): casters (the
  // ground), no visible receiver.
  const Scene behind = explicit_framing("[0, 0, 9]");
  const std::vector<FramingMiss> behind_misses = shadow_framing_misses(behind, 1280, 720);
  ASSERT_EQ(behind_misses.size(), 1u);
  EXPECT_TRUE(behind_misses[0].receivers);
  EXPECT_FALSE(behind_misses[0].casters);
  // Over the box but with a depth range ending above everything (10 m up, 1 m deep): the receivers
  // lie beyond depth 1, the map holds no caster either.
  const Scene above = explicit_framing("[0, 10, 0]", "[-0.5, 0.5]");
  const std::vector<FramingMiss> above_misses = shadow_framing_misses(above, 1280, 720);
  ASSERT_EQ(above_misses.size(), 1u);
  EXPECT_TRUE(above_misses[0].receivers);
  EXPECT_TRUE(above_misses[0].casters);
  // The fitted framings are not checked (they hold the scene by construction).
  for (const std::string& name : builtin_scene_names())
    EXPECT_TRUE(shadow_framing_misses(builtin_scene(name), 1280, 720).empty()) << name;
}

TEST(Framing, AbsurdCameraDepthRangeRefused) {
  auto with_camera = [](const std::string& camera) {
    return R"({"msm_scene": 1, "camera": )" + camera +
           R"(, "light": {"towards_light": [0, 1, 0]}, "objects": [{"primitive": {"type": "box"}}]})";
  };
  EXPECT_NO_THROW(load(with_camera(R"({"near": 0.01, "far": 10000})")));
  for (const char* camera :
       {R"({"near": 1e-30})", R"({"far": 1e30})", R"({"near": 1e-30, "far": 1e30})", R"({"near": 1e-5, "far": 1e5})"}) {
    SCOPED_TRACE(camera);
    try {
      load(with_camera(camera));
      ADD_FAILURE() << "accepted";
    } catch (const SceneError& e) { EXPECT_NE(std::string(e.what()).find("/camera/"), std::string::npos) << e.what(); }
  }
}
