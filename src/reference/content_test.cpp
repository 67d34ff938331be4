// The ray tracer on content as users bring it: the filtered ground truth on receivers whose
// interpolated normals stray from their faces and on surfaces turned away from the light,
// alpha-tested (masked) occluders, and the surface channels (n_dot_l, object) for masking.
#include <cmath>
#include <filesystem>
#include <fstream>
#include <random>
#include <string>

#include <gtest/gtest.h>

#include "msm/image/io.h"
#include "msm/reference/reference.h"
#include "msm/scene/scene.h"
#include "msm/test/temp_dir.h"

namespace {

namespace fs = std::filesystem;
using namespace msm::reference;
using msm::image::Image;

using msm::test::TempDir;

msm::scene::Scene load(const std::string& json, const fs::path& dir = ".") {
  return msm::scene::load_scene_json(json, dir, "content.json");
}

Settings filtered(int width, int height) {
  Settings s;
  s.effect = Effect::filtered;
  s.width = width;
  s.height = height;
  s.samples = 64;
  s.shadow_size = 256;
  return s;
}

// A 2 x 2 ground quad from an OBJ whose vertex normals lean by `degrees` about x (a flat face with
// an interpolated normal that strays, as exported meshes have), nothing above it, light 30 degrees
// off the vertical. The receiver plane is the triangle's, as the renderer's: the ground is lit
// everywhere, however far its normals stray (a plane from the interpolated normal cut into the
// face beyond the plane's tolerance of 0.29 degrees: partly shadowed at 2 degrees).
TEST(reference_filtered, FlatFaceWithStrayNormalsIsLit) {
  for (const double degrees : {0.1, 2.0, 10.0}) {
    SCOPED_TRACE(degrees);
    TempDir dir("msm_reference_content");
    const double a = degrees * 3.141592653589793 / 180.0;
    std::ofstream(dir.path() / "ground.obj") << "v -1 0 -1\nv 1 0 -1\nv 1 0 1\nv -1 0 1\n"
                                             << "vn 0 " << std::cos(a) << " " << std::sin(a) << "\n"
                                             << "f 4//1 3//1 2//1 1//1\n";
    const auto scene = load(R"({"msm_scene": 1, "camera": {"position": [0, 2, 0.01], "target": [0, 0, 0]},
        "light": {"towards_light": [0, 0.866, 0.5]}, "objects": [{"mesh": "ground.obj"}]})",
                            dir.path());
    const Result r = render(scene, filtered(32, 24));
    double sum = 0.0;
    int n = 0;
    for (int y = 0; y < 24; ++y)
      for (int x = 0; x < 32; ++x)
        if (r.visibility.at(x, y, 1) == 0.0f) {
          sum += r.visibility.at(x, y, 0);
          ++n;
        }
    ASSERT_GT(n, 400);
    EXPECT_EQ(sum, double(n)); // exactly lit
  }
}

// A surface turned away from the light (n . l <= 0 for its interpolated normal turned towards the
// viewer) is in its own shadow, as the renderer has it, without sampling: a thin fin lit from
// behind, with nothing else in the light's way, is 0 on the side the camera sees.
TEST(reference_filtered, SurfacesTurnedAwayFromTheLightAreInTheirOwnShadow) {
  const auto scene = load(R"({"msm_scene": 1, "camera": {"position": [0, 0.5, 3], "target": [0, 0.5, 0]},
      "light": {"towards_light": [0, 0.5, -1]},
      "objects": [{"name": "fin", "primitive": {"type": "plane", "size": [1, 1]},
                   "transform": {"rotate": [90, 0, 0], "translate": [0, 0.5, 0]},
                   "material": {"double_sided": true}}]})");
  const Result r = render(scene, filtered(32, 24));
  const int cx = 16, cy = 12; // the fin's middle
  ASSERT_EQ(r.visibility.at(cx, cy, 1), 0.0f);
  EXPECT_EQ(r.visibility.at(cx, cy, 0), 0.0f);
  EXPECT_EQ(r.visibility.at(cx, cy, 2), 0.0f); // sample_count: decided without sampling
  EXPECT_LT(r.surface.at(cx, cy, 0), 0.0f);    // n_dot_l
}

// The surface channels: n_dot_l (the cosine shade() uses) and the object index; -1 and 0 on the
// background.
TEST(reference_surface, NDotLAndObjectChannels) {
  const auto scene = load(R"({"msm_scene": 1, "camera": {"position": [0, 3, 0.01], "target": [0, 0, 0]},
      "light": {"towards_light": [0, 1, 1]},
      "objects": [{"name": "ground", "primitive": {"type": "plane", "size": [2, 2]}},
                  {"name": "box", "primitive": {"type": "box", "size": [0.5, 0.5, 0.5]},
                   "transform": {"translate": [0, 0.25, 0]}}]})");
  Settings s;
  s.width = 64;
  s.height = 48;
  const Result r = render(scene, s);
  ASSERT_EQ(r.surface.channel_names(), (std::vector<std::string>{"n_dot_l", "object"}));
  EXPECT_NEAR(r.surface.at(32, 24, 0), std::sqrt(0.5), 1e-6); // the box's top, seen from above
  EXPECT_EQ(r.surface.at(32, 24, 1), 1.0f);
  EXPECT_EQ(r.surface.at(20, 24, 1), 0.0f); // the ground beside it
  EXPECT_EQ(r.surface.at(0, 0, 1), -1.0f);  // background
  EXPECT_EQ(r.surface.at(0, 0, 0), 0.0f);
}

// An alpha-tested quad (opacity texture: opaque left half, a hole on the right; cutoff 0.5) above
// the ground, light straight down: the ground under the left half is shadowed, under the hole lit,
// in the hard and the translucent effects; the camera above sees the ground through the hole.
TEST(reference_masked, CutOutsCastNoShadowAndAreSeenThrough) {
  TempDir dir("msm_reference_content");
  Image alpha(8, 8, 1);
  for (int y = 0; y < 8; ++y)
    for (int x = 0; x < 8; ++x) alpha.at(x, y) = x < 4 ? 1.0f : 0.0f;
  msm::image::write_png(dir.path() / "alpha.png", alpha);
  // The quad and the ground, seen by this camera.
  auto cutout_scene = [&](const std::string& camera) {
    return load(R"({"msm_scene": 1, "camera": )" + camera + R"(, "light": {"towards_light": [0, 1, 0]},
      "objects": [{"name": "ground", "primitive": {"type": "plane", "size": [4, 4]}},
                  {"name": "cutout", "primitive": {"type": "plane", "size": [1, 1]},
                   "transform": {"translate": [0, 1, 0]},
                   "material": {"opacity_texture": "alpha.png", "alpha_cutoff": 0.5}}]})",
                dir.path());
  };
  const auto scene = cutout_scene(R"({"position": [0, 3, 0.01], "target": [0, 0, 0], "fov_y_deg": 40})");
  ASSERT_TRUE(scene.materials.at(scene.objects[1].material).masked());
  for (const Effect effect : {Effect::hard, Effect::translucent}) {
    SCOPED_TRACE(std::string(to_string(effect)));
    Settings s;
    s.effect = effect;
    s.width = 64;
    s.height = 64;
    const Result r = render(scene, s);
    // Pixels 20 and 44 of row 32 look at x = -0.3 and +0.3 (the quad spans [-0.5, 0.5]).
    EXPECT_EQ(r.surface.at(20, 32, 1), 1.0f) << "the opaque half is seen";
    EXPECT_EQ(r.visibility.at(20, 32, 0), 1.0f) << "and lit";
    EXPECT_EQ(r.surface.at(44, 32, 1), 0.0f) << "the ground is seen through the hole";
    EXPECT_EQ(r.visibility.at(44, 32, 0), 1.0f) << "and lit through it";
  }
  // The shadow on the ground, seen from between the quad and the ground.
  const auto below = cutout_scene(R"({"position": [0, 0.5, 0.01], "target": [0, 0, 0], "fov_y_deg": 90})");
  Settings s;
  s.width = 64;
  s.height = 64;
  const Result r = render(below, s);
  // Row 32, pixels 24 and 40 look at ground x = -0.125 and +0.125 (|x| / 0.5 = (px + 0.5 - 32) / 32).
  EXPECT_EQ(r.visibility.at(24, 32, 0), 0.0f) << "under the opaque half";
  EXPECT_EQ(r.visibility.at(40, 32, 0), 1.0f) << "under the hole";
}

} // namespace
