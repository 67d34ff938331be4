// Tests of msm::scene: built-in scenes and their JSON files, primitives, transforms, Assimp
// import, matrices, and clear errors for bad input.
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <random>
#include <stdexcept>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "msm/light_probe.h"
#include "msm/probe/probe.h"
#include "msm/scene/scene.h"
#include "msm/test/scene_error.h"
#include "msm/test/temp_dir.h"
#include "msm/util/random.h"

namespace fs = std::filesystem;
using namespace msm::scene;

namespace {

constexpr double kPi = std::numbers::pi;

// A fresh temporary directory per test.
using msm::test::TempDir;

double signed_volume(const Mesh& m) {
  double v = 0.0;
  for (std::size_t t = 0; t < m.triangle_count(); ++t) {
    const glm::dvec3 a(m.positions[m.indices[3 * t]]), b(m.positions[m.indices[3 * t + 1]]),
        c(m.positions[m.indices[3 * t + 2]]);
    v += glm::dot(a, glm::cross(b, c)) / 6.0;
  }
  return v;
}

// Normals unit length, and every triangle wound counter-clockwise around its vertex normals.
void expect_consistent(const Mesh& m) {
  ASSERT_EQ(m.positions.size(), m.normals.size());
  ASSERT_EQ(m.positions.size(), m.uvs.size());
  ASSERT_EQ(m.indices.size() % 3, 0u);
  for (const glm::vec3& n : m.normals) ASSERT_NEAR(glm::length(n), 1.0f, 1e-5f);
  for (std::size_t t = 0; t < m.triangle_count(); ++t) {
    const std::uint32_t* i = &m.indices[3 * t];
    ASSERT_LT(std::max({i[0], i[1], i[2]}), m.positions.size());
    const glm::vec3 e = glm::cross(m.positions[i[1]] - m.positions[i[0]], m.positions[i[2]] - m.positions[i[0]]);
    ASSERT_GT(glm::dot(e, m.normals[i[0]] + m.normals[i[1]] + m.normals[i[2]]), 0.0f) << "triangle " << t;
  }
}

std::string scene_with_object(const std::string& object_json, const std::string& extra = "") {
  return R"({"msm_scene": 1, "light": {"towards_light": [0, 1, 0]}, )" + extra + R"("objects": [)" + object_json + "]}";
}

void expect_json_error(const std::string& json, std::initializer_list<std::string> fragments) {
  msm::test::expect_scene_error([&] { load_scene_json(json, fs::current_path(), "test.json"); }, fragments);
}

} // namespace

// ---------------------------------------------------------------------------------------------
// Built-in scenes

TEST(BuiltinScenes, NamesAndDefault) {
  const auto names = builtin_scene_names();
  EXPECT_EQ(names,
            (std::vector<std::string>{"fence", "railing", "stair", "column", "smoke", "models", "pillar_wall", "disc",
                                      "glass", "sky_probe", "tower", "trees", "gate", "room", "city_probe"}));
  EXPECT_EQ(default_scene_name(), "fence");
}

TEST(BuiltinScenes, LoadWithSaneBoundsAndCounts) {
  for (const std::string& name : builtin_scene_names()) {
    SCOPED_TRACE(name);
    const Scene s = builtin_scene(name);
    EXPECT_EQ(s.name, name);
    EXPECT_GE(s.objects.size(), 2u);
    EXPECT_GT(s.triangle_count(), 20u);
    EXPECT_LT(s.triangle_count(), 200000u);
    const Bounds b = s.bounds();
    ASSERT_FALSE(b.empty());
    EXPECT_NEAR(b.min.y, 0.0f, 1e-5f); // everything stands on the ground plane y = 0
    EXPECT_GT(b.max.y, 0.5f);
    EXPECT_LT(glm::length(b.size()), 100.0f);
    for (const Object& o : s.objects) {
      SCOPED_TRACE(o.name);
      expect_consistent(o.mesh);
      EXPECT_LT(o.material, s.materials.size());
    }
    EXPECT_NEAR(glm::length(s.light().towards_light), 1.0f, 1e-6f);
    EXPECT_GT(s.light().towards_light.y, 0.0f);
  }
}

TEST(BuiltinScenes, JsonFilesLoadToTheBuiltins) {
  for (const std::string& name : builtin_scene_names()) {
    SCOPED_TRACE(name);
    const Scene a = builtin_scene(name);
    const Scene b = load_scene_file(fs::path(MSM_SCENES_DIR) / (name + ".json"));
    ASSERT_EQ(a.objects.size(), b.objects.size());
    EXPECT_EQ(a.triangle_count(), b.triangle_count());
    EXPECT_EQ(a.bounds().min, b.bounds().min);
    EXPECT_EQ(a.bounds().max, b.bounds().max);
    for (std::size_t i = 0; i < a.objects.size(); ++i) {
      EXPECT_EQ(a.objects[i].name, b.objects[i].name);
      EXPECT_EQ(a.objects[i].mesh.positions, b.objects[i].mesh.positions);
      EXPECT_EQ(a.objects[i].mesh.indices, b.objects[i].mesh.indices);
    }
    EXPECT_EQ(a.camera.position, b.camera.position);
    EXPECT_EQ(a.light().towards_light, b.light().towards_light);
    EXPECT_EQ(load_scene(name).triangle_count(), a.triangle_count()); // by name
  }
}

TEST(BuiltinScenes, StressCaseGeometry) {
  // fence: the shadows of the sign, the fence and the wall overlap (one, two or three occluders
  // in one filter kernel).
  const Scene fence = builtin_scene("fence");
  // Shadow footprints (light-space xy of each occluder's bounds) of wall, fence and sign overlap.
  const glm::mat4 lvp = fence.light_view_projection();
  auto footprint = [&](const std::string& name) {
    Bounds b;
    for (const Object& o : fence.objects)
      if (o.name.rfind(name, 0) == 0)
        for (const glm::vec3& p : o.mesh.positions) {
          const glm::vec4 c = lvp * glm::vec4(p, 1.0f);
          b.extend(glm::vec3(c.x, c.y, 0.0f));
        }
    return b;
  };
  const Bounds wall = footprint("wall"), fence_fp = footprint("fence"), sign = footprint("sign_board");
  auto overlap = [](const Bounds& a, const Bounds& b) {
    const glm::vec3 lo = glm::max(a.min, b.min), hi = glm::min(a.max, b.max);
    return std::min(hi.x - lo.x, hi.y - lo.y);
  };
  EXPECT_GT(overlap(wall, fence_fp), 0.0f);
  EXPECT_GT(overlap(fence_fp, sign), 0.0f);
  EXPECT_GT(overlap(wall, sign), 0.0f);

  // column: light at 80 degrees incidence.
  const Scene column = builtin_scene("column");
  EXPECT_NEAR(std::acos(column.light().towards_light.y) * 180.0 / kPi, 80.0, 1e-3);
  // railing: the banner is a few centimetres behind the railing.
  const Scene railing = builtin_scene("railing");
  EXPECT_LT(railing.objects[1].bounds.min.z - railing.objects[2].bounds.max.z, 0.1f);
  EXPECT_TRUE(railing.materials[railing.objects[2].material].double_sided);
}

// The soft-shadow scenes (JCGT 2017, Figs. 8, 10, 11, and the analytic disc): each has the objects
// its figure needs, placed so that the effect it stresses happens, and a light with an extent
// (column keeps extent 0: the hard-shadow tests use it; soft techniques give it one on the
// command line).
const Object& object_named(const Scene& s, const std::string& name) {
  for (const Object& o : s.objects)
    if (o.name == name) return o;
  throw std::runtime_error("no object " + name + " in " + s.name);
}

TEST(BuiltinScenes, SoftShadowScenes) {
  // models: two knots, one high above the ground (a wide penumbra) and one nearly touching it
  // (contact hardening), 5-degree light.
  const Scene models = builtin_scene("models");
  ASSERT_EQ(models.objects.size(), 3u);
  const Object& high = object_named(models, "high_knot");
  const Object& low = object_named(models, "low_knot");
  EXPECT_EQ(high.primitive, "torus_knot");
  EXPECT_EQ(low.primitive, "torus_knot");
  EXPECT_GT(high.bounds.min.y, 1.0f);
  EXPECT_GT(low.bounds.min.y, 0.01f); // hovering, not intersecting the ground
  EXPECT_LT(low.bounds.min.y, 0.1f);
  EXPECT_LT(low.bounds.max.y, high.bounds.min.y);
  EXPECT_EQ(models.light().angular_extent_deg, 5.0f);
  // The shadows fall apart: the knots' footprints along the light onto y = 0 do not overlap.
  const auto footprint = [&](const Object& o) {
    Bounds b;
    const glm::vec3 l = models.light().towards_light;
    for (const glm::vec3& p : o.mesh.positions) b.extend(p - (p.y / l.y) * l);
    return b;
  };
  const Bounds fh = footprint(high), fl = footprint(low);
  EXPECT_TRUE(fh.max.x < fl.min.x || fl.max.x < fh.min.x || fh.max.z < fl.min.z || fl.max.z < fh.min.z);

  // pillar_wall: a pillar on the ground in front of a brick wall; the light, from the front, casts
  // the pillar's shadow onto the wall's bricks.
  const Scene pw = builtin_scene("pillar_wall");
  ASSERT_EQ(pw.objects.size(), 3u);
  const Object& wall = object_named(pw, "wall");
  const Object& pillar = object_named(pw, "pillar");
  EXPECT_EQ(wall.primitive, "brick_wall");
  EXPECT_NEAR(pillar.bounds.min.y, 0.0f, 1e-6f);
  EXPECT_NEAR(wall.bounds.min.y, 0.0f, 1e-6f);
  const float gap = pillar.bounds.min.z - wall.bounds.max.z;
  EXPECT_GT(gap, 0.05f);
  EXPECT_LT(gap, 0.5f);
  EXPECT_GT(pw.light().angular_extent_deg, 0.0f);
  EXPECT_GT(pw.light().towards_light.z, 0.0f); // the wall's front faces the light
  // The pillar's top front corners, moved along the light onto the bricks' front plane, land on
  // the wall: the shadow crosses the bricks.
  const glm::vec3 travel = pw.light().travel();
  for (float x : {pillar.bounds.min.x, pillar.bounds.max.x}) {
    const glm::vec3 corner(x, pillar.bounds.max.y, pillar.bounds.max.z);
    const glm::vec3 hit = corner + ((wall.bounds.max.z - corner.z) / travel.z) * travel;
    EXPECT_GT(hit.x, wall.bounds.min.x);
    EXPECT_LT(hit.x, wall.bounds.max.x);
    EXPECT_GT(hit.y, 0.5f);
    EXPECT_LT(hit.y, wall.bounds.max.y);
  }

  // column (Fig. 11): unchanged, hard by default.
  EXPECT_EQ(builtin_scene("column").light().angular_extent_deg, 0.0f);

  // disc: a thin disc straight above the origin, the light straight down; the exact geometry is
  // checked against msm::reference::DiscOccluder in reference_test.
  const Scene disc = builtin_scene("disc");
  EXPECT_EQ(disc.light().towards_light, glm::vec3(0, 1, 0));
  EXPECT_EQ(disc.light().angular_extent_deg, 10.0f);
  const Object& occluder = object_named(disc, "disc");
  EXPECT_EQ(occluder.primitive, "cylinder");
  EXPECT_LT(occluder.bounds.size().y, 2e-4f);
  EXPECT_NEAR(occluder.bounds.size().x, 0.5f, 1e-6f);
}

// The scenes of single scattering (JCGT 2017 §5.5) carry a medium, the others none; each has
// the property its figure needs.
TEST(BuiltinScenes, ScatteringScenes) {
  const std::vector<std::string> scattering{"tower", "trees", "gate", "room"};
  for (const std::string& name : builtin_scene_names()) {
    const Scene s = builtin_scene(name);
    const bool expected = std::find(scattering.begin(), scattering.end(), name) != scattering.end();
    EXPECT_EQ(s.medium.has_value(), expected) << name;
    if (s.medium) { EXPECT_GT(s.medium->extinction, 0.0f) << name; }
  }
  const auto in_view = [](const Scene& s, glm::vec3 direction) {
    const glm::vec4 c = s.camera_view_projection(16.0f / 9.0f) * glm::vec4(s.camera.position + direction, 1.0f);
    return c.w > 0.0f && std::abs(c.x) < c.w && std::abs(c.y) < c.w;
  };
  // tower (Fig. 14): the light is in the view (the epipole), hidden behind the parapet: the ray
  // from the camera towards the light passes through the box around the merlons and pinnacles.
  const Scene tower = builtin_scene("tower");
  EXPECT_TRUE(in_view(tower, tower.light().towards_light));
  Bounds top;
  for (const Object& o : tower.objects)
    if (o.name.rfind("merlon", 0) == 0 || o.name.rfind("pinnacle", 0) == 0) top.extend(o.bounds);
  const glm::vec3 o = tower.camera.position, d = tower.light().towards_light;
  float t0 = 0.0f, t1 = 1e9f;
  for (int a = 0; a < 3; ++a) {
    float ta = (top.min[a] - o[a]) / d[a], tb = (top.max[a] - o[a]) / d[a];
    t0 = std::max(t0, std::min(ta, tb));
    t1 = std::min(t1, std::max(ta, tb));
  }
  EXPECT_LT(t0, t1) << "the view ray into the light misses the parapet";
  // trees (Fig. 16): many leaf clusters.
  int leaves = 0;
  for (const Object& x : builtin_scene("trees").objects) leaves += x.name.rfind("leaves", 0) == 0;
  EXPECT_GE(leaves, 60);
  // gate (Fig. 17): thin bars between the camera and the light.
  const Scene gate = builtin_scene("gate");
  EXPECT_LT(gate.light().towards_light.z, 0.0f);
  EXPECT_GT(gate.camera.position.z, object_named(gate, "grille").bounds.max.z);
  // room (Figs. 15, 19): the camera inside, walls 4 cm thin.
  const Scene room = builtin_scene("room");
  Bounds inside;
  for (const char* wall : {"wall_front", "wall_left", "wall_right", "wall_back_left", "wall_back_right"}) {
    const glm::vec3 size = object_named(room, wall).bounds.size();
    EXPECT_NEAR(std::min({size.x, size.y, size.z}), 0.04f, 1e-5f) << wall;
    inside.extend(object_named(room, wall).bounds);
  }
  EXPECT_TRUE(glm::all(glm::greaterThan(room.camera.position, inside.min)) &&
              glm::all(glm::lessThan(room.camera.position, inside.max)));
}

// ---------------------------------------------------------------------------------------------
// Matrices

// "fit_scene": the map covers every vertex (the "fit" framing covers what the camera sees:
// framing_test.cpp).
TEST(Matrices, LightFrustumContainsAllVerticesWithDepthInUnitRange) {
  for (const std::string& name : builtin_scene_names()) {
    SCOPED_TRACE(name);
    Scene s = builtin_scene(name);
    s.shadow.mode = ShadowFraming::Mode::fit_scene;
    const glm::mat4 m = s.light_view_projection();
    float zmin = 2.0f, zmax = -1.0f;
    for (const Object& o : s.objects)
      for (const glm::vec3& p : o.mesh.positions) {
        const glm::vec4 c = m * glm::vec4(p, 1.0f);
        ASSERT_FLOAT_EQ(c.w, 1.0f);
        ASSERT_GE(c.x, -1.0f);
        ASSERT_LE(c.x, 1.0f);
        ASSERT_GE(c.y, -1.0f);
        ASSERT_LE(c.y, 1.0f);
        ASSERT_GE(c.z, 0.0f);
        ASSERT_LE(c.z, 1.0f);
        zmin = std::min(zmin, c.z);
        zmax = std::max(zmax, c.z);
      }
    EXPECT_LT(zmin, 1e-4f); // tight: near plane at the closest vertex
    EXPECT_GT(zmax, 1.0f - 1e-4f);
    // Points nearer to the light get smaller depths.
    const glm::vec3 c = s.bounds().center();
    const float d0 = (m * glm::vec4(c, 1.0f)).z, d1 = (m * glm::vec4(c + 0.1f * s.light().towards_light, 1.0f)).z;
    EXPECT_LT(d1, d0);
  }
}

TEST(Matrices, ExplicitShadowFraming) {
  const Scene s = load_scene_json(
      scene_with_object(
          R"({"primitive": {"type": "box"}})",
          R"("shadow_map": {"framing": "explicit", "center": [0, 0, 0], "extent": [4, 2], "depth_range": [-5, 5]},)"),
      ".", "explicit.json");
  const glm::mat4 m = s.light_view_projection(); // light straight down
  const glm::vec4 c = m * glm::vec4(0.0f, 0.0f, 0.0f, 1.0f);
  EXPECT_NEAR(c.z, 0.5f, 1e-6f);
  EXPECT_NEAR((m * glm::vec4(0.0f, 5.0f, 0.0f, 1.0f)).z, 0.0f, 1e-6f); // towards the light: near
  EXPECT_NEAR((m * glm::vec4(0.0f, -5.0f, 0.0f, 1.0f)).z, 1.0f, 1e-6f);
  const glm::vec4 edge = m * glm::vec4(2.0f, 0.0f, 0.0f, 1.0f);
  const glm::vec4 edge2 = m * glm::vec4(0.0f, 0.0f, 1.0f, 1.0f);
  EXPECT_NEAR(std::max(std::abs(edge.x), std::abs(edge.y)) + std::max(std::abs(edge2.x), std::abs(edge2.y)), 2.0f,
              1e-5f);
}

TEST(Matrices, CameraUsesVulkanClipConventions) {
  const Scene s = builtin_scene("fence");
  const glm::mat4 m = s.camera_view_projection(16.0f / 9.0f);
  glm::vec4 t = m * glm::vec4(s.camera.target, 1.0f);
  t /= t.w;
  EXPECT_NEAR(t.x, 0.0f, 1e-5f);
  EXPECT_NEAR(t.y, 0.0f, 1e-5f);
  EXPECT_GT(t.z, 0.0f);
  EXPECT_LT(t.z, 1.0f);
  glm::vec4 above = m * glm::vec4(s.camera.target + 0.5f * s.camera.up, 1.0f);
  EXPECT_LT(above.y / above.w, 0.0f); // y down in NDC: up in the world is up in the image
  const glm::vec3 dir = glm::normalize(s.camera.target - s.camera.position);
  glm::vec4 n = m * glm::vec4(s.camera.position + s.camera.near * dir, 1.0f);
  glm::vec4 f = m * glm::vec4(s.camera.position + s.camera.far * dir, 1.0f);
  EXPECT_NEAR(n.z / n.w, 0.0f, 1e-5f);
  EXPECT_NEAR(f.z / f.w, 1.0f, 1e-5f);
  msm::test::expect_scene_error([&] { (void)s.camera.projection(0.0f); }, {"aspect"});
}

// ---------------------------------------------------------------------------------------------
// Primitives

TEST(Primitives, SphereAreaVolumeAndNormals) {
  const float r = 1.5f;
  const Mesh m = make_sphere(r, 64, 32);
  expect_consistent(m);
  EXPECT_NEAR(m.area() / (4.0 * kPi * r * r), 1.0, 0.01);
  EXPECT_NEAR(signed_volume(m) / (4.0 / 3.0 * kPi * r * r * r), 1.0, 0.02);
  for (std::size_t v = 0; v < m.positions.size(); ++v) {
    EXPECT_NEAR(glm::length(m.positions[v]), r, 1e-5f);
    EXPECT_GT(glm::dot(m.normals[v], m.positions[v]), 0.99f * r); // outward
  }
}

TEST(Primitives, Box) {
  const Mesh m = make_box({1.0f, 2.0f, 3.0f});
  expect_consistent(m);
  EXPECT_EQ(m.triangle_count(), 12u);
  EXPECT_NEAR(m.area(), 2.0 * (2 + 6 + 3), 1e-5);
  EXPECT_NEAR(signed_volume(m), 6.0, 1e-5);
  std::vector<glm::vec3> normals;
  for (const glm::vec3& n : m.normals)
    if (std::find(normals.begin(), normals.end(), n) == normals.end()) normals.push_back(n);
  EXPECT_EQ(normals.size(), 6u); // 6 faces
  EXPECT_EQ(m.bounds().min, glm::vec3(-0.5f, -1.0f, -1.5f));
  EXPECT_EQ(m.bounds().max, glm::vec3(0.5f, 1.0f, 1.5f));
}

TEST(Primitives, CylinderPlaneStairFenceKnot) {
  const Mesh c = make_cylinder(0.5f, 2.0f, 128, true);
  expect_consistent(c);
  EXPECT_NEAR(c.area() / (2 * kPi * 0.5 * 2.0 + 2 * kPi * 0.25), 1.0, 0.01);
  EXPECT_NEAR(signed_volume(c) / (kPi * 0.25 * 2.0), 1.0, 0.01);
  EXPECT_EQ(make_cylinder(0.5f, 2.0f, 16, false).triangle_count(), 32u);

  const Mesh p = make_plane({4.0f, 2.0f}, {3, 5});
  expect_consistent(p);
  EXPECT_EQ(p.triangle_count(), 30u);
  EXPECT_NEAR(p.area(), 8.0, 1e-5);
  for (const glm::vec3& n : p.normals) EXPECT_EQ(n, glm::vec3(0, 1, 0));

  const Mesh s = make_stair(4, 2.0f, 0.3f, 0.2f);
  expect_consistent(s);
  EXPECT_EQ(s.triangle_count(), 4u * 12u);
  EXPECT_NEAR(signed_volume(s), 2.0 * 0.3 * 0.2 * (1 + 2 + 3 + 4), 1e-5);
  EXPECT_NEAR(s.bounds().max.y, 0.8f, 1e-6f);
  EXPECT_NEAR(s.bounds().min.z, -1.2f, 1e-6f);
  EXPECT_NEAR(s.bounds().max.z, 0.0f, 1e-6f);

  const Mesh f = make_fence(4.0f, 1.0f, 9, 0.05f, 0.04f, 2, 0.06f);
  expect_consistent(f);
  EXPECT_EQ(f.triangle_count(), (9u + 2u) * 12u);
  EXPECT_NEAR(signed_volume(f), 9 * 0.05 * 0.04 * 1.0 + 2 * 4.0 * 0.06 * 0.04, 1e-5);
  EXPECT_NEAR(f.bounds().min.x, -2.0f, 1e-6f);
  EXPECT_NEAR(f.bounds().max.x, 2.0f, 1e-6f);
  EXPECT_NEAR(f.bounds().min.y, 0.0f, 1e-6f);

  const Mesh k = make_torus_knot(2, 3, 1.0f, 0.1f, 256, 16);
  expect_consistent(k);
  EXPECT_GT(signed_volume(k), 0.0); // closed, outward
}

// A 3-row, 4-column wall: a mortar core and 4 + 5 + 4 bricks (the middle row shifted by half a
// brick, with half bricks at its ends), each face where it belongs.
TEST(Primitives, BrickWall) {
  const float length = 0.24f, height = 0.07f, mortar = 0.01f, relief = 0.02f, thickness = 0.2f;
  const Mesh w = make_brick_wall(3, 4, length, height, mortar, relief, thickness);
  expect_consistent(w);
  EXPECT_EQ(w.triangle_count(), (1u + 4u + 5u + 4u) * 12u);
  const Bounds b = w.bounds();
  EXPECT_NEAR(b.min.x, -0.505f, 1e-6f);
  EXPECT_NEAR(b.max.x, 0.505f, 1e-6f);
  EXPECT_NEAR(b.min.y, 0.0f, 1e-6f);
  EXPECT_NEAR(b.max.y, 3 * 0.08f + 0.01f, 1e-6f);
  EXPECT_NEAR(b.min.z, -thickness, 1e-6f);
  EXPECT_NEAR(b.max.z, relief, 1e-6f);
  // Total brick length: 4 + 3 + 4 whole bricks and two halves of (length - mortar) / 2.
  const double bricks_length = 11 * length + (length - mortar);
  // Closed boxes: the volume is the core's plus the bricks' (which reach half-way into the core).
  EXPECT_NEAR(signed_volume(w), 1.01 * 0.25 * thickness + bricks_length * height * (relief + 0.5 * thickness), 1e-5);
  // The brick faces facing +Z lie at z = relief, and their area is the bricks' front area: no brick
  // is lost or overlaps another; the core's front (z = 0) is covered by bricks except the mortar.
  double front = 0.0, core_front = 0.0;
  for (std::size_t t = 0; t < w.triangle_count(); ++t) {
    const glm::vec3 p0 = w.positions[w.indices[3 * t]], p1 = w.positions[w.indices[3 * t + 1]],
                    p2 = w.positions[w.indices[3 * t + 2]];
    const double area = 0.5 * glm::length(glm::cross(glm::dvec3(p1 - p0), glm::dvec3(p2 - p0)));
    // Corners are centre +- half size in float: within 1e-6 of the intended planes.
    const auto on = [&](float z) {
      return std::abs(p0.z - z) < 1e-6f && std::abs(p1.z - z) < 1e-6f && std::abs(p2.z - z) < 1e-6f;
    };
    if (on(relief)) front += area;
    if (on(0.0f)) core_front += area;
  }
  EXPECT_NEAR(front, bricks_length * height, 1e-5);
  EXPECT_NEAR(core_front, 1.01 * 0.25, 1e-5);
  // Brick rows are separated by mortar: no vertex lies in a bed joint.
  for (const glm::vec3& p : w.positions) {
    if (p.z <= 0.0f) continue;
    for (int r = 0; r <= 3; ++r) EXPECT_FALSE(p.y > r * 0.08f + 1e-6f && p.y < r * 0.08f + mortar - 1e-6f) << p.y;
  }
}

TEST(Primitives, TransformsApply) {
  const Scene s = load_scene_json(scene_with_object(
                                      R"({"name": "b", "primitive": {"type": "box", "size": [1, 1, 1]},
          "transform": {"translate": [10, 0, 0], "rotate": [0, 90, 0], "scale": [2, 1, 1]}},
         {"name": "c", "primitive": {"type": "box", "size": [1, 1, 1]},
          "transform": {"translate": [10, 0, 0], "rotate": {"axis": [0, 2, 0], "angle_deg": 90}, "scale": [2, 1, 1]}},
         {"name": "d", "primitive": {"type": "sphere", "radius": 1}, "transform": {"scale": [1, 3, 1]}})"),
                                  ".", "t.json");
  const Bounds b = s.objects[0].bounds;
  EXPECT_NEAR(b.min.x, 9.5f, 1e-5f);
  EXPECT_NEAR(b.max.x, 10.5f, 1e-5f);
  EXPECT_NEAR(b.min.z, -1.0f, 1e-5f);
  EXPECT_NEAR(b.max.z, 1.0f, 1e-5f);
  for (std::size_t v = 0; v < s.objects[0].mesh.positions.size(); ++v)
    EXPECT_LT(glm::distance(s.objects[0].mesh.positions[v], s.objects[1].mesh.positions[v]), 1e-5f);
  for (const Object& o : s.objects) expect_consistent(o.mesh);
  // Non-uniform scale: normals by the inverse transpose (the ellipsoid's gradient).
  const Mesh& e = s.objects[2].mesh;
  EXPECT_NEAR(e.bounds().max.y, 3.0f, 1e-5f);
  for (std::size_t v = 0; v < e.positions.size(); ++v) {
    const glm::vec3 p = e.positions[v];
    const glm::vec3 grad = glm::normalize(glm::vec3(p.x, p.y / 9.0f, p.z));
    EXPECT_GT(glm::dot(grad, e.normals[v]), 0.9999f);
  }
}

// ---------------------------------------------------------------------------------------------
// Assimp import

TEST(Import, ObjPlyOffGltf) {
  TempDir dir("msm_scene_test");
  // OBJ: a quad (2 triangles) and a triangle, no normals.
  const fs::path obj = dir.write("m.obj", "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 2 0 0\nv 3 0 0\nv 2 1 0\n"
                                          "f 1 2 3 4\nf 5 6 7\n");
  // PLY: a tetrahedron.
  const fs::path ply =
      dir.write("m.ply", "ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\n"
                         "property float z\nelement face 4\nproperty list uchar int vertex_indices\nend_header\n"
                         "0 0 0\n1 0 0\n0 1 0\n0 0 1\n3 0 2 1\n3 0 1 3\n3 0 3 2\n3 1 2 3\n");
  // OFF: a cube of 6 quads.
  const fs::path off = dir.write("m.off", "OFF\n8 6 0\n0 0 0\n1 0 0\n1 1 0\n0 1 0\n0 0 1\n1 0 1\n1 1 1\n0 1 1\n"
                                          "4 0 3 2 1\n4 4 5 6 7\n4 0 1 5 4\n4 2 3 7 6\n4 1 2 6 5\n4 0 4 7 3\n");
  // glTF 2.0: one triangle, the buffer embedded as base64 (3 float3 positions + 3 uint16 indices).
  const std::string gltf =
      R"({"asset": {"version": "2.0"}, "scene": 0, "scenes": [{"nodes": [0]}],
          "nodes": [{"mesh": 0, "translation": [5, 0, 0]}],
          "meshes": [{"primitives": [{"attributes": {"POSITION": 1}, "indices": 0}]}],
          "buffers": [{"uri": "data:application/octet-stream;base64,AAABAAIAAAAAAAAAAAAAAAAAAAAAAIA/AAAAAAAAAAAAAAAAAACAPwAAAAA=", "byteLength": 44}],
          "bufferViews": [{"buffer": 0, "byteOffset": 0, "byteLength": 6, "target": 34963},
                          {"buffer": 0, "byteOffset": 8, "byteLength": 36, "target": 34962}],
          "accessors": [{"bufferView": 0, "componentType": 5123, "count": 3, "type": "SCALAR"},
                        {"bufferView": 1, "componentType": 5126, "count": 3, "type": "VEC3",
                         "min": [0, 0, 0], "max": [1, 1, 0]}]})";
  const fs::path gl = dir.write("m.gltf", gltf);

  const Mesh mo = import_mesh(obj);
  EXPECT_EQ(mo.triangle_count(), 3u);
  expect_consistent(mo);
  const Mesh mp = import_mesh(ply);
  EXPECT_EQ(mp.triangle_count(), 4u);
  EXPECT_EQ(import_mesh(off).triangle_count(), 12u);
  EXPECT_NEAR(import_mesh(off).area(), 6.0, 1e-5);
  const Mesh mg = import_mesh(gl);
  EXPECT_EQ(mg.triangle_count(), 1u);
  EXPECT_NEAR(mg.bounds().min.x, 5.0f, 1e-6f); // the node transform is applied
  EXPECT_NEAR(mg.area(), 0.5, 1e-6);

  // Through a scene file: path relative to the scene file, then transformed.
  fs::create_directories(dir.path() / "scenes");
  const fs::path scene =
      dir.write("scenes/s.json",
                scene_with_object(R"({"name": "m", "mesh": "../m.obj", "transform": {"translate": [0, 0, 7]}})"));
  const Scene s = load_scene_file(scene);
  EXPECT_EQ(s.name, "s"); // no "name": the file's stem
  EXPECT_EQ(s.triangle_count(), 3u);
  EXPECT_NEAR(s.bounds().min.z, 7.0f, 1e-6f);
  EXPECT_EQ(s.objects[0].mesh_file, (dir.path() / "m.obj").lexically_normal());
}

// A real model from a Debian package: the Stanford bunny of glmark2-data (69666 triangles). Its
// own vertex normals are smoothed, so a few sliver triangles at creases face slightly against
// them (measured: 1 of 69666); the generated meshes' per-triangle winding check does not apply,
// so this asserts the count, valid indices, unit normals and consistent winding on >= 99.9%.
TEST(Import, RealModel) {
  // scripts/bootstrap.sh installs glmark2-data; MSM_GLMARK2_MODELS_DIR (CMake) says where. A missing
  // model fails: a test that skips when its input is absent proves nothing.
  const fs::path bunny = fs::path(MSM_GLMARK2_MODELS_DIR) / "bunny.obj";
  ASSERT_TRUE(fs::exists(bunny)) << bunny << " is missing (install glmark2-data: scripts/bootstrap.sh does)";
  const Mesh m = import_mesh(bunny);
  ASSERT_EQ(m.triangle_count(), 69666u);
  ASSERT_EQ(m.positions.size(), m.normals.size());
  std::size_t consistent = 0;
  for (const glm::vec3& n : m.normals) ASSERT_NEAR(glm::length(n), 1.0f, 1e-5f);
  for (std::size_t t = 0; t < m.triangle_count(); ++t) {
    const std::uint32_t* i = &m.indices[3 * t];
    ASSERT_LT(std::max({i[0], i[1], i[2]}), m.positions.size());
    const glm::vec3 e = glm::cross(m.positions[i[1]] - m.positions[i[0]], m.positions[i[2]] - m.positions[i[0]]);
    consistent += glm::dot(e, m.normals[i[0]] + m.normals[i[1]] + m.normals[i[2]]) > 0.0f;
  }
  EXPECT_GE(double(consistent), 0.999 * double(m.triangle_count()));
}

// A truncated PLY (the first 40000 bytes of assimp-testmodels' Wuson.ply) trips an
// assertion inside Assimp, which Debian's build turns into abort(): the import must fail with a
// SceneError naming the file instead (import.cpp interposes Assimp's assertion handler). Cut at
// 40000 bytes the header check (mesh_header.cpp) refuses it first; cut at 400000 its vertices are
// all there and Assimp's assertion trips, as it did at 40000 before the header check.
TEST(Import, TruncatedPlyIsAnErrorNotAnAbort) {
  const fs::path wuson = fs::path(MSM_ASSIMP_MODELS_DIR) / "PLY" / "Wuson.ply";
  ASSERT_TRUE(fs::exists(wuson)) << wuson << " is missing (install assimp-testmodels: scripts/bootstrap.sh does)";
  std::ifstream in(wuson, std::ios::binary);
  std::string head(400000, '\0');
  in.read(head.data(), std::streamsize(head.size()));
  ASSERT_EQ(in.gcount(), 400000);
  TempDir dir("msm_scene_test");
  const fs::path truncated = dir.write("truncated.ply", head);
  // Caught by the check of the ASCII body (mesh_header.cpp) before Assimp reads it.
  msm::test::expect_scene_error(
      [&] { (void)import_mesh(truncated); },
      {"truncated.ply", "the PLY body ends in element 'vertex' (5314 of 11184 read; truncated?)"});
  const fs::path short_file = dir.write("short.ply", head.substr(0, 40000));
  msm::test::expect_scene_error([&] { (void)import_mesh(short_file); },
                                {"short.ply", "at least 186,408 bytes", "truncated or corrupt"});
  // The importer still works afterwards.
  EXPECT_GT(import_mesh(wuson).triangle_count(), 0u);
}

std::string fmt_vertex(const std::string& prefix, int i) {
  const double a = 0.001 * i;
  return (prefix.empty() ? "" : prefix + " ") + std::to_string(std::cos(a)) + " " + std::to_string(std::sin(a)) +
         " 0\n";
}

// Mesh files of n triangles (a fan around vertex 0) in the formats whose header or face lines
// declare their triangle count (mesh_header.cpp).
std::string fan_obj(int n) {
  std::string text;
  for (int i = 0; i <= n + 1; ++i) text += i == 0 ? "v 0 0 0\n" : fmt_vertex("v", i);
  for (int i = 1; i <= n; ++i) text += "f 1 " + std::to_string(i + 1) + " " + std::to_string(i + 2) + "\n";
  return text;
}
std::string fan_ply(int n) {
  std::string text = "ply\nformat ascii 1.0\nelement vertex " + std::to_string(n + 2) +
                     "\nproperty float x\nproperty float y\nproperty float z\nelement face " + std::to_string(n) +
                     "\nproperty list uchar int vertex_indices\nend_header\n0 0 0\n";
  for (int i = 1; i <= n + 1; ++i) text += fmt_vertex("", i);
  for (int i = 1; i <= n; ++i) text += "3 0 " + std::to_string(i) + " " + std::to_string(i + 1) + "\n";
  return text;
}
std::string fan_off(int n) {
  std::string text = "OFF\n" + std::to_string(n + 2) + " " + std::to_string(n) + " 0\n0 0 0\n";
  for (int i = 1; i <= n + 1; ++i) text += fmt_vertex("", i);
  for (int i = 1; i <= n; ++i) text += "3 0 " + std::to_string(i) + " " + std::to_string(i + 1) + "\n";
  return text;
}

// Issue 19: the total-triangle limit (msm/util/limits.h) is checked from what a mesh file
// declares, before Assimp imports (and allocates for) it; the same file imports under a limit
// one higher.
TEST(Import, TriangleLimitCheckedFromTheFileBeforeImport) {
  TempDir dir("msm_scene_test");
  const int n = 1001;
  const std::vector<fs::path> files = {dir.write("fan.obj", fan_obj(n)), dir.write("fan.ply", fan_ply(n)),
                                       dir.write("fan.off", fan_off(n))};
  ::setenv("MSM_MAX_TRIANGLES", "1000", 1);
  for (const fs::path& file : files)
    msm::test::expect_scene_error([&] { (void)import_mesh(file); }, {file.filename().string(), "declares 1,001",
                                                                     "the limit is 1,000", "MSM_MAX_TRIANGLES"});
  // glTF: a one-triangle mesh shown by 1001 nodes is 1001 triangles after PreTransformVertices.
  std::string nodes;
  for (int i = 0; i < n; ++i) nodes += std::string(i ? "," : "") + R"({"mesh":0})";
  const fs::path gltf =
      dir.write("instanced.gltf", R"({"asset":{"version":"2.0"},"nodes":[)" + nodes +
                                      R"(],"meshes":[{"primitives":[{"attributes":{"POSITION":0},"indices":1}]}],)"
                                      R"("accessors":[{"count":3},{"count":3}]})");
  msm::test::expect_scene_error([&] { (void)import_mesh(gltf); },
                                {"instanced.gltf", "declares 1,001 triangles", "the limit is 1,000"});
  ::setenv("MSM_MAX_TRIANGLES", "1001", 1);
  for (const fs::path& file : files) EXPECT_EQ(import_mesh(file).triangle_count(), std::size_t(n)) << file;
  ::unsetenv("MSM_MAX_TRIANGLES");
}

// The scene's running total is checked object by object while it loads (40 spheres of
// 4M triangles ended in std::bad_alloc after 10 GB): loading stops at the object that crosses it.
TEST(Errors, TriangleLimitStopsTheLoadAtTheObjectThatCrossesIt) {
  const std::string json = R"({"msm_scene": 1, "light": {"towards_light": [0, 1, 0]}, "objects": [
    {"name": "a", "primitive": {"type": "sphere", "segments": 64, "rings": 32}},
    {"name": "b", "primitive": {"type": "sphere", "segments": 64, "rings": 32}},
    {"name": "c", "primitive": {"type": "sphere", "segments": 64, "rings": 32}}]})";
  const std::size_t per_sphere = make_sphere(0.5f, 64, 32).triangle_count();
  ::setenv("MSM_MAX_TRIANGLES", std::to_string(2 * per_sphere + 1).c_str(), 1);
  expect_json_error(json, {"test.json", "/objects/2", "object 'c'", "the limit is", "MSM_MAX_TRIANGLES"});
  ::setenv("MSM_MAX_TRIANGLES", std::to_string(3 * per_sphere).c_str(), 1);
  EXPECT_EQ(load_scene_json(json, fs::current_path(), "test.json").triangle_count(), 3 * per_sphere);
  ::unsetenv("MSM_MAX_TRIANGLES");
}

// Found by the mesh fuzzer (tests/fuzz/crashes/mesh_import): Assimp 5.2 reads a PLY header without
// end_header forever; and headers that declare more than the file holds are truncated files.
TEST(Import, ImpossiblePlyAndOffHeadersAreErrorsNotHangs) {
  TempDir dir("msm_scene_test");
  const fs::path no_end =
      dir.write("no_end.ply", "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\n"
                              "property float y\nproperty float z\nend_headlr\n0 0 0\n1 0 0\n0 1 0\n");
  msm::test::expect_scene_error([&] { (void)import_mesh(no_end); },
                                {"no_end.ply", "no end_header", "truncated or corrupt"});
  const fs::path glued =
      dir.write("glued.ply", std::string("ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\n"
                                         "property float y\nproperty float z\nend_header\x08") +
                                 "0 0 0\n1 0 0\n0 1 0\n");
  msm::test::expect_scene_error([&] { (void)import_mesh(glued); }, {"glued.ply", "no end_header"});
  const fs::path binary_line =
      dir.write("binary_line.ply", std::string("ply\nformat ascii 1.0\nproperty list ucha\0\0\"a\"\n"
                                               "end_header\n0 0 0\n",
                                               62));
  msm::test::expect_scene_error([&] { (void)import_mesh(binary_line); },
                                {"binary_line.ply", "line 3 of the PLY header is not text"});
  const fs::path many = dir.write("many.ply", "ply\nformat binary_little_endian 1.0\nelement vertex 4000000000\n"
                                              "property float x\nproperty float y\nproperty float z\nend_header\n");
  msm::test::expect_scene_error([&] { (void)import_mesh(many); },
                                {"many.ply", "48,000,000,000 bytes", "truncated or corrupt"});
  // An ASCII body that breaks the format (Assimp read past its buffers on one: a bus error, the
  // fuzzer's find in tests/fuzz/crashes/mesh_import): a vertex line of five values for three
  // properties, a face index beyond the vertices, a word that is not a number.
  const std::string ply_head = "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
                               "property float z\nelement face 1\nproperty list uchar int vertex_index\nend_header\n";
  const fs::path extra = dir.write("extra.ply", ply_head + "0 0 0\n4 0 1 3 2\n0 1 0\n3 0 1 2\n");
  msm::test::expect_scene_error([&] { (void)import_mesh(extra); },
                                {"extra.ply", "line 2 of the PLY body has 5 values; element 'vertex' declares 3"});
  const fs::path index = dir.write("index.ply", ply_head + "0 0 0\n1 0 0\n0 1 0\n3 0 1 51\n");
  msm::test::expect_scene_error([&] { (void)import_mesh(index); }, {"index.ply", "vertex index 51 of 3 vertices"});
  const fs::path word = dir.write("word.ply", ply_head + "0 0 0\n1 0 0\n0 1 zero\n3 0 1 2\n");
  msm::test::expect_scene_error([&] { (void)import_mesh(word); },
                                {"word.ply", "line 3 of the PLY body: 'zero' is not a number"});
  EXPECT_GT(import_mesh(dir.write("good.ply", ply_head + "0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n")).triangle_count(), 0u);
  const fs::path off = dir.write("many.off", "OFF\n1000000 3 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n");
  msm::test::expect_scene_error([&] { (void)import_mesh(off); },
                                {"many.off", "1,000,000 vertices", "truncated or corrupt"});
  // A GLB whose JSON chunk, or the binary chunk after it, claims more than the file holds: Assimp
  // would allocate the claim first (4.1 GB from a file of a few hundred bytes: the fuzzer's find,
  // tests/fuzz/crashes/mesh_import). The same file with honest lengths still loads.
  auto glb = [](std::uint32_t json_claim, std::uint32_t bin_claim) {
    const std::string json = R"({"asset":{"version":"2.0"}})"; // 27 bytes, padded to 28
    auto u32 = [](std::uint32_t v) {
      return std::string{char(v & 0xff), char((v >> 8) & 0xff), char((v >> 16) & 0xff), char(v >> 24)};
    };
    const std::string body = json + " ";
    return std::string("glTF") + u32(2) + u32(20 + 28 + 8 + 4) + u32(json_claim) + "JSON" + body + u32(bin_claim) +
           std::string("BIN\0", 4) + std::string(4, '\0');
  };
  const fs::path json_claim = dir.write("json_claim.glb", glb(0xf4620100u, 4));
  msm::test::expect_scene_error([&] { (void)import_mesh(json_claim); },
                                {"json_claim.glb", "truncated GLB: its JSON chunk claims 4,100,063,488 bytes"});
  const fs::path bin_claim = dir.write("bin_claim.glb", glb(28, 0x7fffffffu));
  msm::test::expect_scene_error(
      [&] { (void)import_mesh(bin_claim); },
      {"bin_claim.glb", "truncated GLB: its binary chunk claims 2,147,483,647 bytes, the file has 4"});
  // Honest lengths: past the header check (Assimp then finds no mesh in it, a different error).
  const fs::path honest = dir.write("honest.glb", glb(28, 4));
  try {
    (void)import_mesh(honest);
  } catch (const SceneError& e) {
    EXPECT_EQ(std::string(e.what()).find("truncated GLB"), std::string::npos) << e.what();
  }
}

// ---------------------------------------------------------------------------------------------
// Textures

TEST(Textures, PathRecordedAndLoadedLazily) {
  TempDir dir("msm_scene_test");
  dir.write("t.ppm", std::string("P6\n2 1\n255\n") + std::string("\xff\x00\x00\x00\x80\xff", 6));
  const Scene s = load_scene_json(
      scene_with_object(
          R"({"primitive": {"type": "box"}, "material": {"albedo_texture": "t.ppm", "opacity": 0.5, "double_sided": true}})"),
      dir.path(), "tex.json");
  const Material& m = s.materials[s.objects[0].material];
  EXPECT_EQ(m.albedo_texture, (dir.path() / "t.ppm").lexically_normal());
  EXPECT_FLOAT_EQ(m.opacity, 0.5f);
  EXPECT_TRUE(m.double_sided);
  const Image img = load_texture(m.albedo_texture);
  ASSERT_EQ(img.width, 2);
  ASSERT_EQ(img.height, 1);
  EXPECT_EQ(img.rgba, (std::vector<std::uint8_t>{255, 0, 0, 255, 0, 128, 255, 255}));
  msm::test::expect_scene_error([&] { load_texture(dir.path() / "none.png"); }, {"none.png", "does not exist"});
  dir.write("bad.png", "not an image");
  msm::test::expect_scene_error([&] { load_texture(dir.path() / "bad.png"); }, {"bad.png", "cannot decode"});
}

TEST(Materials, TransmissionColor) {
  // Default: no transmission colour, per-channel opacity = alpha in every channel (grey shadows).
  const Scene d = load_scene_json(scene_with_object(R"({"primitive": {"type": "box"}, "material": {"opacity": 0.5}})"),
                                  fs::current_path(), "t.json");
  const Material& dm = d.materials[d.objects[0].material];
  EXPECT_EQ(dm.transmission_color, glm::vec3(0.0f));
  EXPECT_EQ(dm.channel_opacity(0.5f), glm::vec3(0.5f));
  EXPECT_EQ(dm.channel_opacity(1.0f), glm::vec3(1.0f));
  EXPECT_TRUE(dm.translucent());
  EXPECT_FALSE(Material{}.translucent());

  // Parsed, named and inline; opacity 1 with a transmission colour is still translucent.
  const Scene s = load_scene_json(
      scene_with_object(
          R"({"primitive": {"type": "box"}, "material": "glass"}, {"primitive": {"type": "box"}, "material": {"transmission_color": [0, 0.5, 1]}})",
          R"("materials": {"glass": {"opacity": 0.6, "transmission_color": [1, 0.25, 0]}},)"),
      fs::current_path(), "t.json");
  const Material& glass = s.materials[s.objects[0].material];
  EXPECT_EQ(glass.name, "glass");
  EXPECT_EQ(glass.transmission_color, glm::vec3(1.0f, 0.25f, 0.0f));
  const glm::vec3 a = glass.channel_opacity(0.6f);
  EXPECT_FLOAT_EQ(a.r, 0.0f);
  EXPECT_FLOAT_EQ(a.g, 0.45f);
  EXPECT_FLOAT_EQ(a.b, 0.6f);
  const Material& stained = s.materials[s.objects[1].material];
  EXPECT_FLOAT_EQ(stained.opacity, 1.0f);
  EXPECT_EQ(stained.transmission_color, glm::vec3(0.0f, 0.5f, 1.0f));
  EXPECT_TRUE(stained.translucent());
  Material only_blue;
  only_blue.transmission_color = {0.0f, 0.0f, 0.1f};
  EXPECT_TRUE(only_blue.translucent());
  EXPECT_EQ(only_blue.channel_opacity(0.0f), glm::vec3(0.0f));

  // Validation: each component in [0, 1], a number, exactly three of them.
  const auto with = [](const std::string& tc) {
    return scene_with_object(R"({"primitive": {"type": "box"}, "material": {"transmission_color": )" + tc + "}}");
  };
  expect_json_error(with("[0, 1.5, 0]"), {"test.json", "/objects/0/material/transmission_color/1", "[0, 1]", "1.5"});
  expect_json_error(with("[-0.1, 0, 0]"), {"/objects/0/material/transmission_color/0", "[0, 1]"});
  expect_json_error(with(R"([0, 0, "NaN"])"), {"/objects/0/material/transmission_color/2", "number"});
  expect_json_error(with("[0, 0, null]"), {"/objects/0/material/transmission_color/2", "number"});
  expect_json_error(with("[1, 1]"), {"/objects/0/material/transmission_color", "3 numbers"});
  expect_json_error(with("[1, 1, 1, 1]"), {"/objects/0/material/transmission_color", "3 numbers"});
  expect_json_error(with("0.5"), {"/objects/0/material/transmission_color", "3 numbers"});
  expect_json_error(scene_with_object(R"({"primitive": {"type": "box"}, "material": "g"})",
                                      R"("materials": {"g": {"transmission_color": [2, 0, 0]}},)"),
                    {"/materials/g/transmission_color/0", "[0, 1]"});
  expect_json_error(
      scene_with_object(R"({"primitive": {"type": "box"}, "material": {"transmission_colour": [1, 0, 0]}})"),
      {"/objects/0/material/transmission_colour", "unknown key", "transmission_color"});
}

// ---------------------------------------------------------------------------------------------
// Bad input: a SceneError naming the file, the location and the problem.

TEST(Errors, Files) {
  TempDir dir("msm_scene_test");
  msm::test::expect_scene_error([&] { load_scene_file(dir.path() / "missing.json"); },
                                {"missing.json", "does not exist"});
  msm::test::expect_scene_error([&] { load_scene_file(dir.path()); }, {"not a regular file"});
  const fs::path bad = dir.write("bad.json", R"({"msm_scene": 1, "objects": [ )");
  msm::test::expect_scene_error([&] { load_scene_file(bad); }, {"bad.json", "malformed JSON"});
  msm::test::expect_scene_error([&] { builtin_scene("nosuch"); }, {"unknown built-in scene 'nosuch'", "fence"});
  msm::test::expect_scene_error([&] { load_scene("nosuch"); }, {"nosuch", "neither a built-in scene"});
}

// A scene saved as UTF-16 (Windows editors' "Unicode"), with or without a byte-order mark, or as
// UTF-32: named as such, not "invalid literal" at a byte the terminal cannot show.
TEST(Errors, WideEncodingsAreNamed) {
  const std::string json = scene_with_object(R"({"primitive": {"type": "box"}})");
  const auto utf16 = [&](bool big_endian, bool mark) {
    std::string out = mark ? (big_endian ? std::string("\xFE\xFF") : std::string("\xFF\xFE")) : std::string();
    for (char c : json) out += big_endian ? std::string{'\0', c} : std::string{c, '\0'};
    return out;
  };
  expect_json_error(utf16(false, true),
                    {"test.json", "UTF-16 (little-endian, byte-order mark FF FE)", "save it as UTF-8"});
  expect_json_error(utf16(true, true), {"UTF-16 (big-endian, byte-order mark FE FF)"});
  expect_json_error(utf16(false, false), {"UTF-16 (little-endian, no byte-order mark)"});
  expect_json_error(utf16(true, false), {"UTF-16 (big-endian, no byte-order mark)"});
  expect_json_error(std::string("\xFF\xFE\0\0", 4) + "{", {"UTF-32 (little-endian)"});
  // UTF-8 with its mark still reads.
  EXPECT_EQ(load_scene_json("\xEF\xBB\xBF" + json, fs::current_path(), "test.json").objects.size(), 1u);
}

// Names are labels: one of 5 MB is refused at load, and the message shows 48 bytes of it, not
// the whole (nor do JSON pointers through a long key).
TEST(Errors, AbsurdNamesAreRefusedAndShortened) {
  const std::string huge(5u << 20, 'n');
  const auto check = [&](const std::string& json, std::initializer_list<std::string> fragments) {
    try {
      load_scene_json(json, fs::current_path(), "test.json");
      ADD_FAILURE() << "no SceneError";
    } catch (const SceneError& e) {
      const std::string what = e.what();
      EXPECT_LT(what.size(), 400u);
      for (const std::string& f : fragments) EXPECT_NE(what.find(f), std::string::npos) << f << " not in: " << what;
    }
  };
  check(scene_with_object(R"({"name": ")" + huge + R"(", "primitive": {"type": "box"}})"),
        {"/objects/0/name", "a name of 5242880 bytes ('nnnnnnnn", "... (5242880 bytes)", "at most 256 bytes"});
  check(scene_with_object(R"({"primitive": {"type": "box"}})", R"("name": ")" + huge + R"(",)"), {"/name"});
  check(scene_with_object(R"({"primitive": {"type": "box"}})", R"("materials": {")" + huge + R"(": {}},)"),
        {"/materials/nnnn", "at most 256 bytes"});
  check(scene_with_object(R"({"primitive": {"type": "box"}, ")" + huge + R"(": 1})"),
        {"/objects/0/nnnn", "unknown key"});
  const std::string longest(256, 'x');
  EXPECT_EQ(load_scene_json(scene_with_object(R"({"name": ")" + longest + R"(", "primitive": {"type": "box"}})"),
                            fs::current_path(), "test.json")
                .objects.front()
                .name,
            longest);
}

TEST(Errors, Structure) {
  expect_json_error("[1, 2]", {"test.json", "must be a JSON object"});
  expect_json_error(R"({"light": {"towards_light": [0,1,0]}, "objects": []})", {"/msm_scene", "required"});
  expect_json_error(R"({"msm_scene": 2, "light": {"towards_light": [0,1,0]}, "objects": []})",
                    {"/msm_scene", "version"});
  expect_json_error(R"({"msm_scene": 1, "objects": [{"primitive": {"type": "box"}}]})", {"/light", "required"});
  expect_json_error(R"({"msm_scene": 1, "light": {"towards_light": [0,1,0]}, "objects": []})",
                    {"/objects", "non-empty"});
  expect_json_error(scene_with_object(R"({"primitive": {"type": "box"}, "colour": 1})"),
                    {"/objects/0/colour", "unknown key"});
  expect_json_error(scene_with_object(R"({"name": "p", "primitive": {"type": "pyramid"}})"),
                    {"/objects/0/primitive/type", "object 'p'", "unknown primitive 'pyramid'"});
  expect_json_error(scene_with_object(R"({"name": "x"})"), {"/objects/0", "exactly one of"});
  expect_json_error(scene_with_object(R"({"primitive": {"type": "box"}, "material": "steel"})"),
                    {"unknown material 'steel'"});
  expect_json_error(
      R"({"msm_scene": 1, "light": {"towards_light": [0,0,0]}, "objects": [{"primitive": {"type": "box"}}]})",
      {"/light/towards_light", "non-zero"});
  expect_json_error(scene_with_object(R"({"primitive": {"type": "box", "size": [1, "2", 1]}})"),
                    {"/objects/0/primitive/size/1", "number"});
  expect_json_error(scene_with_object(R"({"primitive": {"type": "box"}})", R"("shadow_map": {"framing": "tight"},)"),
                    {"/shadow_map/framing", "unknown framing"});
}

TEST(Errors, Values) {
  expect_json_error(scene_with_object(R"({"name": "s", "primitive": {"type": "box"}, "transform": {"scale": -1}})"),
                    {"/objects/0/transform/scale", "object 's'", "> 0"});
  expect_json_error(scene_with_object(R"({"primitive": {"type": "box"}, "transform": {"scale": [1, 0, 1]}})"),
                    {"scale", "> 0"});
  for (const char* fov : {"0", "180", "-5", "200"})
    expect_json_error(
        scene_with_object(R"({"primitive": {"type": "box"}})", std::string(R"("camera": {"fov_y_deg": )") + fov + "},"),
        {"/camera/fov_y_deg", "(0, 180)"});
  for (const char* opacity : {"1.5", "-0.1"})
    expect_json_error(
        scene_with_object(std::string(R"({"primitive": {"type": "box"}, "material": {"opacity": )") + opacity + "}}"),
        {"/objects/0/material/opacity", "[0, 1]"});
  expect_json_error(scene_with_object(R"({"primitive": {"type": "sphere", "segments": 1000000000}})"),
                    {"/objects/0/primitive/segments", "4096"});
  expect_json_error(scene_with_object(R"({"primitive": {"type": "sphere", "segments": 1e30}})"),
                    {"segments", "absurd"});
  expect_json_error(scene_with_object(R"({"primitive": {"type": "sphere", "segments": 4096, "rings": 4096}})"),
                    {"/objects/0/primitive", "cap"});
  expect_json_error(scene_with_object(R"({"primitive": {"type": "box", "size": [1e9, 1, 1]}})"), {"size", "<= 1e+06"});
  expect_json_error(scene_with_object(R"({"primitive": {"type": "fence", "bars": 0}})"), {"bars"});
  expect_json_error(scene_with_object(R"({"primitive": {"type": "brick_wall", "rows": 0}})"),
                    {"/objects/0/primitive/rows", "[1, 4096]"});
  expect_json_error(scene_with_object(R"({"primitive": {"type": "brick_wall", "rows": 4096, "columns": 4096}})"),
                    {"/objects/0/primitive", "cap"});
  expect_json_error(scene_with_object(R"({"primitive": {"type": "brick_wall", "mortar": 0.3}})"),
                    {"/objects/0/primitive/mortar", "smaller than brick_length"});
  expect_json_error(scene_with_object(R"({"primitive": {"type": "brick_wall", "mortar": 0.08}})"),
                    {"/objects/0/primitive/mortar", "smaller than brick_height"});
  expect_json_error(scene_with_object(R"({"primitive": {"type": "brick_wall", "relief": 0}})"), {"relief", "> 0"});
  expect_json_error(scene_with_object(R"({"primitive": {"type": "brick_wall", "brick_length": 1e9}})"),
                    {"brick_length", "<= 1e+06"});
  expect_json_error(scene_with_object(R"({"primitive": {"type": "brick_wall", "columns": 4000, "brick_length": 900}})"),
                    {"/objects/0/primitive", "more than 1e+06"});
  expect_json_error(scene_with_object(R"({"primitive": {"type": "brick_wall", "bricks": 3}})"), {"bricks"});
  expect_json_error(scene_with_object(R"({"primitive": {"type": "plane", "size": [1e400, 1]}})"),
                    {"test.json", "number overflow"});
  expect_json_error(scene_with_object(R"({"primitive": {"type": "box"}, "material": {"albedo_texture": "nope.png"}})"),
                    {"/objects/0/material/albedo_texture", "nope.png", "does not exist"});
}

TEST(Errors, Meshes) {
  TempDir dir("msm_scene_test");
  auto load = [&](const std::string& object_json) {
    load_scene_file(dir.write("s.json", scene_with_object(object_json)));
  };
  msm::test::expect_scene_error([&] { load(R"({"name": "m", "mesh": "missing.obj"})"); },
                                {"s.json", "/objects/0/mesh", "object 'm'", "missing.obj", "does not exist"});
  dir.write("garbage.ply", "ply\nthis is not a ply file\n\x01\x02\x03");
  msm::test::expect_scene_error([&] { load(R"({"mesh": "garbage.ply"})"); },
                                {"/objects/0/mesh", "garbage.ply", "truncated or corrupt"});
  dir.write("empty.obj", "# nothing\n");
  msm::test::expect_scene_error([&] { load(R"({"mesh": "empty.obj"})"); }, {"/objects/0/mesh", "empty.obj"});
  dir.write("degenerate.obj", "v 0 0 0\nv 1 0 0\nv 2 0 0\nv 0 1 0\nf 1 2 3\nf 1 1 4\n");
  msm::test::expect_scene_error([&] { load(R"({"mesh": "degenerate.obj"})"); }, {"/objects/0/mesh", "non-zero area"});
  dir.write("nan.ply",
            "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\n"
            "element face 1\nproperty list uchar int vertex_indices\nend_header\nnan 0 0\n1 0 0\n0 1 0\n3 0 1 2\n");
  msm::test::expect_scene_error([&] { load(R"({"mesh": "nan.ply"})"); },
                                {"/objects/0/mesh", "nan.ply", "NaN or infinite"});
  dir.write("inf.obj", "v 1e39 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
  msm::test::expect_scene_error([&] { load(R"({"mesh": "inf.obj"})"); },
                                {"/objects/0/mesh", "inf.obj", "NaN or infinite"});
  // Degenerate triangles next to good ones are dropped.
  dir.write("mixed.obj", "v 0 0 0\nv 1 0 0\nv 2 0 0\nv 0 1 0\nf 1 2 3\nf 1 2 4\n");
  load_scene_file(dir.write("ok.json", scene_with_object(R"({"mesh": "mixed.obj"})")));
  EXPECT_EQ(load_scene_file(dir.path() / "ok.json").triangle_count(), 1u);
}

// ---------------------------------------------------------------------------------------------
// Participating medium

TEST(Medium, ParsedWithDefaultsAndPhase) {
  const std::string box = R"({"primitive": {"type": "box"}})";
  EXPECT_FALSE(load_scene_json(scene_with_object(box), fs::current_path(), "t").medium.has_value());
  const Scene iso =
      load_scene_json(scene_with_object(box, R"("medium": {"extinction": 0.25},)"), fs::current_path(), "t");
  ASSERT_TRUE(iso.medium.has_value());
  EXPECT_EQ(iso.medium->extinction, 0.25f);
  EXPECT_EQ(iso.medium->scattering_albedo, 1.0f);
  EXPECT_EQ(iso.medium->g, 0.0f);
  const Scene hg = load_scene_json(
      scene_with_object(
          box, R"("medium": {"extinction": 2, "scattering_albedo": 0.5, "phase": "henyey_greenstein", "g": -0.3},)"),
      fs::current_path(), "t");
  EXPECT_EQ(hg.medium->scattering_albedo, 0.5f);
  EXPECT_EQ(hg.medium->g, -0.3f);
}

TEST(Medium, BadValuesNameTheirPointer) {
  const std::string box = R"({"primitive": {"type": "box"}})";
  const auto with = [&](const std::string& medium) { return scene_with_object(box, R"("medium": )" + medium + ","); };
  expect_json_error(with("{}"), {"/medium/extinction", "required"});
  expect_json_error(with(R"({"extinction": 0})"), {"/medium/extinction", "(0,"});
  expect_json_error(with(R"({"extinction": -1})"), {"/medium/extinction"});
  expect_json_error(with(R"({"extinction": 1e30})"), {"/medium/extinction"});
  expect_json_error(with(R"({"extinction": "thick"})"), {"/medium/extinction", "number"});
  expect_json_error(with(R"({"extinction": 1, "scattering_albedo": 1.5})"), {"/medium/scattering_albedo"});
  expect_json_error(with(R"({"extinction": 1, "phase": "rayleigh"})"), {"/medium/phase", "unknown phase"});
  expect_json_error(with(R"({"extinction": 1, "g": 0.5})"), {"/medium/g", "henyey_greenstein"});
  expect_json_error(with(R"({"extinction": 1, "phase": "henyey_greenstein"})"), {"/medium/g", "required"});
  expect_json_error(with(R"({"extinction": 1, "phase": "henyey_greenstein", "g": 1})"), {"/medium/g", "0.9999"});
  expect_json_error(with(R"({"extinction": 1, "phase": "henyey_greenstein", "g": 0.99999})"), {"/medium/g"});
  expect_json_error(with(R"({"extinction": 1, "phase": "henyey_greenstein", "g": -1})"), {"/medium/g"});
  expect_json_error(with(R"({"extinction": 1, "density": 1})"), {"/medium/density", "unknown key"});
}

// ---------------------------------------------------------------------------------------------
// Image-based lighting: a probe's area lights

TEST(Probe, LightsFollowTheDirectionalOnes) {
  const std::string box = R"({"primitive": {"type": "box"}})";
  const std::string studio = std::string(MSM_STUDIOLIGHTS_DIR) + "/studio.exr";
  // A probe alone: its lights only.
  const Scene alone = load_scene_json(R"({"msm_scene": 1, "probe": {"file": ")" + studio +
                                          R"(", "lights": 8, "size": 16}, "objects": [)" + box + "]}",
                                      fs::current_path(), "t");
  ASSERT_TRUE(alone.probe.has_value());
  EXPECT_EQ(alone.lights.size(), 8u);
  EXPECT_EQ(alone.probe->first_light, 0u);
  // Fewer than six: one light per group of faces (median_cut merges the face regions).
  for (int n = 1; n <= 5; ++n) {
    const Scene few = load_scene_json(R"({"msm_scene": 1, "probe": {"file": "sky", "size": 8, "lights": )" +
                                          std::to_string(n) + R"(}, "objects": [)" + box + "]}",
                                      fs::current_path(), "t");
    ASSERT_EQ(few.lights.size(), std::size_t(n));
    for (const auto& l : few.lights) {
      EXPECT_NEAR(glm::length(l.towards_light), 1.0f, 1e-5f) << n;
      EXPECT_TRUE(std::isfinite(l.irradiance.x) && l.irradiance.y > 0.0f && std::isfinite(l.irradiance.z)) << n;
      EXPECT_TRUE(l.angular_extent_deg > 0.0f && l.angular_extent_deg < 90.0f) << n;
    }
  }
  // Beside a directional light: it stays first.
  const Scene both =
      load_scene_json(scene_with_object(box, R"("probe": {"file": "sky", "lights": 6, "size": 8, "intensity": 2},)"),
                      fs::current_path(), "t");
  ASSERT_EQ(both.lights.size(), 7u);
  EXPECT_EQ(both.probe->first_light, 1u);
  EXPECT_EQ(both.lights[0].towards_light, glm::vec3(0, 1, 0));
  for (std::size_t k = 1; k < both.lights.size(); ++k) {
    EXPECT_NEAR(glm::length(both.lights[k].towards_light), 1.0f, 1e-5f);
    EXPECT_GE(both.lights[k].angular_extent_deg, 0.0f);
    EXPECT_LT(both.lights[k].angular_extent_deg, 90.0f);
  }
}

// "horizon_split": the probe's lights come from median_cut with the split, and --lights N
// (set_probe_light_count) keeps it (a count below ten is refused at /probe/lights).
TEST(Probe, HorizonSplitReachesTheCut) {
  const std::string head = R"({"msm_scene": 1, "probe": {"file": "sky", "size": 16, "lights": 16)";
  const std::string tail = R"(}, "objects": [{"primitive": {"type": "box"}}]})";
  Scene split = load_scene_json(head + R"(, "horizon_split": true)" + tail, fs::current_path(), "t");
  const Scene plain = load_scene_json(head + tail, fs::current_path(), "t");
  ASSERT_TRUE(split.probe && split.probe->horizon_split);
  EXPECT_FALSE(plain.probe->horizon_split);
  const auto expected = msm::probe::probe_area_lights("sky", 16, 16, 0.0f, 1.0f, true);
  ASSERT_EQ(split.lights.size(), expected.size());
  for (std::size_t k = 0; k < expected.size(); ++k)
    EXPECT_EQ(split.lights[k].towards_light, msm::scene::light_of_area_light(expected[k]).towards_light) << k;
  bool differs = false;
  for (std::size_t k = 0; k < plain.lights.size(); ++k)
    differs |= plain.lights[k].towards_light != split.lights[k].towards_light;
  EXPECT_TRUE(differs);
  msm::scene::set_probe_light_count(split, 12);
  EXPECT_EQ(split.lights.size(), 12u);
  EXPECT_TRUE(split.probe->horizon_split);
  EXPECT_THROW(msm::scene::set_probe_light_count(split, 9), msm::scene::SceneError);
  EXPECT_EQ(split.lights.size(), 12u); // unchanged by the refused count
}

// "sub_lights": each light gets the lights of the finer cut inside its region (their energies add
// up to the light's: the probe's lights as probe_area_lights makes them), re-cut with --lights and
// kept; at most as many as the lights: none.
TEST(Probe, SubLightsReachTheLights) {
  const std::string head = R"({"msm_scene": 1, "probe": {"file": "sky", "size": 16, "lights": 4)";
  const std::string tail = R"(}, "objects": [{"primitive": {"type": "box"}}]})";
  Scene scene = load_scene_json(head + R"(, "sub_lights": 32)" + tail, fs::current_path(), "t");
  ASSERT_TRUE(scene.probe);
  EXPECT_EQ(scene.probe->sub_lights, 32);
  ASSERT_EQ(scene.lights.size(), 4u);
  const auto expected = msm::probe::probe_area_lights("sky", 16, 4);
  const auto grouped = msm::probe::probe_lights_with_sub_lights("sky", 16, 4, 32);
  ASSERT_EQ(grouped.size(), expected.size());
  std::size_t subs = 0;
  for (std::size_t k = 0; k < scene.lights.size(); ++k) {
    const msm::scene::DirectionalLight& l = scene.lights[k];
    EXPECT_EQ(l.towards_light, msm::scene::light_of_area_light(expected[k]).towards_light) << k;
    ASSERT_FALSE(l.sub_lights.empty()) << k;
    subs += l.sub_lights.size();
    // Σ M_e of the sub-lights = the light's M_e (XYZ round trips: 1e-3 relative).
    glm::dvec3 sum(0.0);
    for (const msm::MsmAreaLight& a : grouped[k].sub_lights) sum += glm::dvec3(a.irradiance);
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(sum[c] / double(expected[k].irradiance[c]), 1.0, 1e-3) << k;
  }
  EXPECT_EQ(subs, 32u);
  msm::scene::set_probe_light_count(scene, 8);
  EXPECT_EQ(scene.probe->sub_lights, 32);
  EXPECT_FALSE(scene.lights.front().sub_lights.empty());
  msm::scene::set_probe_light_count(scene, 32);
  for (const auto& l : scene.lights) EXPECT_TRUE(l.sub_lights.empty()); // 32 sub-lights for 32 lights: none
  msm::scene::set_probe_light_count(scene, 8, 0);
  for (const auto& l : scene.lights) EXPECT_TRUE(l.sub_lights.empty());
  EXPECT_THROW(msm::scene::set_probe_light_count(scene, 8, 300), msm::scene::SceneError);
}

// The shading's shortcut for sub-lights (sub_lights_linear_part, shading.glsl): wherever its
// rectangle is above the horizon every sub-light's msm_light_cosine is n·l_k (each wholly above it)
// and the linear part is their sum; wherever below, each is 0. On the sky and on city.exr,
// 1 to 16 lights of 64 sub-lights, 2000 random normals per light; and the shortcut is taken for
// most of the normals that see every sub-light above or below (it would be safe but useless with no
// bounds): the shares are stated per case with their margin.
TEST(Probe, SubLightsLinearPartIsTheirSumWhereAllAreAboveTheHorizon) {
  struct Case {
    std::string probe;
    int count;
    double min_share; // of the normals that see every sub-light on one side, taken by the shortcut
  };
  const std::string city = std::string(MSM_STUDIOLIGHTS_DIR) + "/city.exr";
  // Measured: sky 0.477 (4 lights), 0.952 (16); city.exr 0.162, 0.833. One light's sub-lights
  // surround every normal: none sees them all on one side, and the shortcut is never taken.
  const Case cases[] = {{"sky", 1, 0.0}, {"sky", 4, 0.42}, {"sky", 16, 0.90}, {city, 4, 0.12}, {city, 16, 0.78}};
  msm::util::SplitMix64 rng(15);
  for (const Case& c : cases) {
    int one_side = 0, taken = 0;
    for (const msm::probe::ProbeLight& grouped : msm::probe::probe_lights_with_sub_lights(c.probe, 32, c.count, 64)) {
      const DirectionalLight light = light_of_probe_light(grouped);
      ASSERT_FALSE(light.sub_lights.empty()) << c.probe << " " << c.count;
      const SubLightsLinearPart part = sub_lights_linear_part(light);
      double scale = 0.0;
      for (const DirectionalLight& sub : light.sub_lights) scale += glm::length(glm::dvec3(sub.irradiance));
      for (int i = 0; i < 2000; ++i) {
        const float z = float(2.0 * rng.uniform() - 1.0), phi = float(2.0 * std::numbers::pi * rng.uniform());
        const float r = std::sqrt(std::max(1.0f - z * z, 0.0f));
        const glm::vec3 n(r * std::cos(phi), z, r * std::sin(phi));
        glm::dvec3 sum(0.0);
        bool all_above = true, all_below = true;
        for (const DirectionalLight& sub : light.sub_lights) {
          const float cosine = msm::msm_light_cosine(n, sub.towards_light, sub.x_axis.value_or(glm::vec3(0.0f)),
                                                     sub.rectangle_extents(), sub.cone_half_angle());
          sum += glm::dvec3(sub.irradiance) * double(cosine);
          all_above = all_above && std::abs(cosine - glm::dot(n, sub.towards_light)) <= 1e-6f;
          all_below = all_below && cosine <= 1e-6f;
        }
        const int side = msm::msm_tangent_rect_side(n, light.towards_light, part.x_axis, part.y_axis, part.bounds);
        if (side > 0) {
          ASSERT_TRUE(all_above) << c.probe << " " << c.count;
          const glm::vec3 linear = msm::msm_linear_irradiance(part.irradiance_by_direction, n);
          for (int k = 0; k < 3; ++k) EXPECT_NEAR(linear[k], sum[k], 1e-5 * scale) << c.probe << " " << c.count;
        }
        if (side < 0) { ASSERT_TRUE(all_below) << c.probe << " " << c.count; }
        one_side += (all_above || all_below) ? 1 : 0;
        taken += side != 0 ? 1 : 0;
      }
    }
    const double share = double(taken) / double(std::max(one_side, 1));
    EXPECT_GE(share, c.min_share) << c.probe << " " << c.count << ": " << taken << " of " << one_side;
    if (c.count == 1) { EXPECT_EQ(one_side, 0); }
  }
}

TEST(Probe, BadValuesNameTheirPointer) {
  const std::string box = R"({"primitive": {"type": "box"}})";
  const auto with = [&](const std::string& probe) { return scene_with_object(box, R"("probe": )" + probe + ","); };
  expect_json_error(with("{}"), {"/probe/file", "required"});
  expect_json_error(with(R"({"file": "none.exr"})"), {"/probe/file", "does not exist"});
  expect_json_error(with(R"({"file": "sky", "lights": 0})"), {"/probe/lights", "[1, 256]"});
  expect_json_error(with(R"({"file": "sky", "lights": 256})"), {"/probe/lights", "exceed 256"});
  expect_json_error(with(R"({"file": "sky", "size": 0})"), {"/probe/size"});
  expect_json_error(with(R"({"file": "sky", "intensity": -1})"), {"/probe/intensity"});
  expect_json_error(with(R"({"file": "sky", "spin": 1})"), {"/probe/spin", "unknown key"});
  expect_json_error(with(R"({"file": "sky", "horizon_split": 1})"), {"/probe/horizon_split", "true or false"});
  expect_json_error(with(R"({"file": "sky", "horizon_split": true, "lights": 9})"), {"/probe/lights", "10 to 256"});
  expect_json_error(with(R"({"file": "sky", "horizon_split": true, "size": 15})"), {"/probe/size", "even"});
  expect_json_error(with(R"({"file": "sky", "sub_lights": -1})"), {"/probe/sub_lights", "[0, 256]"});
  expect_json_error(with(R"({"file": "sky", "sub_lights": 257})"), {"/probe/sub_lights", "[0, 256]"});
  expect_json_error(with(R"({"file": "sky", "sub_lights": 1.5})"), {"/probe/sub_lights"});
  expect_json_error(with(R"({"file": "sky", "horizon_split": true, "lights": 10, "sub_lights": 8})"),
                    {"/probe/sub_lights", "10 to 256"});
  const std::string license = std::string(MSM_STUDIOLIGHTS_DIR) + "/license.txt";
  expect_json_error(with(R"({"file": ")" + license + R"("})"), {"/probe/file", "not an EXR"});
  expect_json_error(R"({"msm_scene": 1, "objects": [)" + box + "]}", {"/light", "\"probe\""});
}

// ---- Rectangular lights (Kneiphof §4.1.2) ----

// overridden_light, the one rule of the renderer, the ray tracer and the viewer: no override is the
// light as declared; an extent alone a disc of that diameter; a height a rectangle of that height,
// its width the extent given or the light's own.
TEST(Lights, OverriddenLightIsTheDeclaredOneUnlessOverridden) {
  DirectionalLight rect;
  rect.angular_extent_deg = 20.0f;
  rect.angular_height_deg = 2.0f;
  const DirectionalLight same = overridden_light(rect, std::nullopt, std::nullopt);
  EXPECT_TRUE(same.rectangular());
  EXPECT_EQ(same.angular_extent_deg, 20.0f);
  EXPECT_EQ(same.angular_height_deg, 2.0f);
  const DirectionalLight disc = overridden_light(rect, 8.0f, std::nullopt);
  EXPECT_FALSE(disc.rectangular());
  EXPECT_EQ(disc.angular_extent_deg, 8.0f);
  const DirectionalLight lower = overridden_light(rect, std::nullopt, 4.0f);
  EXPECT_EQ(lower.angular_extent_deg, 20.0f);
  EXPECT_EQ(lower.angular_height_deg, 4.0f);
  DirectionalLight round;
  round.angular_extent_deg = 10.0f;
  EXPECT_FALSE(overridden_light(round, std::nullopt, std::nullopt).rectangular());
  const DirectionalLight made = overridden_light(round, 6.0f, 3.0f);
  EXPECT_EQ(made.angular_extent_deg, 6.0f);
  EXPECT_EQ(made.angular_height_deg, 3.0f);
}

// Irradiance above 1e36 (the shading's sums over kMaxLights lights stay finite in single precision)
// is refused with its JSON pointer; 1e36 itself is taken.
TEST(Lights, IrradianceAboveTheFloatLimitRefused) {
  const auto scene_of = [](const std::string& irradiance) {
    return R"({"msm_scene": 1, "lights": [{"towards_light": [0, 1, 0]}, {"towards_light": [0, 1, 0], "irradiance": )" +
           irradiance + R"(}], "objects": [{"primitive": {"type": "box"}}]})";
  };
  EXPECT_EQ(load_scene_json(scene_of("[1e36, 1e36, 1e36]"), fs::current_path(), "t").lights[1].irradiance.y, 1e36f);
  try {
    load_scene_json(scene_of("[1, 2e36, 1]"), fs::current_path(), "t");
    ADD_FAILURE() << "accepted";
  } catch (const SceneError& e) {
    EXPECT_NE(std::string(e.what()).find("/lights/1/irradiance"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("at most 1e+36"), std::string::npos) << e.what();
  }
}

// A light with one extent is the disc it always was; a second extent makes it a rectangle along
// its x_axis, whose shadow-map frame takes that axis (the probe's lights take their face's u axis).
TEST(Lights, RectangularLightsCarryTwoExtentsAndTheirFrame) {
  const std::string box = R"({"primitive": {"type": "box"}})";
  const auto with_light = [&](const std::string& light) {
    return load_scene_json(R"({"msm_scene": 1, "light": )" + light + R"(, "objects": [)" + box + "]}",
                           fs::current_path(), "t");
  };
  const Scene disc = with_light(R"({"towards_light": [0, 1, 0], "angular_extent_deg": 10})");
  EXPECT_FALSE(disc.light().rectangular());
  EXPECT_FALSE(disc.light().x_axis.has_value());
  EXPECT_EQ(disc.light().tan_half_extents(), glm::vec2(std::tan(glm::radians(5.0f))));
  EXPECT_FLOAT_EQ(disc.light().cone_half_angle(), glm::radians(5.0f));

  const Scene rect = with_light(
      R"({"towards_light": [0, 1, 1], "angular_extent_deg": 20, "angular_height_deg": 8, "x_axis": [1, 0, 0.5]})");
  const DirectionalLight& l = rect.light();
  ASSERT_TRUE(l.rectangular());
  EXPECT_FLOAT_EQ(l.tan_half_extents().x, std::tan(glm::radians(10.0f)));
  EXPECT_FLOAT_EQ(l.tan_half_extents().y, std::tan(glm::radians(4.0f)));
  EXPECT_NEAR(l.cone_half_angle(), msm::msm_rect_light_cone_half_angle(l.tan_half_extents()), 1e-7f);
  // The frame's x axis is x_axis projected orthogonal to the light (up to its sign).
  const LightFrame f = rect.light_frame();
  const glm::dvec3 z = glm::normalize(glm::dvec3(0, 1, 1));
  const glm::dvec3 x = glm::normalize(glm::dvec3(1, 0, 0.5) - glm::dot(glm::dvec3(1, 0, 0.5), z) * z);
  EXPECT_NEAR(std::abs(glm::dot(f.x_axis, x)), 1.0, 1e-6);
  EXPECT_NEAR(glm::dot(f.y_axis, z), 0.0, 1e-6);

  // The probe's lights: rectangles on their faces' u axes, below 90° each way.
  const Scene probe = load_scene_json(scene_with_object(box, R"("probe": {"file": "sky", "lights": 6, "size": 8},)"),
                                      fs::current_path(), "t");
  for (std::size_t k = 1; k < probe.lights.size(); ++k) {
    const DirectionalLight& p = probe.lights[k];
    ASSERT_TRUE(p.rectangular() && p.x_axis.has_value()) << k;
    EXPECT_LT(*p.angular_height_deg, 90.0f);
    EXPECT_NEAR(glm::dot(*p.x_axis, p.towards_light), 0.0f, 1e-5f) << k;
    EXPECT_NEAR(std::abs(glm::dot(probe.light_frame(p).x_axis, glm::dvec3(*p.x_axis))), 1.0, 1e-5) << k;
  }
}

TEST(Lights, BadSecondExtentOrAxisNamesItsPointer) {
  const std::string box = R"({"primitive": {"type": "box"}})";
  const auto scene_of = [&](const std::string& light) {
    return R"({"msm_scene": 1, "light": )" + light + R"(, "objects": [)" + box + "]}";
  };
  expect_json_error(scene_of(R"({"towards_light": [0, 1, 0], "angular_height_deg": 90})"),
                    {"test.json", "/light/angular_height_deg", "must be in [0, 90)"});
  expect_json_error(scene_of(R"({"towards_light": [0, 1, 0], "angular_height_deg": -1})"),
                    {"/light/angular_height_deg", "must be in [0, 90)"});
  expect_json_error(scene_of(R"({"towards_light": [0, 1, 0], "angular_height_deg": "wide"})"),
                    {"/light/angular_height_deg"});
  expect_json_error(scene_of(R"({"towards_light": [0, 1, 0], "x_axis": [0, 0, 0]})"),
                    {"/light/x_axis", "non-zero direction"});
  expect_json_error(scene_of(R"({"towards_light": [0, 1, 0], "x_axis": [0, -2, 0]})"),
                    {"/light/x_axis", "must not be parallel to towards_light"});
  expect_json_error(R"({"msm_scene": 1, "lights": [{"towards_light": [0, 1, 0]}, {"towards_light": [1, 1, 0],
                      "angular_height_deg": 1e9}], "objects": [)" +
                        box + "]}",
                    {"/lights/1/angular_height_deg"});
}

// ---- Animated objects (dynamic scenes) ----

// A box 2 wide turning 30° a frame about +Y through its origin (1, 0, 0) and moving 0.5 a frame
// along +Z: at frame 3 it has turned 90° (2 deep, 1 wide) about (1, 0, 1.5), by hand; the same
// vertices as a box placed there by its transform, the normals too; the still object and frame 0
// are the scene itself.
TEST(Motion, AtFrameTurnsAboutTheOriginThenMoves) {
  const std::string still = R"({"name": "still", "primitive": {"type": "sphere", "radius": 0.5}})";
  const Scene s = load_scene_json(scene_with_object(R"({"name": "b", "primitive": {"type": "box", "size": [2, 1, 1]},
          "transform": {"translate": [1, 0, 0]},
          "motion": {"translate": [0, 0, 0.5], "rotate": {"axis": [0, 1, 0], "angle_deg": 30}}}, )" +
                                                    still),
                                  ".", "t.json");
  ASSERT_TRUE(s.animated());
  const Scene moved = at_frame(s, 3);
  const Bounds b = moved.objects[0].bounds;
  EXPECT_NEAR(b.min.x, 0.5f, 1e-5f);
  EXPECT_NEAR(b.max.x, 1.5f, 1e-5f);
  EXPECT_NEAR(b.min.z, 0.5f, 1e-5f);
  EXPECT_NEAR(b.max.z, 2.5f, 1e-5f);
  EXPECT_NEAR(b.min.y, -0.5f, 1e-5f);
  const Scene placed = load_scene_json(scene_with_object(R"({"primitive": {"type": "box", "size": [2, 1, 1]},
                            "transform": {"translate": [1, 0, 1.5], "rotate": [0, 90, 0]}})"),
                                       ".", "t.json");
  const Mesh &m = moved.objects[0].mesh, &p = placed.objects[0].mesh;
  ASSERT_EQ(m.positions.size(), p.positions.size());
  for (std::size_t v = 0; v < m.positions.size(); ++v) {
    EXPECT_LT(glm::distance(m.positions[v], p.positions[v]), 1e-5f) << v;
    EXPECT_GT(glm::dot(m.normals[v], p.normals[v]), 0.99999f) << v;
  }
  expect_consistent(m);
  EXPECT_LT(glm::distance(moved.objects[0].transform.translate, glm::vec3(1, 0, 1.5f)), 1e-6f);
  EXPECT_EQ(moved.objects[1].mesh.positions, s.objects[1].mesh.positions);
  EXPECT_EQ(at_frame(s, 0).objects[0].mesh.positions, s.objects[0].mesh.positions);
  EXPECT_FALSE(load_scene_json(scene_with_object(still), ".", "t.json").animated());
  msm::test::expect_scene_error([&] { (void)at_frame(s, -1); }, {"frame -1", ">= 0"});
}

TEST(Motion, BadValuesNameTheirPointer) {
  const auto with = [](const std::string& motion) {
    return scene_with_object(R"({"name": "b", "primitive": {"type": "box"}, "motion": )" + motion + "}");
  };
  expect_json_error(with("1"), {"/objects/0/motion", "must be an object"});
  expect_json_error(with("{}"), {"/objects/0/motion", "\"translate\" and/or \"rotate\""});
  expect_json_error(with(R"({"spin": 1})"), {"/objects/0/motion/spin", "unknown key"});
  expect_json_error(with(R"({"translate": [0, 2000, 0]})"), {"/objects/0/motion/translate", "per frame"});
  expect_json_error(with(R"({"translate": [0, 1]})"), {"/objects/0/motion/translate", "3 numbers"});
  expect_json_error(with(R"({"rotate": [0, 10, 0]})"), {"/objects/0/motion/rotate", "axis"});
  expect_json_error(with(R"({"rotate": {"axis": [0, 1, 0]}})"), {"/objects/0/motion/rotate", "angle_deg"});
  expect_json_error(with(R"({"rotate": {"axis": [0, 0, 0], "angle_deg": 5}})"),
                    {"/objects/0/motion/rotate/axis", "non-zero"});
  expect_json_error(with(R"({"rotate": {"axis": [0, 1, 0], "angle_deg": 400}})"),
                    {"/objects/0/motion/rotate/angle_deg", "[-360, 360]"});
}

// ---- A probe instead of the scene's lighting (msm render --probe) ----

// The directional light of `models` gives way to the sky's 32 area lights at ProbeLighting's face
// size; sky_probe given its own probe gets the lights its JSON made; a scene with a probe keeps its
// settings (sky_probe's 64² faces, a re-cut count); a missing file and a black probe are errors
// naming the file.
TEST(Probe, SetProbeReplacesTheScenesLighting) {
  Scene models = builtin_scene("models");
  ASSERT_FALSE(models.probe);
  set_probe(models, "sky");
  ASSERT_TRUE(models.probe);
  EXPECT_EQ(models.probe->lights, 32);
  EXPECT_EQ(models.probe->size, 128);
  EXPECT_EQ(models.probe->first_light, 0u);
  EXPECT_EQ(models.lights.size(), 32u);
  Scene sky = builtin_scene("sky_probe");
  Scene again = sky;
  set_probe(again, "sky"); // what its JSON made
  ASSERT_EQ(again.lights.size(), sky.lights.size());
  for (std::size_t i = 0; i < sky.lights.size(); ++i) {
    EXPECT_EQ(again.lights[i].towards_light, sky.lights[i].towards_light) << i;
    EXPECT_EQ(again.lights[i].irradiance, sky.lights[i].irradiance) << i;
  }
  set_probe_light_count(sky, 12);
  const std::string lamp = std::string(MSM_TEST_DATA_DIR) + "/probes/lamp.exr";
  set_probe(sky, lamp);
  EXPECT_EQ(sky.probe->file, lamp);
  EXPECT_EQ(sky.probe->size, 64);
  EXPECT_EQ(sky.probe->lights, 12);
  EXPECT_EQ(sky.lights.size(), 12u);
  msm::test::expect_scene_error([&] { set_probe(models, "/no/such/probe.exr"); },
                                {"/no/such/probe.exr", "no such light probe"});
  msm::test::expect_scene_error([&] { set_probe(models, std::string(MSM_TEST_DATA_DIR) + "/probes/black.exr"); },
                                {"black.exr", "no light"});
  EXPECT_EQ(models.lights.size(), 32u) << "a refused probe leaves the scene as it was";
}

// Six face files named by a "{face}" path as a scene's probe: the lights of the cube they hold (the
// sky written face by face) are the sky's own, from the JSON and through set_probe; a missing face
// is an error naming it.
TEST(Probe, SixFaceFilesAreAProbe) {
  TempDir dir("msm_scene_test");
  const msm::probe::CubeMap sky = msm::probe::load_probe("sky", 16);
  const fs::path pattern = dir.path() / "sky_{face}.exr";
  const std::array<fs::path, 6> files = msm::probe::cube_face_files(pattern);
  msm::probe::write_cube_faces(pattern, sky);
  const std::string box = R"({"primitive": {"type": "box"}})";
  const auto with = [&](const std::string& file) {
    return load_scene_json(scene_with_object(box, R"("probe": {"file": ")" + file + R"(", "size": 16, "lights": 8},)"),
                           fs::current_path(), "t.json");
  };
  const Scene faces = with(pattern.string()), own = with("sky");
  Scene set = own;
  set_probe(set, pattern);
  ASSERT_EQ(faces.lights.size(), own.lights.size());
  ASSERT_EQ(set.lights.size(), 8u); // the scene's directional light replaced too
  for (std::size_t i = 0; i < own.lights.size(); ++i) {
    EXPECT_LT(glm::distance(faces.lights[i].towards_light, own.lights[i].towards_light), 1e-6f) << i;
    EXPECT_LT(glm::distance(faces.lights[i].irradiance, own.lights[i].irradiance),
              1e-6f * glm::length(own.lights[i].irradiance))
        << i;
  }
  for (std::size_t i = 0; i < set.lights.size(); ++i)
    EXPECT_EQ(set.lights[i].towards_light, faces.lights[faces.probe->first_light + i].towards_light) << i;
  fs::remove(files[3]);
  expect_json_error(scene_with_object(box, R"("probe": {"file": ")" + pattern.string() + R"("},)"),
                    {"/probe/file", "sky_ny.exr", "does not exist"});
  msm::test::expect_scene_error([&] { set_probe(set, pattern); }, {"sky_ny.exr", "no such light probe"});
  msm::probe::write_cube_faces(pattern, sky);
  Scene turned = own;
  turned.probe->rotation_deg = 10.0f;
  msm::test::expect_scene_error([&] { set_probe(turned, pattern); },
                                {"cannot be rotated", "the scene's probe has \"rotation_deg\": 10"});
}

// ---------------------------------------------------------------------------------------------
// Spot and point lights: "lights" entries of every kind, their declaration and their validation

namespace {

std::string scene_with_lights(const std::string& lights) {
  return R"({"msm_scene": 1, "lights": [)" + lights +
         R"(], "objects": [{"primitive": {"type": "plane", "size": [4, 4]}}]})";
}

Scene load_lights(const std::string& lights) {
  return load_scene_json(scene_with_lights(lights), fs::current_path(), "test.json");
}

} // namespace

TEST(LocalLights, KindsMixInOneListInTheirOrder) {
  const Scene s = load_lights(R"({"type": "spot", "position": [0, 3, 0], "direction": [0, -2, 0],
      "inner_cone_deg": 20, "outer_cone_deg": 30, "range": 10, "intensity": [5, 6, 7], "radius": 0.1},
    {"towards_light": [0, 1, 0]},
    {"type": "point", "position": [1, 2, 3]},
    {"type": "directional", "towards_light": [1, 1, 0], "irradiance": [2, 2, 2]})");
  ASSERT_EQ(s.lights.size(), 2u);
  ASSERT_EQ(s.local_lights.size(), 2u);
  EXPECT_EQ(s.light_count(msm::scene::LightKind::directional), 2u);
  EXPECT_EQ(s.light_count(msm::scene::LightKind::spot), 1u);
  EXPECT_EQ(s.light_count(msm::scene::LightKind::point), 1u);
  EXPECT_EQ(s.lights[1].irradiance, glm::vec3(2.0f));
  const msm::scene::LocalLight& spot = s.local_lights[0];
  EXPECT_EQ(spot.kind, msm::scene::LightKind::spot);
  EXPECT_EQ(spot.position, glm::vec3(0, 3, 0));
  EXPECT_EQ(spot.direction, glm::vec3(0, -1, 0)); // normalized
  EXPECT_EQ(spot.inner_cone_deg, 20.0f);
  EXPECT_EQ(spot.outer_cone_deg, 30.0f);
  EXPECT_EQ(spot.range, 10.0f);
  EXPECT_EQ(spot.intensity, glm::vec3(5, 6, 7));
  EXPECT_EQ(spot.radius, 0.1f);
  const msm::scene::LocalLight& point = s.local_lights[1];
  EXPECT_EQ(point.kind, msm::scene::LightKind::point);
  EXPECT_EQ(point.position, glm::vec3(1, 2, 3));
  EXPECT_EQ(point.range, msm::scene::LocalLight::kInfiniteRange); // glTF: unbounded when absent
  EXPECT_EQ(point.intensity, glm::vec3(1.0f));
  EXPECT_EQ(point.radius, 0.0f);
}

TEST(LocalLights, OnlyLocalLightsLeaveNoDirectionalOne) {
  const Scene s = load_lights(R"({"type": "point", "position": [0, 1, 0]})");
  EXPECT_TRUE(s.lights.empty());
  ASSERT_EQ(s.local_lights.size(), 1u);
}

// The declaration is what the loader reads: every declared key of a kind is accepted for it.
TEST(LocalLights, TheDeclarationNamesEachKindAndItsKeys) {
  for (const msm::scene::LightKindInfo& k : msm::scene::light_kinds()) {
    EXPECT_EQ(msm::scene::parse_light_kind(k.name), k.kind);
    EXPECT_EQ(&msm::scene::light_kind(k.kind), &k);
    EXPECT_FALSE(k.keys.empty());
    EXPECT_GE(k.shadow_views, 1);
  }
  EXPECT_FALSE(msm::scene::parse_light_kind("area").has_value());
  EXPECT_EQ(msm::scene::light_kind(msm::scene::LightKind::point).shadow_views, 6);
}

TEST(LocalLights, BadInputNamesThePointerAndTheProblem) {
  expect_json_error(scene_with_lights(R"({"type": "area", "position": [0, 1, 0]})"),
                    {"/lights/0/type", "unknown light type 'area'", "spot"});
  expect_json_error(scene_with_lights(R"({"type": "spot", "direction": [0, -1, 0]})"),
                    {"/lights/0/position", "required"});
  expect_json_error(scene_with_lights(R"({"type": "spot", "position": [0, 1, 0]})"),
                    {"/lights/0/direction", "required"});
  expect_json_error(scene_with_lights(R"({"type": "spot", "position": [0, 1, 0], "direction": [0, 0, 0]})"),
                    {"/lights/0/direction", "non-zero"});
  // Cone angles: outer in (0, 90), inner in [0, 90) and not wider than outer.
  const std::string spot = R"({"type": "spot", "position": [0, 1, 0], "direction": [0, -1, 0], )";
  expect_json_error(scene_with_lights(spot + R"("outer_cone_deg": 90})"), {"/lights/0/outer_cone_deg", "(0, 90)"});
  expect_json_error(scene_with_lights(spot + R"("outer_cone_deg": 0})"), {"/lights/0/outer_cone_deg", "(0, 90)"});
  expect_json_error(scene_with_lights(spot + R"("outer_cone_deg": -5})"), {"/lights/0/outer_cone_deg"});
  expect_json_error(scene_with_lights(spot + R"("inner_cone_deg": -1})"), {"/lights/0/inner_cone_deg", "[0, 90)"});
  expect_json_error(scene_with_lights(spot + R"("inner_cone_deg": 40, "outer_cone_deg": 30})"),
                    {"/lights/0/inner_cone_deg", "wider than outer_cone_deg"});
  // The default outer cone (45°) bounds a given inner one too.
  expect_json_error(scene_with_lights(spot + R"("inner_cone_deg": 50})"), {"/lights/0/inner_cone_deg", "wider"});
  // Range > 0; radius >= 0 (0: a hard point); intensity >= 0.
  const std::string point = R"({"towards_light": [0, 1, 0]}, {"type": "point", "position": [0, 1, 0], )";
  expect_json_error(scene_with_lights(point + R"("range": 0})"), {"/lights/1/range", "(0, "});
  expect_json_error(scene_with_lights(point + R"("range": -3})"), {"/lights/1/range"});
  expect_json_error(scene_with_lights(point + R"("radius": -0.1})"), {"/lights/1/radius", "[0, "});
  expect_json_error(scene_with_lights(point + R"("intensity": [1, -1, 1]})"), {"/lights/1/intensity", ">= 0"});
  expect_json_error(scene_with_lights(point + R"("intensity": [1, 1e30, 1]})"), {"/lights/1/intensity", "at most"});
  expect_json_error(scene_with_lights(point + R"("position": [0, 1e7, 0]})"), {"/lights/1/position"});
  // A key of another kind is a typo here: a point light has no direction or cone.
  expect_json_error(scene_with_lights(point + R"("direction": [0, -1, 0]})"),
                    {"/lights/1/direction", "unknown key of a point light"});
  expect_json_error(scene_with_lights(spot + R"("towards_light": [0, 1, 0]})"),
                    {"/lights/0/towards_light", "unknown key of a spot light"});
  expect_json_error(scene_with_lights(R"({"type": "directional", "position": [0, 1, 0], "towards_light": [0, 1, 0]})"),
                    {"/lights/0/position", "unknown key of a directional light"});
  expect_json_error(scene_with_lights(R"({"type": 3, "position": [0, 1, 0]})"), {"/lights/0/type", "string"});
  expect_json_error(scene_with_lights(R"(7)"), {"/lights/0", "JSON object"});
  // "light" stays one directional light.
  expect_json_error(
      R"({"msm_scene": 1, "light": {"type": "point", "position": [0, 1, 0]}, "objects": [{"primitive": {"type": "plane", "size": [4, 4]}}]})",
      {"/light/type", "\"lights\""});
}

TEST(LocalLights, AnEqualInnerAndOuterConeIsAHardEdge) {
  const Scene s = load_lights(R"({"type": "spot", "position": [0, 0, 0], "direction": [0, -1, 0],
      "inner_cone_deg": 30, "outer_cone_deg": 30})");
  const msm::scene::LocalLight& l = s.local_lights[0];
  const auto at_angle = [](float deg) {
    return glm::vec3(std::sin(glm::radians(deg)), -std::cos(glm::radians(deg)), 0);
  };
  EXPECT_EQ(l.irradiance_at(at_angle(29.9f)), glm::vec3(1.0f));
  EXPECT_EQ(l.irradiance_at(at_angle(30.1f)), glm::vec3(0.0f));
}

// E = I cone(θ) / d², hand-computed: a spot 2 m above the origin pointing down, I = 8 W/sr, inner
// 30°, outer 45°. glTF's cone: t = (cos θ − cos 45°) / (cos 30° − cos 45°), cone = t².
TEST(LocalLights, IrradianceIsInverseSquareTimesTheGltfCone) {
  const Scene s = load_lights(R"({"type": "spot", "position": [0, 2, 0], "direction": [0, -1, 0],
      "inner_cone_deg": 30, "outer_cone_deg": 45, "range": 5, "intensity": [8, 8, 8]})");
  const msm::scene::LocalLight& l = s.local_lights[0];
  // Straight below at d = 2: 8 / 4 = 2.
  EXPECT_NEAR(l.irradiance_at({0, 0, 0}).x, 2.0f, 1e-6f);
  // 1 m to the side: d² = 5, θ = atan(1/2) = 26.57° inside the inner cone: 8 / 5 = 1.6.
  EXPECT_NEAR(l.irradiance_at({1, 0, 0}).x, 1.6f, 1e-6f);
  // 1.5 m to the side: d² = 6.25, cos θ = 2 / 2.5 = 0.8 (36.87°, in the ramp):
  // t = (0.8 − 0.70710678) / (0.86602540 − 0.70710678) = 0.58454, cone = 0.34169, E = 8 × 0.34169 / 6.25.
  EXPECT_NEAR(l.irradiance_at({0, 0, 1.5f}).x, 0.437363f, 2e-5f);
  // 2.5 m to the side: θ = 51.3° beyond the outer cone: 0.
  EXPECT_EQ(l.irradiance_at({2.5f, 0, 0}), glm::vec3(0.0f));
  // Beyond the range (5 m): 0; a point light lights every direction.
  EXPECT_EQ(l.irradiance_at({0, -3.5f, 0}), glm::vec3(0.0f));
  const Scene p = load_lights(R"({"type": "point", "position": [0, 2, 0], "intensity": [8, 8, 8]})");
  EXPECT_NEAR(p.local_lights[0].irradiance_at({0, 6, 0}).x, 0.5f, 1e-6f);
  // At the light's own position: finite, never inf or NaN.
  const glm::vec3 at = p.local_lights[0].irradiance_at({0, 2, 0});
  EXPECT_TRUE(std::isfinite(at.x));
}

// The probe's area lights count together with the declared lights of every kind.
TEST(LocalLights, CountTowardsTheLightLimitWithAProbe) {
  std::string lights = R"({"type": "point", "position": [0, 1, 0]})";
  for (int i = 1; i < 250; ++i) lights += R"(, {"type": "point", "position": [0, 1, 0]})";
  expect_json_error(
      R"({"msm_scene": 1, "lights": [)" + lights +
          R"(], "probe": {"file": "sky", "lights": 8, "size": 8}, "objects": [{"primitive": {"type": "plane", "size": [4, 4]}}]})",
      {"/probe/lights", "250 declared lights", "exceed"});
}
