// glTF as engines use it: per-primitive materials, texture coordinates right side up, alpha
// modes, textures in files, data URIs and GLB, KHR_materials_transmission; and real models from
// Debian packages (assimp-testmodels, glmark2-data), found through CMake-configured paths.
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <numbers>
#include <random>
#include <string>
#include <vector>

#include <fmt/format.h>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "msm/scene/scene.h"
#include "msm/test/gltf_writer.h"
#include "msm/test/scene_error.h"
#include "msm/test/temp_dir.h"

namespace fs = std::filesystem;
using namespace msm::scene;
using msm::scene::testing::GltfMaterial;
using msm::scene::testing::GltfModel;
using msm::scene::testing::GltfPrimitive;
using msm::scene::testing::GltfTexture;
using msm::scene::testing::quad;
using msm::scene::testing::write_gltf;

namespace {

using msm::test::TempDir;

// 2x2 texels, all different: red top-left, green top-right, blue bottom-left, white bottom-right
// (alpha 255, 0, 255, 0 in that order: the right column is transparent).
GltfTexture corners_texture() { return {2, 2, {255, 0, 0, 255, 0, 255, 0, 0, 0, 0, 255, 255, 255, 255, 255, 0}}; }

// One quad in the y = 0 plane facing up, its material "t" textured with corners_texture().
GltfModel textured_quad() {
  GltfModel model;
  model.textures = {corners_texture()};
  model.materials = {{.name = "t", .texture = 0}};
  model.primitives.push_back(quad({0, 0, 0}, {1, 0, 0}, {0, 0, -1}, {0, 1, 0}, 0));
  return model;
}

std::string scene_json(const std::string& mesh, const std::string& material = "") {
  return R"({"msm_scene": 1, "light": {"towards_light": [0, 1, 0]}, "objects": [{"name": "m", "mesh": ")" + mesh +
         "\"" + (material.empty() ? "" : R"(, "material": )" + material) + "}]}";
}

Scene load(const TempDir& dir, const std::string& json) {
  return load_scene_json(json, dir.path(), (dir.path() / "s.json").string());
}

// The vertex of an object at a position (exactly as written).
std::size_t vertex_at(const Mesh& m, glm::vec3 p) {
  for (std::size_t i = 0; i < m.positions.size(); ++i)
    if (glm::length(m.positions[i] - p) < 1e-6f) return i;
  ADD_FAILURE() << "no vertex at " << p.x << ", " << p.y << ", " << p.z;
  return 0;
}

} // namespace

// glTF's texture coordinates are msm's (v down, row 0 on top): imported unchanged, although
// Assimp flips them on the way in. OBJ's v points up: imported as 1 - v.
TEST(GltfImport, TextureCoordinatesRightSideUp) {
  TempDir dir("msm_gltf_test");
  GltfModel model;
  model.primitives.push_back(quad({0, 1, 0}, {1, 0, 0}, {0, -1, 0}, {0, 0, 1}));
  write_gltf(dir.path() / "quad.gltf", model);
  const Mesh g = import_mesh(dir.path() / "quad.gltf");
  EXPECT_EQ(g.uvs[vertex_at(g, {0, 1, 0})], glm::vec2(0, 0)); // top-left of the quad: top-left texel
  EXPECT_EQ(g.uvs[vertex_at(g, {1, 1, 0})], glm::vec2(1, 0));
  EXPECT_EQ(g.uvs[vertex_at(g, {0, 0, 0})], glm::vec2(0, 1));

  std::ofstream(dir.path() / "quad.obj") << "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\n"
                                         << "vt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\nf 1/1 2/2 3/3 4/4\n";
  const Mesh o = import_mesh(dir.path() / "quad.obj");
  EXPECT_EQ(o.uvs[vertex_at(o, {0, 1, 0})], glm::vec2(0, 0)); // OBJ (0, 1): top-left in OBJ's convention
  EXPECT_EQ(o.uvs[vertex_at(o, {0, 0, 0})], glm::vec2(0, 1));
}

// KHR_texture_transform on the base colour texture, as engines apply it (translation * rotation *
// scale, the rotation turning u away from v; Assimp's own baking puts v off where there is a
// rotation): offset (0.25, 0.5), rotation 90 degrees, scale (0.5, 0.25) map (u, v) to
// (0.25 + 0.25 v, 0.5 - 0.5 u). Offset and scale alone: (0.5 + 0.5 u, 0.5 v).
TEST(GltfImport, TextureTransform) {
  TempDir dir("msm_gltf_test");
  for (const bool rotated : {true, false}) {
    SCOPED_TRACE(rotated);
    GltfModel model;
    model.textures = {corners_texture()};
    GltfMaterial m{.name = "t", .texture = 0};
    if (rotated) {
      m.uv_offset = {0.25f, 0.5f};
      m.uv_rotation = 1.5707963267948966f;
      m.uv_scale = {0.5f, 0.25f};
    } else {
      m.uv_offset = {0.5f, 0.0f};
      m.uv_scale = {0.5f, 0.5f};
    }
    model.materials = {m};
    model.primitives.push_back(quad({0, 1, 0}, {1, 0, 0}, {0, -1, 0}, {0, 0, 1}, 0));
    write_gltf(dir.path() / "t.gltf", model);
    const Mesh g = import_mesh(dir.path() / "t.gltf");
    const std::pair<glm::vec3, glm::vec2> expected[] = {
        {{0, 1, 0}, rotated ? glm::vec2(0.25f, 0.5f) : glm::vec2(0.5f, 0.0f)}, // uv (0, 0)
        {{1, 1, 0}, rotated ? glm::vec2(0.25f, 0.0f) : glm::vec2(1.0f, 0.0f)}, // uv (1, 0)
        {{1, 0, 0}, rotated ? glm::vec2(0.5f, 0.0f) : glm::vec2(1.0f, 0.5f)},  // uv (1, 1)
        {{0, 0, 0}, glm::vec2(0.5f, 0.5f)}}; // uv (0, 1): the same with and without the rotation
    for (const auto& [p, uv] : expected) {
      const glm::vec2 got = g.uvs[vertex_at(g, p)];
      EXPECT_NEAR(got.x, uv.x, 1e-6f) << p.x << ", " << p.y;
      EXPECT_NEAR(got.y, uv.y, 1e-6f) << p.x << ", " << p.y;
    }
  }
}

// The primitives follow the same convention: the box's front face and the cylinder's side show
// the picture's top row at their top.
TEST(GltfImport, PrimitivesTextureCoordinatesRightSideUp) {
  const Mesh box = make_box(glm::vec3(2.0f));
  EXPECT_EQ(box.uvs[vertex_at(box, {-1, 1, 1})].y, 0.0f); // front face: seen from +z, top edge v = 0
  const Mesh cylinder = make_cylinder(1.0f, 2.0f, 8, false);
  EXPECT_EQ(cylinder.uvs[vertex_at(cylinder, {1, 1, 0})].y, 0.0f);
  EXPECT_EQ(cylinder.uvs[vertex_at(cylinder, {1, -1, 0})].y, 1.0f);
}

// One mesh, two primitives of different materials: two objects, each with its own material.
TEST(GltfImport, TwoMaterialsOnOneMesh) {
  TempDir dir("msm_gltf_test");
  GltfModel model;
  model.materials = {{.name = "red", .base_color = {1, 0, 0, 1}}, {.name = "blue", .base_color = {0, 0, 1, 1}}};
  model.primitives.push_back(quad({0, 0, 0}, {1, 0, 0}, {0, 0, -1}, {0, 1, 0}, 0));
  model.primitives.push_back(quad({2, 0, 0}, {1, 0, 0}, {0, 0, -1}, {0, 1, 0}, 1));
  write_gltf(dir.path() / "two.gltf", model);
  const Scene s = load(dir, scene_json("two.gltf"));
  ASSERT_EQ(s.objects.size(), 2u);
  for (const Object& o : s.objects) {
    const Material& m = s.materials.at(o.material);
    const bool red = o.bounds.max.x < 1.5f;
    EXPECT_EQ(o.name, red ? "m/red" : "m/blue");
    EXPECT_EQ(m.name, red ? "m/red" : "m/blue");
    EXPECT_EQ(m.albedo, red ? glm::vec3(1, 0, 0) : glm::vec3(0, 0, 1));
    EXPECT_EQ(o.mesh.triangle_count(), 2u);
    EXPECT_FALSE(m.translucent());
  }
  // A material given in the scene replaces the file's: one object, as before.
  const Scene one = load(dir, scene_json("two.gltf", R"({"albedo": [0, 1, 0]})"));
  ASSERT_EQ(one.objects.size(), 1u);
  EXPECT_EQ(one.objects[0].name, "m");
  EXPECT_EQ(one.objects[0].mesh.triangle_count(), 4u);
  EXPECT_EQ(one.materials.at(one.objects[0].material).albedo, glm::vec3(0, 1, 0));
}

// Alpha modes: MASK is alpha-tested with the base colour's alpha (texture included), BLEND is a
// translucent occluder, OPAQUE ignores alpha; double-sidedness and transmission are read.
TEST(GltfImport, AlphaModesAndTransmission) {
  TempDir dir("msm_gltf_test");
  write_gltf(dir.path() / "alpha.gltf", alpha_modes_model(corners_texture()));
  const Scene s = load(dir, scene_json("alpha.gltf"));
  ASSERT_EQ(s.objects.size(), 4u);
  auto material = [&](const std::string& name) -> const Material& {
    for (const Object& o : s.objects)
      if (o.name == "m/" + name) return s.materials.at(o.material);
    throw std::runtime_error("no object m/" + name);
  };
  const Material& mask = material("mask");
  ASSERT_TRUE(mask.masked());
  EXPECT_FLOAT_EQ(mask.alpha_cutoff.value_or(-1.0f), 0.3f);
  EXPECT_FLOAT_EQ(mask.opacity, 0.9f);
  EXPECT_TRUE(mask.opacity_from_alpha);
  EXPECT_EQ(mask.opacity_texture, mask.albedo_texture);
  EXPECT_TRUE(mask.double_sided);
  EXPECT_FALSE(mask.translucent());
  // The opacity is the texture's alpha: opaque left column, transparent right column.
  const OpacityImage alpha = opacity_image(mask);
  ASSERT_EQ(alpha.width, 2);
  EXPECT_EQ(alpha.values, (std::vector<std::uint8_t>{255, 0, 255, 0}));

  const Material& blend = material("blend");
  EXPECT_FALSE(blend.masked());
  EXPECT_TRUE(blend.translucent());
  EXPECT_FLOAT_EQ(blend.opacity, 0.5f);

  const Material& opaque = material("opaque");
  EXPECT_FALSE(opaque.translucent());
  EXPECT_FALSE(opaque.masked());
  EXPECT_EQ(opaque.opacity, 1.0f);
  EXPECT_TRUE(opaque.opacity_texture.empty());

  const Material& glass = material("glass");
  EXPECT_TRUE(glass.translucent());
  EXPECT_NEAR(glass.transmission_color.r, 0.8f, 1e-6f);
  EXPECT_NEAR(glass.transmission_color.g, 0.4f, 1e-6f);
  EXPECT_NEAR(glass.transmission_color.b, 0.2f, 1e-6f);
}

// Textures as data URIs, as files beside the .gltf, and inside a GLB: the same texels, the row
// order of the picture kept (row 0 on top).
TEST(GltfImport, EmbeddedAndExternalTextures) {
  TempDir dir("msm_gltf_test");
  const GltfModel model = textured_quad();
  write_gltf(dir.path() / "data.gltf", model);
  write_gltf(dir.path() / "files.gltf", model, true);
  write_gltf(dir.path() / "binary.glb", model);
  for (const std::string name : {"data.gltf", "files.gltf", "binary.glb"}) {
    SCOPED_TRACE(name);
    const Scene s = load(dir, scene_json(name));
    ASSERT_EQ(s.objects.size(), 1u);
    const Material& m = s.materials.at(s.objects[0].material);
    const bool embedded = name != "files.gltf";
    EXPECT_EQ(m.albedo_pixels != nullptr, embedded);
    if (embedded)
      EXPECT_EQ(m.albedo_texture.string(), (dir.path() / name).string() + "#0");
    else
      EXPECT_EQ(m.albedo_texture, dir.path() / "files_0.png");
    const Image texels = albedo_image(m);
    ASSERT_EQ(texels.width, 2);
    ASSERT_EQ(texels.height, 2);
    EXPECT_EQ(texels.rgba, corners_texture().rgba);
  }
  // A missing texture file is an error naming it.
  fs::remove(dir.path() / "files_0.png");
  try {
    load(dir, scene_json("files.gltf"));
    ADD_FAILURE() << "no error for a missing texture";
  } catch (const SceneError& e) { EXPECT_NE(std::string(e.what()).find("files_0.png"), std::string::npos); }
}

// A texture that cannot be decoded names its file (or the model and the embedded texture) and
// what it is: empty, or a format msm does not read (KTX2 from KHR_texture_basisu), not only stb's
// "unknown image type".
TEST(GltfImport, UndecodableTexturesAreNamed) {
  TempDir dir("msm_gltf_test");
  const GltfModel model = textured_quad();
  write_gltf(dir.path() / "files.gltf", model, true);
  const std::string ktx2_magic = "\xABKTX 20\xBB\r\n\x1A\n" + std::string(20, '\0');
  const auto texture_error = [&](const std::string& bytes) -> std::string {
    std::ofstream(dir.path() / "files_0.png", std::ios::binary | std::ios::trunc) << bytes;
    const Scene s = load(dir, scene_json("files.gltf"));
    try {
      albedo_image(s.materials.at(s.objects[0].material));
    } catch (const SceneError& e) { return e.what(); }
    return "no error";
  };
  std::string what = texture_error("");
  EXPECT_NE(what.find("files_0.png: cannot decode the texture: the image is empty (0 bytes)"), std::string::npos)
      << what;
  what = texture_error(ktx2_magic);
  EXPECT_NE(what.find("files_0.png: cannot decode the texture: a KTX2 image, which msm does not read (PNG, JPEG"),
            std::string::npos)
      << what;
  what = texture_error("not an image at all");
  EXPECT_NE(what.find("files_0.png: cannot decode the texture: not an image msm reads (PNG, JPEG"), std::string::npos)
      << what;

  // Embedded (a data URI whose bytes are KTX2): the model, the texture's index and the format.
  write_gltf(dir.path() / "data.gltf", model);
  std::ifstream in(dir.path() / "data.gltf");
  std::string gltf((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const std::size_t at = gltf.find("data:image/png;base64,");
  ASSERT_NE(at, std::string::npos);
  const std::size_t end = gltf.find('"', at);
  gltf.replace(at, end - at, "data:image/png;base64,q0tUWCAyMLsNChoKAAAAAAAAAAAAAAAAAAAAAAAAAAA=");
  std::ofstream(dir.path() / "ktx2.gltf", std::ios::binary) << gltf;
  try {
    load(dir, scene_json("ktx2.gltf"));
    ADD_FAILURE() << "no error for an embedded KTX2 texture";
  } catch (const SceneError& e) {
    EXPECT_NE(std::string(e.what()).find("ktx2.gltf"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("cannot decode embedded texture 0"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("a KTX2 image, which msm does not read"), std::string::npos) << e.what();
  }
}

// A model of points or lines only says so (Assimp alone ends in "No meshes remaining"); lines
// beside triangles are skipped.
TEST(GltfImport, PointsAndLinesAreNotTriangles) {
  TempDir dir("msm_gltf_test");
  for (int mode : {0, 1}) {
    GltfModel model;
    GltfPrimitive p;
    p.positions = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}};
    p.indices = {0, 1, 1, 2, 2, 3};
    p.mode = mode;
    model.primitives.push_back(p);
    const fs::path file = dir.path() / fmt::format("mode{}.gltf", mode);
    write_gltf(file, model);
    try {
      import_mesh(file);
      ADD_FAILURE() << "no error for mode " << mode;
    } catch (const SceneError& e) {
      EXPECT_NE(std::string(e.what()).find("contains no triangles, only points or lines"), std::string::npos)
          << e.what();
    }
    model.primitives.push_back(quad({0, 0, 0}, {1, 0, 0}, {0, 0, -1}, {0, 1, 0}));
    write_gltf(file, model);
    EXPECT_EQ(import_mesh(file).indices.size(), 6u) << mode;
  }
}

// The JSON schema has alpha testing too.
TEST(GltfImport, AlphaCutoffInJson) {
  TempDir dir("msm_gltf_test");
  const Scene s =
      load(dir, R"({"msm_scene": 1, "light": {"towards_light": [0, 1, 0]}, "objects": [{"primitive": {"type": "box"},
               "material": {"opacity": 0.7, "alpha_cutoff": 0.5}}]})");
  const Material& m = s.materials.at(s.objects[0].material);
  ASSERT_TRUE(m.masked());
  EXPECT_FALSE(m.translucent());
  EXPECT_THROW(load(dir, R"({"msm_scene": 1, "light": {"towards_light": [0, 1, 0]}, "objects": [{"primitive":
                            {"type": "box"}, "material": {"alpha_cutoff": 1.5}}]})"),
               SceneError);
}

// Khronos samples from Debian's assimp-testmodels: the 2CylinderEngine (a GLB of many parts,
// node transforms and instances), BoxTextured as .gltf with a file, as .glb with the texture
// inside, and with a data URI. Fails when the package is missing (scripts/bootstrap.sh).
TEST(GltfImport, KhronosSamples) {
  const fs::path root = fs::path(MSM_ASSIMP_MODELS_DIR) / "glTF2";
  const fs::path engine = root / "2CylinderEngine-glTF-Binary/2CylinderEngine.glb";
  ASSERT_TRUE(fs::exists(engine)) << engine << " is missing: install assimp-testmodels (scripts/bootstrap.sh)";
  const std::string json = R"({"msm_scene": 1, "light": {"towards_light": [0, 1, 0]}, "objects": [{"name": "engine",
                               "mesh": ")" +
                           engine.string() + "\"}]}";
  const Scene s = load_scene_json(json, ".", "engine.json");
  EXPECT_EQ(s.triangle_count(), 110336u);
  EXPECT_GE(s.objects.size(), 2u); // one per material of the file
  for (const Object& o : s.objects) EXPECT_NE(o.material, 0u) << o.name << ": the file's material is used";

  Image first;
  for (const char* sample : {"BoxTextured-glTF/BoxTextured.gltf", "BoxTextured-glTF-Binary/BoxTextured.glb",
                             "BoxTextured-glTF-Embedded/BoxTextured.gltf"}) {
    SCOPED_TRACE(sample);
    const std::vector<ModelPart> parts = import_model(root / sample);
    ASSERT_EQ(parts.size(), 1u);
    ASSERT_TRUE(parts[0].material.has_value());
    const Image texels = albedo_image(*parts[0].material);
    ASSERT_GT(texels.width, 0);
    if (first.width == 0) first = texels;
    EXPECT_EQ(texels.rgba, first.rgba); // the same picture, wherever it is stored
    EXPECT_EQ(parts[0].mesh.triangle_count(), 12u);
  }
}

// Formats without materials (OFF, PLY, OBJ without .mtl): Assimp invents one; the part keeps the
// scene's default material.
TEST(GltfImport, FormatsWithoutMaterialsKeepTheDefault) {
  TempDir dir("msm_gltf_test");
  std::ofstream(dir.path() / "t.off") << "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n";
  std::ofstream(dir.path() / "t.ply") << "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\n"
                                         "property float y\nproperty float z\nelement face 1\n"
                                         "property list uchar int vertex_indices\nend_header\n0 0 0\n1 0 0\n"
                                         "0 1 0\n3 0 1 2\n";
  std::ofstream(dir.path() / "t.obj") << "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n";
  for (const char* name : {"t.off", "t.ply", "t.obj"}) {
    const std::vector<ModelPart> parts = import_model(dir.path() / name);
    ASSERT_EQ(parts.size(), 1u) << name;
    EXPECT_FALSE(parts[0].material.has_value()) << name;
  }
}

// glmark2-data's Stanford bunny: one part, no material of its own (the scene's default).
TEST(GltfImport, BunnyHasNoMaterial) {
  const fs::path bunny = fs::path(MSM_GLMARK2_MODELS_DIR) / "bunny.obj";
  ASSERT_TRUE(fs::exists(bunny)) << bunny << " is missing: install glmark2-data (scripts/bootstrap.sh)";
  const std::vector<ModelPart> parts = import_model(bunny);
  ASSERT_EQ(parts.size(), 1u);
  EXPECT_FALSE(parts[0].material.has_value());
}

// ---------------------------------------------------------------------------------------------
// KHR_lights_punctual: an object's "import_lights" adds its glTF file's lights, placed by the
// file's nodes and then the object's transform.

namespace {

// Adds the extension's `lights` to a written .gltf and each of `nodes` as a root of its scene.
void add_lights(const fs::path& file, const nlohmann::json& lights, const std::vector<nlohmann::json>& nodes) {
  nlohmann::json j = nlohmann::json::parse(std::ifstream(file));
  j["extensionsUsed"].push_back("KHR_lights_punctual");
  j["extensions"]["KHR_lights_punctual"]["lights"] = lights;
  for (const nlohmann::json& node : nodes) {
    j["nodes"].push_back(node);
    j["scenes"][0]["nodes"].push_back(j["nodes"].size() - 1);
  }
  std::ofstream(file) << j.dump();
}

void write_quad(const fs::path& file) {
  GltfModel model;
  model.primitives.push_back(quad({0, 0, 0}, {1, 0, 0}, {0, 0, -1}, {0, 1, 0}));
  write_gltf(file, model);
}

std::string lights_scene(const std::string& object_extra, const std::string& lights = "") {
  return R"({"msm_scene": 1, )" + lights +
         R"("objects": [{"name": "lamp", "mesh": "lamp.gltf", "import_lights": true)" + object_extra + "}]}";
}

const double kSqrtHalf = std::sqrt(0.5);

} // namespace

TEST(GltfLights, ImportedWithTheNodeHierarchyAndTheObjectTransform) {
  TempDir dir("msm_gltf_test");
  write_quad(dir.path() / "lamp.gltf");
  const nlohmann::json lights = {{{"type", "spot"},
                                  {"name", "desk"},
                                  {"color", {1.0, 0.5, 0.25}},
                                  {"intensity", 8.0},
                                  {"range", 10.0},
                                  {"spot", {{"innerConeAngle", 0.2}, {"outerConeAngle", 0.5}}}},
                                 {{"type", "point"}, {"intensity", 3.0}},
                                 {{"type", "directional"}, {"color", {0.5, 0.5, 0.5}}, {"intensity", 2.0}}};
  // The spot on a child (0, 1, 0) of a node at (1, 2, 3) turned 90° about +Y: at (1, 3, 3),
  // shining along -Z turned, -X. The point light at (-1, 0, 0); the sun turned -90° about +X:
  // shining down.
  add_lights(dir.path() / "lamp.gltf", lights,
             {{{"translation", {1, 2, 3}}, {"rotation", {0, kSqrtHalf, 0, kSqrtHalf}}, {"children", {4}}},
              {{"translation", {-1, 0, 0}}, {"extensions", {{"KHR_lights_punctual", {{"light", 1}}}}}},
              {{"rotation", {-kSqrtHalf, 0, 0, kSqrtHalf}}, {"extensions", {{"KHR_lights_punctual", {{"light", 2}}}}}},
              {{"translation", {0, 1, 0}}, {"extensions", {{"KHR_lights_punctual", {{"light", 0}}}}}}});
  // The last node (index 4) is the first one's child, not a root of the scene: drop it from the roots.
  {
    nlohmann::json j = nlohmann::json::parse(std::ifstream(dir.path() / "lamp.gltf"));
    j["scenes"][0]["nodes"].erase(j["scenes"][0]["nodes"].size() - 1);
    std::ofstream(dir.path() / "lamp.gltf") << j.dump();
  }
  const Scene s = load(dir, lights_scene(R"(, "transform": {"translate": [0, 0, 10], "scale": 2})"));
  ASSERT_EQ(s.lights.size(), 1u);
  ASSERT_EQ(s.local_lights.size(), 2u);
  EXPECT_NEAR(glm::distance(s.lights[0].towards_light, glm::vec3(0, 1, 0)), 0.0f, 1e-6f);
  EXPECT_EQ(s.lights[0].irradiance, glm::vec3(1.0f));
  const msm::scene::LocalLight* spot = &s.local_lights[0];
  const msm::scene::LocalLight* point = &s.local_lights[1];
  if (spot->kind != msm::scene::LightKind::spot) std::swap(spot, point);
  ASSERT_EQ(spot->kind, msm::scene::LightKind::spot);
  EXPECT_NEAR(glm::distance(spot->position, glm::vec3(2, 6, 16)), 0.0f, 1e-5f); // (1, 3, 3) × 2 + (0, 0, 10)
  EXPECT_NEAR(glm::distance(spot->direction, glm::vec3(-1, 0, 0)), 0.0f, 1e-6f);
  EXPECT_NEAR(spot->inner_cone_deg, 0.2 * 180.0 / std::numbers::pi, 1e-4);
  EXPECT_NEAR(spot->outer_cone_deg, 0.5 * 180.0 / std::numbers::pi, 1e-4);
  EXPECT_EQ(spot->intensity, glm::vec3(8, 4, 2));
  EXPECT_EQ(spot->range, 20.0f); // scaled with the object
  EXPECT_EQ(point->kind, msm::scene::LightKind::point);
  EXPECT_NEAR(glm::distance(point->position, glm::vec3(-2, 0, 10)), 0.0f, 1e-5f);
  EXPECT_EQ(point->range, msm::scene::LocalLight::kInfiniteRange);
  EXPECT_EQ(point->intensity, glm::vec3(3.0f));
}

TEST(GltfLights, BadLightsAndMisuseAreClearErrors) {
  TempDir dir("msm_gltf_test");
  const auto with_light = [&](const nlohmann::json& light) {
    write_quad(dir.path() / "lamp.gltf");
    add_lights(dir.path() / "lamp.gltf", nlohmann::json::array({light}),
               {{{"extensions", {{"KHR_lights_punctual", {{"light", 0}}}}}}});
  };
  // glTF allows an outer cone of π/2; a perspective shadow map does not.
  with_light({{"type", "spot"}, {"name", "wide"}, {"spot", {{"outerConeAngle", std::numbers::pi / 2.0}}}});
  msm::test::expect_scene_error(
      [&] { load(dir, lights_scene("")); },
      {"/objects/0/import_lights", "lamp.gltf", "light 0 ('wide')", "outer_cone_deg", "(0, 90)"});
  with_light({{"type", "spot"}, {"spot", {{"innerConeAngle", 0.6}, {"outerConeAngle", 0.5}}}});
  msm::test::expect_scene_error([&] { load(dir, lights_scene("")); }, {"inner_cone_deg", "wider"});
  with_light({{"type", "point"}, {"range", -1.0}});
  msm::test::expect_scene_error([&] { load(dir, lights_scene("")); }, {"range"});
  with_light({{"type", "area"}});
  msm::test::expect_scene_error([&] { load(dir, lights_scene("")); }, {"/objects/0/import_lights", "type 'area'"});
  // A file without lights, and no light in the scene either.
  write_quad(dir.path() / "lamp.gltf");
  msm::test::expect_scene_error([&] { load(dir, lights_scene("")); }, {"/objects", "no light"});
  EXPECT_EQ(load(dir, lights_scene("", R"("light": {"towards_light": [0, 1, 0]}, )")).lights.size(), 1u);
  // Not a glTF file; a primitive.
  std::ofstream(dir.path() / "lamp.obj") << "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n";
  msm::test::expect_scene_error(
      [&] { load(dir, R"({"msm_scene": 1, "objects": [{"mesh": "lamp.obj", "import_lights": true}]})"); },
      {"/objects/0/import_lights", "glTF"});
  msm::test::expect_scene_error(
      [&] {
        load(dir, R"({"msm_scene": 1, "light": {"towards_light": [0, 1, 0]},
                  "objects": [{"primitive": {"type": "box", "size": [1, 1, 1]}, "import_lights": true}]})");
      },
      {"/objects/0/import_lights"});
}
