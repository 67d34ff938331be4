// Animated objects in the renderer (dynamic scenes): Renderer::move_objects draws a
// frame of scene::at_frame exactly as a renderer made for that frame's scene, and as the scene
// with the object placed there by hand (its transform written out); the translucent draws are
// sorted again, and going back to frame 0 leaves nothing of the moved frame behind.
#include "msm/render/renderer.h"
#include "msm/scene/scene.h"

#include "msm/image/metrics.h"
#include "msm/test/vulkan_test.h"

#include <fmt/format.h>
#include <gtest/gtest.h>

#include <filesystem>
#include <string>

namespace msm::render {
namespace {

class MotionTest : public vk::test::VulkanTest {};

// A box turning 30° a frame about +Y through its origin and moving 0.3 a frame along +X, over a
// ground plane, and two translucent slabs: a red one turning 20° a frame and moving 0.6 a frame
// towards -X until at frame 3 it lies under a static blue one. Along the light the blue slab is
// the nearer at frame 0 and the farther at frame 3 (the order of the blended draws flips), and
// at frame 3 the two overlap in the light's view, so a stale order would blend them wrongly.
// `box` and `pane` replace the two moving objects' transforms and motions (the hand-placed frame).
std::string scene_json(const std::string& box, const std::string& pane) {
  return fmt::format(R"({{"msm_scene": 1, "camera": {{"position": [0, 4, 5], "target": [0, 0, 0]}},
    "light": {{"towards_light": [0.4, 1, 0.3], "angular_extent_deg": 6}},
    "objects": [{{"primitive": {{"type": "plane", "size": [8, 8]}}}},
      {{"name": "box", "primitive": {{"type": "box", "size": [1.6, 0.6, 0.4]}}, {}}},
      {{"name": "pane", "primitive": {{"type": "box", "size": [1, 0.05, 1]}}, {},
        "material": {{"albedo": [0.9, 0.3, 0.2], "opacity": 0.5}}}},
      {{"name": "glass", "primitive": {{"type": "box", "size": [1, 0.05, 1]}},
        "transform": {{"translate": [-0.8, 0.95, -1.2]}}, "material": {{"albedo": [0.2, 0.3, 0.9], "opacity": 0.6}}}}]}})",
                     box, pane);
}
const std::string kBox = R"("transform": {"translate": [-0.5, 1, 0]},
  "motion": {"translate": [0.3, 0, 0], "rotate": {"axis": [0, 1, 0], "angle_deg": 30}})";
const std::string kPane = R"("transform": {"translate": [1, 0.8, -1.5]},
  "motion": {"translate": [-0.6, 0, 0.1], "rotate": {"axis": [0, 1, 0], "angle_deg": 20}})";
const std::string kBoxAt3 = R"("transform": {"translate": [0.4, 1, 0], "rotate": [0, 90, 0]})";
const std::string kPaneAt3 = R"("transform": {"translate": [-0.8, 0.8, -1.2], "rotate": [0, 60, 0]})";

scene::Scene load(const std::string& json) {
  return scene::load_scene_json(json, std::filesystem::current_path(), "motion.json");
}

image::Image render(Renderer& renderer, const std::string& technique) {
  RenderSettings s;
  s.technique = technique;
  s.width = 128;
  s.height = 72;
  s.shadow_size = 256;
  return renderer.render(s).color;
}

TEST_F(MotionTest, MovedObjectsRenderAsTheFramesScene) {
  const scene::Scene scene = load(scene_json(kBox, kPane));
  const scene::Scene at3 = scene::at_frame(scene, 3), by_hand = load(scene_json(kBoxAt3, kPaneAt3));
  for (const char* technique : {"msm-hamburger-64", "mssm6", "pcf"}) {
    Renderer moving(ctx(), scene);
    const image::Image first = render(moving, technique);
    moving.move_objects(at3);
    const image::Image moved = render(moving, technique);
    Renderer fresh(ctx(), at3), placed(ctx(), by_hand);
    const double same = image::compute_metrics(moved, render(fresh, technique)).mae;
    const double hand = image::compute_metrics(moved, render(placed, technique)).mae;
    const double change = image::compute_metrics(moved, first).mae;
    moving.move_objects(scene::at_frame(scene, 0));
    const double back = image::compute_metrics(render(moving, technique), first).mae;
    fmt::print("{}: frame 3 against a renderer of frame 3 {:.2e}, against the hand-placed scene {:.2e}; against "
               "frame 0 {:.4f}; back at frame 0 {:.2e}\n",
               technique, same, hand, change, back);
    EXPECT_EQ(same, 0.0) << technique;
    EXPECT_LT(hand, 1e-4) << technique; // vertices within float rounding of each other
    EXPECT_GT(change, 0.01) << technique;
    EXPECT_EQ(back, 0.0) << technique;
  }
}

// A scene whose objects have other meshes is refused, object by object, and the renderer draws
// as before.
TEST_F(MotionTest, OtherMeshesAreRefused) {
  const scene::Scene scene = load(scene_json(kBox, kPane));
  Renderer renderer(ctx(), scene);
  const image::Image before = render(renderer, "msm-hamburger-64");
  scene::Scene other = scene;
  other.objects.pop_back();
  EXPECT_THROW(renderer.move_objects(other), RenderError);
  other = scene::at_frame(scene, 2);
  other.objects[2].mesh = scene::make_sphere(0.5f, 16, 8); // the same count of objects, another mesh
  try {
    renderer.move_objects(other);
    ADD_FAILURE() << "another mesh accepted";
  } catch (const RenderError& e) {
    EXPECT_NE(std::string(e.what()).find("object 2 ('pane')"), std::string::npos) << e.what();
  }
  EXPECT_EQ(image::compute_metrics(render(renderer, "msm-hamburger-64"), before).mae, 0.0);
}

} // namespace
} // namespace msm::render
