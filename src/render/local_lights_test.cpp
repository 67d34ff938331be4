// Spot and point lights in the renderer: the light kinds it does not draw (scene::LightKindInfo::
// rendered) are refused with a message that names them, never rendered as if they were absent.
#include "msm/render/renderer.h"
#include "msm/scene/scene.h"

#include "msm/test/vulkan_test.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <string>

namespace msm::render {
namespace {

class LocalLightsRenderTest : public vk::test::VulkanTest {};

scene::Scene scene_with_lights(const std::string& lights) {
  return scene::load_scene_json(R"({"msm_scene": 1, "lights": [)" + lights + R"(],
    "objects": [{"primitive": {"type": "plane", "size": [4, 4]}},
                {"primitive": {"type": "box", "size": [0.5, 0.5, 0.5]}, "transform": {"translate": [0, 0.5, 0]}}]})",
                                std::filesystem::current_path(), "test.json");
}

TEST_F(LocalLightsRenderTest, KindsTheRendererDoesNotDrawAreRefusedByName) {
  for (const scene::LightKindInfo& kind : scene::light_kinds()) {
    if (kind.rendered) continue;
    const std::string light = kind.kind == scene::LightKind::spot
                                  ? R"({"type": "spot", "position": [0, 3, 0], "direction": [0, -1, 0]})"
                                  : R"({"type": "point", "position": [0, 3, 0]})";
    // Alone and beside a directional light (which alone would render).
    for (const std::string& lights : {light, R"({"towards_light": [0, 1, 0]}, )" + light}) {
      const scene::Scene s = scene_with_lights(lights);
      try {
        Renderer renderer(ctx(), s);
        ADD_FAILURE() << "no RenderError for a scene with a " << kind.name << " light";
      } catch (const RenderError& e) {
        const std::string what = e.what();
        EXPECT_NE(what.find(std::string(kind.name)), std::string::npos) << what;
        EXPECT_NE(what.find("msm reference"), std::string::npos) << what;
      }
    }
  }
}

} // namespace
} // namespace msm::render
