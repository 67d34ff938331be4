// glTF materials in the renderer and the ray tracer: textures the right way up (an asymmetric
// texture against hand-computed pixels), two materials on one mesh, textures embedded in a GLB,
// and alpha-tested (MASK) cut-outs casting their shadow in every technique as the ray tracer
// says.
#include "msm/reference/reference.h"
#include "msm/render/renderer.h"
#include "msm/techniques.h"

#include "msm/image/metrics.h"
#include "msm/test/gltf_writer.h"
#include "msm/test/image_compare.h"
#include "msm/test/vulkan_test.h"

#include <fmt/format.h>
#include <gtest/gtest.h>

#include <filesystem>
#include <random>

namespace msm::render {
namespace {

namespace fs = std::filesystem;
using scene::testing::GltfModel;
using scene::testing::GltfTexture;
using scene::testing::quad;
using scene::testing::write_gltf;

class GltfMaterialTest : public vk::test::VulkanTest {
 protected:
  void SetUp() override {
    VulkanTest::SetUp();
    std::random_device rd;
    dir = fs::temp_directory_path() / fmt::format("msm_gltf_material_test_{}{}", rd(), rd());
    fs::create_directories(dir);
  }
  void TearDown() override {
    std::error_code ec;
    fs::remove_all(dir, ec);
    VulkanTest::TearDown();
  }
  fs::path dir;
};

// 8 x 8 texels in four 4 x 4 quadrants: red top-left, green top-right, blue bottom-left, white
// bottom-right (quadrants, so that bilinear filtering inside one returns its colour exactly).
GltfTexture quadrants() {
  GltfTexture t{8, 8, {}};
  const std::uint8_t colours[4][4] = {{255, 0, 0, 255}, {0, 255, 0, 255}, {0, 0, 255, 255}, {255, 255, 255, 255}};
  for (int y = 0; y < 8; ++y)
    for (int x = 0; x < 8; ++x) {
      const std::uint8_t* c = colours[(y / 4) * 2 + x / 4];
      t.rgba.insert(t.rgba.end(), c, c + 4);
    }
  return t;
}

constexpr int kWidth = 160, kHeight = 120;

// The pixel whose centre is nearest the projection of a world point.
glm::ivec2 pixel_of(const scene::Scene& s, glm::vec3 p) {
  const glm::vec4 c = s.camera_view_projection(float(kWidth) / kHeight) * glm::vec4(p, 1.0f);
  const glm::vec2 ndc = glm::vec2(c) / c.w;
  return glm::ivec2(glm::floor((ndc * 0.5f + 0.5f) * glm::vec2(kWidth, kHeight)));
}

// Linear RGB at a pixel of an image with channels R, G, B first.
glm::vec3 rgb(const image::Image& im, glm::ivec2 p) {
  return {im.at(p.x, p.y, 0), im.at(p.x, p.y, 1), im.at(p.x, p.y, 2)};
}

// Which of the four colours a pixel shows: a channel of the texel that is 0 is exactly 0 in the
// image (radiance = albedo x light), the others are lit (> 0.05).
std::string colour_name(glm::vec3 c) {
  const bool r = c.r > 0.05f, g = c.g > 0.05f, b = c.b > 0.05f;
  const bool zero_r = c.r == 0.0f, zero_g = c.g == 0.0f, zero_b = c.b == 0.0f;
  if (r && zero_g && zero_b) return "red";
  if (zero_r && g && zero_b) return "green";
  if (zero_r && zero_g && b) return "blue";
  if (r && g && b) return "white";
  return fmt::format("({:.3f}, {:.3f}, {:.3f})", c.r, c.g, c.b);
}

// A 2 x 2 quad facing the camera, textured with the quadrants (uv (0, 0) at its top-left corner),
// and beside it on the same mesh a second primitive of a second, untextured, material (pure
// green), in a .gltf with data URIs and in a .glb with the picture in its binary chunk. The
// renderer and the ray tracer show red at the quad's top-left, green top-right, blue bottom-left,
// white bottom-right (upside down would swap red and blue), the second primitive green.
TEST_F(GltfMaterialTest, TexturesRightWayUpInRendererAndRayTracer) {
  GltfModel model;
  model.textures = {quadrants()};
  model.materials = {{.name = "picture", .texture = 0}, {.name = "plain", .base_color = {0, 1, 0, 1}}};
  model.primitives.push_back(quad({-1.5f, 1, 0}, {2, 0, 0}, {0, -2, 0}, {0, 0, 1}, 0));
  model.primitives.push_back(quad({0.75f, 0.5f, 0}, {0.5f, 0, 0}, {0, -1, 0}, {0, 0, 1}, 1));
  for (const char* file : {"picture.gltf", "picture.glb"}) {
    SCOPED_TRACE(file);
    write_gltf(dir / file, model);
    const std::string json = fmt::format(R"({{"msm_scene": 1,
        "camera": {{"position": [0, 0, 3], "target": [0, 0, 0], "fov_y_deg": 60}},
        "light": {{"towards_light": [0, 0, 1]}}, "objects": [{{"name": "q", "mesh": "{}"}}]}})",
                                         file);
    const scene::Scene s = scene::load_scene_json(json, dir, "picture.json");
    ASSERT_EQ(s.objects.size(), 2u);
    Renderer renderer(ctx(), s);
    RenderSettings rs;
    rs.technique = "pcf";
    rs.width = kWidth;
    rs.height = kHeight;
    const image::Image raster = renderer.render(rs).color;
    reference::Settings ts;
    ts.width = kWidth;
    ts.height = kHeight;
    const image::Image traced = reference::render(s, ts).radiance;
    const std::pair<glm::vec3, const char*> expected[] = {{{-1.0f, 0.5f, 0.0f}, "red"},
                                                          {{0.0f, 0.5f, 0.0f}, "green"},
                                                          {{-1.0f, -0.5f, 0.0f}, "blue"},
                                                          {{0.0f, -0.5f, 0.0f}, "white"},
                                                          {{1.0f, 0.0f, 0.0f}, "green"}};
    for (const auto& [point, name] : expected) {
      const glm::ivec2 p = pixel_of(s, point);
      EXPECT_EQ(colour_name(rgb(raster, p)), name) << "renderer, pixel " << p.x << ", " << p.y;
      EXPECT_EQ(colour_name(rgb(traced, p)), name) << "ray tracer, pixel " << p.x << ", " << p.y;
    }
  }
}

// A 1 x 1 quad 0.5 above the ground, alpha-tested (MASK, cutoff 0.5) with a 16 x 16 alpha
// pattern: opaque in the picture's top half (v < 0.5, towards -z) and in its left quarter, a hole
// elsewhere; light straight down, camera low, looking under the quad. Hand-computed: the ground
// under the opaque far half is in shadow, under the hole in the near right part lit; the
// renderer's cut-outs are seen through. Then every technique against the ray-traced filtered
// shadow, with the bounds of the built-in scenes (ground_truth_test.cpp).
TEST_F(GltfMaterialTest, MaskCutOutsCastTheirShadowInEveryTechnique) {
  GltfTexture mask{16, 16, {}};
  for (int y = 0; y < 16; ++y)
    for (int x = 0; x < 16; ++x) {
      const bool opaque = y < 8 || x < 4;
      mask.rgba.insert(mask.rgba.end(), {200, 200, 200, std::uint8_t(opaque ? 255 : 0)});
    }
  GltfModel model;
  model.textures = {mask};
  model.materials = {
      {.name = "cutout", .texture = 0, .alpha_mode = "MASK", .alpha_cutoff = 0.5f, .double_sided = true}};
  model.primitives.push_back(quad({-0.5f, 0.5f, -0.5f}, {1, 0, 0}, {0, 0, 1}, {0, 1, 0}, 0));
  write_gltf(dir / "cutout.glb", model);
  const scene::Scene s = scene::load_scene_json(R"({"msm_scene": 1,
      "camera": {"position": [0.3, 0.3, 2.2], "target": [0, 0, -0.2], "fov_y_deg": 50},
      "light": {"towards_light": [0, 1, 0]},
      "objects": [{"name": "ground", "primitive": {"type": "plane", "size": [3, 3]}},
                  {"name": "cutout", "mesh": "cutout.glb"}]})",
                                                dir, "cutout.json");
  ASSERT_TRUE(s.materials.at(s.objects[1].material).masked());
  reference::Settings ts;
  ts.effect = reference::Effect::filtered;
  ts.width = kWidth;
  ts.height = kHeight;
  ts.shadow_size = 512;
  const reference::Result truth = reference::render(s, ts);
  const image::Image mask_image = truth.visibility.channel("background");
  const image::Image reference_visibility = truth.visibility.channel("visibility");
  // Ground points under the far (opaque) half, under the near-right hole; and the cut-out seen
  // through from the camera (below the quad, the ray meets the ground through the hole).
  const glm::ivec2 shadowed = pixel_of(s, {0.25f, 0.0f, -0.25f}), lit = pixel_of(s, {0.25f, 0.0f, 0.25f});
  EXPECT_LT(truth.visibility.at(shadowed.x, shadowed.y, 0), 0.01f);
  EXPECT_GT(truth.visibility.at(lit.x, lit.y, 0), 0.99f);

  Renderer renderer(ctx(), s);
  for (const Technique* tp : rendered_techniques()) {
    const Technique& t = *tp;
    if (msm_technique_is_area_light(t.id)) continue; // soft shadows: the area-light tests
    SCOPED_TRACE(t.name);
    RenderSettings rs;
    rs.technique = std::string(t.name);
    rs.width = kWidth;
    rs.height = kHeight;
    rs.shadow_size = 512;
    rs.mipmaps = false;
    const image::Image shadow = renderer.render(rs).shadow;
    // TMSM puts depths 0 and 1 on one point of its circle: an occluder at the map's near plane
    // over a receiver at its far plane is its known worst case (it leaks there); its error is
    // bounded below like every other.
    if (t.id != MSM_TECH_TMSM_128) { EXPECT_LT(shadow.at(shadowed.x, shadowed.y, 0), 0.1f); }
    EXPECT_GT(shadow.at(lit.x, lit.y, 0), 0.9f);
    const image::Metrics m =
        image::compute_metrics(shadow.channel("visibility"), reference_visibility, {.mask = &mask_image});
    // As on the built-in scenes: PCF within 0.012 of the ray tracer, every technique within 0.07
    // (the plain map 0.12).
    EXPECT_LT(m.mae, t.name == "pcf" ? 0.012 : t.name == "plain" ? 0.12 : 0.07);
    fmt::print("cut-out {:<26} MAE {:.4f}, leaking {:.4f}\n", t.name, m.mae, m.light_leaking);
  }
}

} // namespace
} // namespace msm::render
