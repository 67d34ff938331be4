// The ray tracer's spot and point lights against hand-computed irradiance: a light 2 m above a
// plane seen straight down, the camera placed so that the pixels of the middle row see the plane at
// whole half-metres from the point below the light (x = (i − 10) / 2 for pixel i of 21), where
// E cos θ = I cone(θ) cos θ / d² is worked out by hand; an occluder's exact shadow; never NaN.
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <numbers>
#include <string>

#include <gtest/gtest.h>

#include "msm/filter.h"
#include "msm/reference/kernel.h"
#include "msm/reference/reference.h"
#include "msm/scene/scene.h"

namespace {

using namespace msm::reference;
using msm::MSM_FILTER_DEFAULT_SIGMA;
using msm::MSM_FILTER_DEFAULT_TAPS;
using msm::scene::Scene;

constexpr double kPi = std::numbers::pi;
constexpr double kAlbedo = 0.8, kAmbient = 0.03;
constexpr int kSide = 21;

// 21² pixels, fov 90°, 5.25 m above the plane: pixel centre i of the middle row is at NDC
// (2i − 20) / 21, i.e. x = 5.25 (2i − 20) / 21 = (i − 10) / 2 m on the plane.
Scene scene_with(const std::string& light, const std::string& extra_objects = "",
                 const std::string& camera_position = "[0, 5.25, 0]") {
  return msm::scene::load_scene_json(
      R"({"msm_scene": 1, "camera": {"position": )" + camera_position +
          R"(, "target": [0, 0, 0], "up": [0, 0, -1], "fov_y_deg": 90, "near": 0.1, "far": 100},
        "lights": [)" +
          light + R"(], "objects": [{"primitive": {"type": "plane", "size": [40, 40]}})" + extra_objects + "]}",
      std::filesystem::current_path(), "test.json");
}

Result trace(const Scene& scene, Effect effect = Effect::hard, int samples = 256) {
  Settings s;
  s.effect = effect;
  s.width = s.height = kSide;
  s.samples = samples;
  return render(scene, s);
}

// The radiance of the plane (albedo 0.8) receiving E cos θ (msm/shading.h: albedo (E cos θ / π + ambient)).
double radiance_of(double e_cos) { return kAlbedo * (e_cos / kPi + kAmbient); }

// Pixel of the middle row seeing x metres from the point below the light (x a multiple of 0.5).
int pixel(double x) { return int(std::lround(2.0 * x)) + 10; }

const std::string kSpot = R"({"type": "spot", "position": [0, 2, 0], "direction": [0, -1, 0],
    "inner_cone_deg": 30, "outer_cone_deg": 45, "range": 20, "intensity": [8, 8, 8]})";

TEST(LocalLightsReference, SpotOverAPlaneGivesTheHandComputedIrradiance) {
  const Result r = trace(scene_with(kSpot));
  const int row = kSide / 2;
  // x = 0: d = 2, θ = 0 (inside the inner cone), cos θ = 1: E cos θ = 8 / 4 = 2.
  // x = 1: d² = 5, θ = 26.57° (inside), cos θ = 2 / √5: E cos θ = 8 / 5 × 0.8944272 = 1.4310835.
  // x = 1.5: d² = 6.25, cos θ = 0.8 (36.87°, in the ramp), glTF's cone t = (0.8 − cos 45°) /
  //   (cos 30° − cos 45°) = 0.5845410, t² = 0.3416882: E cos θ = 8 × 0.3416882 / 6.25 × 0.8 = 0.3498887.
  // x = 3: θ = 56.3° beyond the outer cone: 0 (ambient only).
  const struct {
    double x, e_cos;
  } expected[] = {{0.0, 2.0}, {1.0, 1.4310835}, {-1.0, 1.4310835}, {1.5, 0.3498887}, {3.0, 0.0}, {-4.5, 0.0}};
  for (const auto& e : expected) {
    for (int c = 0; c < 3; ++c)
      EXPECT_NEAR(r.radiance.at(pixel(e.x), row, c), radiance_of(e.e_cos), 2e-5) << "x = " << e.x;
    // The one light's visibility where it arrives; where none does, 0 (no light to see).
    EXPECT_EQ(r.visibility.at(pixel(e.x), row, 0), e.e_cos > 0.0 ? 1.0f : 0.0f) << "x = " << e.x;
    EXPECT_NEAR(r.surface.at(pixel(e.x), row, 0), 2.0 / std::hypot(e.x, 2.0), 1e-5) << "x = " << e.x; // n·l
  }
  // Symmetric about the spot's axis along the column too.
  EXPECT_NEAR(r.radiance.at(row, pixel(1.0), 0), radiance_of(1.4310835), 2e-5);
}

TEST(LocalLightsReference, AnOccluderCastsTheExactShadowOfThePointLight) {
  // A 0.5 m box centred 1 m up: the ray from x = 0 to the light passes through it, the one from
  // x = 1 passes it at x = 0.625 .. 0.375 (for y = 0.75 .. 1.25), outside its half-width 0.25.
  const std::string box = R"(, {"primitive": {"type": "box", "size": [0.5, 0.5, 0.5]},
      "transform": {"translate": [0, 1, 0]}})";
  const Result r = trace(scene_with(R"({"type": "point", "position": [0, 2, 0], "intensity": [8, 8, 8]})", box));
  const int row = kSide / 2;
  // x = 0: the camera sees the box's top (y = 1.25), 0.75 m below the light: E cos θ = 8 / 0.5625.
  EXPECT_EQ(r.visibility.at(pixel(0.0), row, 0), 1.0f);
  EXPECT_NEAR(r.radiance.at(pixel(0.0), row, 0), radiance_of(8.0 / 0.5625), 1e-4);
  EXPECT_EQ(r.visibility.at(pixel(1.0), row, 0), 1.0f);
  EXPECT_NEAR(r.radiance.at(pixel(1.0), row, 0), radiance_of(1.4310835), 2e-5);
  // x = 3 (beyond where the spot's cone would end): a point light lights every direction,
  // d² = 13, cos θ = 2 / √13: E cos θ = 8 × 2 / 13^1.5 = 0.3413644.
  EXPECT_NEAR(r.radiance.at(pixel(3.0), row, 0), radiance_of(0.3413644), 2e-5);
  // x = 0.5 lies in the box's shadow: the ray from (0.5, 0, 0) meets y = 0.75 at x = 0.3125.
  EXPECT_EQ(r.visibility.at(pixel(0.5), row, 0), 0.0f);
  EXPECT_NEAR(r.radiance.at(pixel(0.5), row, 0), radiance_of(0.0), 1e-7);
}

TEST(LocalLightsReference, TheRangeEndsTheLight) {
  // range 2.5: x = 1 (d = 2.236) lit, x = 2 (d = 2.828) dark.
  const Result r =
      trace(scene_with(R"({"type": "point", "position": [0, 2, 0], "range": 2.5, "intensity": [8, 8, 8]})"));
  const int row = kSide / 2;
  EXPECT_NEAR(r.radiance.at(pixel(1.0), row, 0), radiance_of(1.4310835), 2e-5);
  EXPECT_NEAR(r.radiance.at(pixel(2.0), row, 0), radiance_of(0.0), 1e-7);
}

TEST(LocalLightsReference, DirectionalAndLocalLightsAddUp) {
  // A directional light straight down (E = 3) beside the spot: the radiance adds their terms.
  const Result r = trace(scene_with(R"({"towards_light": [0, 1, 0], "irradiance": [3, 3, 3]}, )" + kSpot));
  EXPECT_NEAR(r.radiance.at(pixel(1.0), kSide / 2, 0), radiance_of(3.0 + 1.4310835), 2e-5);
  EXPECT_EQ(r.visibility.at(pixel(1.0), kSide / 2, 0), 1.0f);
}

TEST(LocalLightsReference, ALightOnTheSurfaceOrInsideAMeshGivesNoNaN) {
  // On the plane, right where the middle pixel looks: the shortest distance keeps E finite.
  const Result on = trace(scene_with(R"({"type": "point", "position": [0, 0, 0], "intensity": [8, 8, 8]})"));
  // Inside a closed box (documented: it lights nothing outside).
  const Result inside = trace(scene_with(R"({"type": "point", "position": [0, 1, 0], "intensity": [8, 8, 8]})",
                                         R"(, {"primitive": {"type": "box", "size": [0.5, 0.5, 0.5]},
                                               "transform": {"translate": [0, 1, 0]}})"));
  Settings filtered;
  filtered.effect = Effect::filtered;
  filtered.width = filtered.height = kSide;
  filtered.samples = 16;
  const Result on_filtered =
      render(scene_with(R"({"type": "point", "position": [0, 0, 0], "intensity": [8, 8, 8]})"), filtered);
  for (const Result* r : {&on, &inside, &on_filtered})
    for (int y = 0; y < kSide; ++y)
      for (int x = 0; x < kSide; ++x)
        for (int c = 0; c < 3; ++c) ASSERT_TRUE(std::isfinite(r->radiance.at(x, y, c))) << x << ", " << y;
  EXPECT_EQ(inside.visibility.at(pixel(2.0), kSide / 2, 0), 0.0f);
  EXPECT_NEAR(inside.radiance.at(pixel(2.0), kSide / 2, 0), radiance_of(0.0), 1e-7);
}

// soft: a sphere light of radius 0.5 fills a cone of sin α = r / d; wholly above the horizon its
// cosine-weighted integral is π sin² α cos θ, so the irradiance is the point light's I cos θ / d².
TEST(LocalLightsReference, ASphereLightUnoccludedGivesThePointLightsIrradiance) {
  const Result r =
      trace(scene_with(R"({"type": "point", "position": [0, 2, 0], "radius": 0.5, "intensity": [8, 8, 8]})"),
            Effect::soft, 64);
  const int row = kSide / 2;
  for (const auto& [x, e_cos] : {std::pair{0.0, 2.0}, {1.0, 1.4310835}, {3.0, 0.3413644}}) {
    EXPECT_NEAR(r.radiance.at(pixel(x), row, 0), radiance_of(e_cos), 5e-3 * radiance_of(e_cos)) << "x = " << x;
    EXPECT_EQ(r.visibility.at(pixel(x), row, 0), 1.0f) << "x = " << x;
    EXPECT_EQ(r.visibility.at(pixel(x), row, 2), 64.0f); // sample_count
  }
  // Radius 0: the soft effect traces the hard shadow, exactly.
  const Scene hard_light = scene_with(R"({"type": "point", "position": [0, 2, 0], "intensity": [8, 8, 8]})");
  const Result soft = trace(hard_light, Effect::soft, 16), hard = trace(hard_light);
  for (int y = 0; y < kSide; ++y)
    for (int x = 0; x < kSide; ++x) ASSERT_EQ(soft.radiance.at(x, y, 0), hard.radiance.at(x, y, 0)) << x << ", " << y;
}

// A half-plane occluder (x < 0, 1 m up) whose edge lies in the vertical plane through the point
// below the light and the light's centre: that plane halves the light's cone and mirrors its
// cosine weights, so exactly half the light is seen, 0.5 up to the sampling error.
TEST(LocalLightsReference, AHalfPlaneThroughTheSphereLightsCentreHidesHalfOfIt) {
  const std::string light = R"({"type": "point", "position": [0, 2, 0], "radius": 0.5, "intensity": [8, 8, 8]})";
  const auto half_plane = [](double edge) {
    return R"(, {"primitive": {"type": "box", "size": [10, 0.02, 10]}, "transform": {"translate": [)" +
           std::to_string(edge - 5.0) + ", 1, 0]}}";
  };
  // The camera looks past the occluder's edge at the origin (the middle pixel).
  const Result r = trace(scene_with(light, half_plane(0.0), "[2, 5.25, 0]"), Effect::soft, 1024);
  const int mid = kSide / 2;
  EXPECT_NEAR(r.visibility.at(mid, mid, 0), 0.5, 0.01);
  EXPECT_GT(r.visibility.at(mid, mid, 3), 0.0f); // std_error
  EXPECT_LT(r.visibility.at(mid, mid, 3), 0.02f);
  // The edge 0.3 m further into the shadowed side: more than half seen; 0.3 m the other way, less.
  EXPECT_GT(trace(scene_with(light, half_plane(-0.3), "[2, 5.25, 0]"), Effect::soft).visibility.at(mid, mid, 0), 0.6f);
  EXPECT_LT(trace(scene_with(light, half_plane(0.3), "[2, 5.25, 0]"), Effect::soft).visibility.at(mid, mid, 0), 0.4f);
}

// A disc occluder on the axis between the sphere light and the point below it: from that point the
// light fills the cap of half-angle α around the normal (sin α = r / d = 0.5 / 2) and the disc (radius
// 0.15, 1 m up) the cap of half-angle β (tan β = 0.15), β < α. A cap of half-angle θ around the
// normal has the cosine-weighted integral π sin² θ, so the seen share is 1 − sin² β / sin² α =
// 1 − (0.0225 / 1.0225) / 0.0625 = 0.6479218, and E = I (sin² α − sin² β) / r² = 1.2958436 W/m².
TEST(LocalLightsReference, ADiscOnTheAxisHidesTheClosedFormShareOfTheSphereLight) {
  const std::string light = R"({"type": "point", "position": [0, 2, 0], "radius": 0.5, "intensity": [8, 8, 8]})";
  const std::string disc = R"(, {"primitive": {"type": "cylinder", "radius": 0.15, "height": 0.0001, "segments": 1024},
      "transform": {"translate": [0, 1, 0]}})";
  // The camera looks past the disc at the origin (the middle pixel): its ray crosses y = 1 at x = 0.38.
  const Result r = trace(scene_with(light, disc, "[2, 5.25, 0]"), Effect::soft, 4096);
  const int mid = kSide / 2;
  const double seen = 1.0 - (0.0225 / 1.0225) / 0.0625;
  // The samples are stratified: the error measured is 0.0005, far below the reported standard error
  // (0.0074, an independent sample's); the solid angle instead of the projected one would give 0.6517.
  EXPECT_GT(r.visibility.at(mid, mid, 3), 0.0f);
  EXPECT_NEAR(r.visibility.at(mid, mid, 0), seen, 0.0015);
  // The camera sees the origin at cos θ = 5.25 / √(5.25² + 2²) but the light falls on it at θ = 0.
  EXPECT_NEAR(r.radiance.at(mid, mid, 0), radiance_of(2.0 * seen), 0.01 * radiance_of(2.0 * seen));
}

// translucent: a red pane (opacity 0.5, transmission colour [1, 0, 0]) 1 m up between the point
// light and the ground passes [1, 0.5, 0.5]; a second one 3 m up, beyond the light, passes
// nothing that arrives: the transmittance runs to the light only.
TEST(LocalLightsReference, TranslucentPanesBetweenTheLightAndTheGroundColourItsLight) {
  const std::string pane =
      R"(, {"primitive": {"type": "plane", "size": [40, 40]}, "transform": {"translate": [0, Y, 0]},
      "material": {"opacity": 0.5, "transmission_color": [1, 0, 0], "double_sided": true}})";
  const auto at = [&](const char* y) { return std::string(pane).replace(pane.find('Y'), 1, y); };
  const Result r =
      trace(scene_with(R"({"type": "point", "position": [0, 2, 0], "intensity": [8, 8, 8]})", at("1") + at("3")),
            Effect::translucent);
  const int x = pixel(1.0), y = kSide / 2;
  const glm::dvec3 t(1.0, 0.5, 0.5);
  for (int c = 0; c < 3; ++c) {
    EXPECT_NEAR(r.visibility_rgb.at(x, y, c), t[c], 1e-6) << c;
    EXPECT_NEAR(r.radiance.at(x, y, c), kAlbedo * (1.4310835 * t[c] / kPi + kAmbient), 2e-5) << c;
  }
  EXPECT_NEAR(r.visibility.at(x, y, 0), 2.0 / 3.0, 1e-6);
}

// filtered: a thin occluder 1 m up covering z < 0, its edge along x through the light's axis; the
// light 2 m above the plane. A receiver (x, 0, z) sees the edge at z / 2 in tangents of the map
// facing down (its plane at unit distance, the edge's direction there at tangent 0), so its light
// rays are blocked where z / 2 + o t < 0 (o the kernel's offset across the edge in texels, t the
// texel in tangents) and the filtered visibility is the kernel's CDF K1(z / (2 t)) — for every x,
// the edge being a line in the map.
const std::string kEdgeOccluder = R"(, {"primitive": {"type": "box", "size": [40, 0.0002, 10]},
    "transform": {"translate": [0, 1, -5]}})";

Result trace_filtered(const Scene& scene, int shadow_size, int filter_size = MSM_FILTER_DEFAULT_TAPS) {
  Settings s;
  s.effect = Effect::filtered;
  s.width = s.height = kSide;
  s.samples = 1024;
  s.shadow_size = shadow_size;
  s.filter_size = filter_size;
  return render(scene, s);
}

// The middle row sees z = 0; rows r > 10 see z = (r − 10) / 2.
int row_at(double z) { return 10 + int(std::lround(2.0 * z)); }

TEST(LocalLightsReference, FilteredSpotAcrossAStraightEdgeIsTheKernelsCdf) {
  const Scene scene = scene_with(kSpot, kEdgeOccluder);
  constexpr int kShadowSize = 8;
  const double texel = 2.0 * std::tan(kPi / 4.0) / kShadowSize; // the spot's outer cone: 45°
  const Result r = trace_filtered(scene, kShadowSize);
  const FilterKernel kernel(MSM_FILTER_DEFAULT_TAPS, MSM_FILTER_DEFAULT_SIGMA);
  for (double x : {-1.0, -0.5, 0.0, 0.5, 1.0}) // within the inner cone: one light, V its visibility
    for (double z : {0.0, 0.5, 1.0}) {
      const double expected = kernel.cdf(z / 2.0 / texel);
      const float v = r.visibility.at(pixel(x), row_at(z), 0);
      EXPECT_NEAR(v, expected, 0.01) << "x = " << x << ", z = " << z;
      EXPECT_EQ(r.visibility.at(pixel(x), row_at(z), 2), 1024.0f);
      std::printf("spot x %4.1f z %.1f: filtered %.4f, K1 %.4f\n", x, z, v, expected);
    }
}

// A point light's faces meet at 45°: 2 m from the point below it (x = 2 relative to the light). The cube's -y face sees the edge
// at z / 2 in its tangents, the +x face at z / x; the kernel continues on each face's plane across
// the seam, so on both sides of it (x = 1.5, 2, 2.5, the seam within the kernel's reach) the
// profile is that face's CDF, the two meeting at the seam. The range of 100 m lets the receiver
// plane's radial distance change by 2 m per texel (the renderer's clamp, MSM_MAX_RECEIVER_DEPTH_SLOPE
// of the range), more than the ground's does across these coarse texels near the seam.
TEST(LocalLightsReference, FilteredPointLightEdgeAcrossACubeSeamHasOneProfile) {
  const Scene scene =
      scene_with(R"({"type": "point", "position": [-2, 2, 0], "range": 100, "intensity": [8, 8, 8]})", kEdgeOccluder);
  constexpr int kShadowSize = 16;         // the kernel (±5 texels) stays below the ground's horizon
  const double texel = 2.0 / kShadowSize; // the face's 90° part
  const Result r = trace_filtered(scene, kShadowSize);
  const FilterKernel kernel(MSM_FILTER_DEFAULT_TAPS, MSM_FILTER_DEFAULT_SIGMA);
  for (double x : {1.5, 2.0, 2.5})
    for (double z : {0.0, 0.5, 1.0}) {
      const double along_axis = std::max(x, 2.0); // the face that holds (x, −2, z): −y up to x = 2, then +x
      const double expected = kernel.cdf(z / along_axis / texel);
      const float v = r.visibility.at(pixel(x - 2.0), row_at(z), 0); // the light 2 m to the left of x = 0
      EXPECT_NEAR(v, expected, 0.01) << "x = " << x << ", z = " << z;
      std::printf("point x %.1f z %.1f: filtered %.4f, K1 %.4f\n", x, z, v, expected);
    }
}

// A kernel of one tap spreads over one bilinear tent (±1 texel); with a map of 4096 texels that is
// 1 mm at the receivers, none of which lies that close to a shadow's edge: the filtered effect's
// images are the hard effect's, exactly.
TEST(LocalLightsReference, FilteredWithOneTapOfAFineMapIsTheHardShadow) {
  const std::string box = R"(, {"primitive": {"type": "box", "size": [0.5, 0.5, 0.5]},
      "transform": {"translate": [0, 1, 0]}})";
  for (const std::string& light :
       {std::string(R"({"type": "point", "position": [0, 2, 0], "intensity": [8, 8, 8]})"), kSpot}) {
    SCOPED_TRACE(light);
    const Scene scene = scene_with(light, box);
    const Result filtered = trace_filtered(scene, 4096, 1), hard = trace(scene);
    std::size_t shadowed = 0;
    for (int y = 0; y < kSide; ++y)
      for (int x = 0; x < kSide; ++x) {
        ASSERT_EQ(filtered.visibility.at(x, y, 0), hard.visibility.at(x, y, 0)) << x << ", " << y;
        for (int c = 0; c < 3; ++c)
          ASSERT_EQ(filtered.radiance.at(x, y, c), hard.radiance.at(x, y, c)) << x << ", " << y;
        shadowed += hard.visibility.at(x, y, 0) < 1.0f;
      }
    EXPECT_GT(shadowed, 0u);
  }
  // A directional light beside the spot, nothing in the way: each light's filtered visibility is 1.
  const Scene both = scene_with(R"({"towards_light": [0.3, 1, 0], "irradiance": [3, 3, 3]}, )" + kSpot);
  const Result filtered = trace_filtered(both, 4096, 1), hard = trace(both);
  for (int y = 0; y < kSide; ++y)
    for (int x = 0; x < kSide; ++x)
      for (int c = 0; c < 3; ++c) ASSERT_EQ(filtered.radiance.at(x, y, c), hard.radiance.at(x, y, c)) << x << ", " << y;
}

TEST(LocalLightsReference, FilteredRefusesLocalLightsWithSeveralDirectionalLights) {
  const Scene scene = scene_with(R"({"towards_light": [0, 1, 0], "irradiance": [3, 3, 3]},
                                    {"towards_light": [0.3, 1, 0], "irradiance": [3, 3, 3]}, )" +
                                 kSpot);
  Settings s;
  s.effect = Effect::filtered;
  s.width = s.height = 8;
  s.samples = 4;
  EXPECT_THROW(render(scene, s), std::invalid_argument);
}

// An unshadowed beam: a spot 1 m above the camera's central ray, its axis straight down, a hard cone
// of 30° (inner = outer), intensity 4 W/sr; the ray runs 6 m from the camera to the axis and on
// to a wall 6 m behind it, through an isotropic medium (p = 1 / 4π) of extinction σ = 1e-4 and
// albedo 1. The beam lights the ray over |x| <= tan 30° about the axis, where E = I / (1 + x²):
//   L = ∫ σ p I / (1 + x²) exp(−σ (6 + x)) dx = σ I / (4π) · 2 atan(tan 30°) · exp(−6σ) (1 + O(σ²))
//     = σ I exp(−6σ) / 12,
// the odd term of exp(−σ x) cancelling over the symmetric interval. With a plate 0.5 m wide across
// the beam 0.5 m below the light, whose edges at ±0.25 m cast to ±0.5 m on the ray, the light
// reaches |x| in [0.5, tan 30°] only: 2 (atan(tan 30°) − atan(0.5)) in place of 2 atan(tan 30°).
TEST(LocalLightsReference, SpotLightScatteringOfAnUnshadowedBeamByHand) {
  const auto beam = [](const std::string& extra) {
    return msm::scene::load_scene_json(
        R"({"msm_scene": 1, "camera": {"position": [-6, 0, 0], "target": [6, 0, 0], "fov_y_deg": 10, "near": 0.1,
            "far": 100},
          "lights": [{"type": "spot", "position": [0, 1, 0], "direction": [0, -1, 0], "inner_cone_deg": 30,
                      "outer_cone_deg": 30, "range": 100, "intensity": [4, 4, 4]}],
          "medium": {"extinction": 1e-4, "scattering_albedo": 1},
          "objects": [{"primitive": {"type": "box", "size": [1, 40, 40]}, "transform": {"translate": [6.5, 0, 0]}})" +
            extra + "]}",
        std::filesystem::current_path(), "beam.json");
  };
  const double sigma = 1e-4, intensity = 4.0;
  const auto centre = [](const Scene& scene) {
    Settings s;
    s.effect = Effect::scattering;
    s.width = s.height = 5; // the centre pixel's ray: NDC (0, 0), the camera's axis
    s.samples = 16384;
    return render(scene, s).scattering.at(2, 2, 0);
  };
  const double open = centre(beam(""));
  const double expected = sigma * intensity * std::exp(-6.0 * sigma) / 12.0;
  EXPECT_NEAR(open, expected, 0.01 * expected);
  const double blocked = centre(
      beam(R"(, {"primitive": {"type": "box", "size": [0.5, 0.001, 40]}, "transform": {"translate": [0, 0.5, 0]}})"));
  const double lit = 2.0 * (std::atan(std::tan(kPi / 6.0)) - std::atan(0.5));
  const double expected_blocked = sigma * intensity / (4.0 * kPi) * lit * std::exp(-6.0 * sigma);
  EXPECT_NEAR(blocked, expected_blocked, 0.01 * expected);
  std::printf("beam: open %.6g (by hand %.6g), half blocked %.6g (by hand %.6g)\n", open, expected, blocked,
              expected_blocked);
}

// scenes/street.json: a street at night (two point lights among columns, a spot light through a
// fence, faint moonlight). Taking an occluder away never darkens a pixel and brightens some: the
// fence's bars shadow the spot's light, the columns the lamps'.
TEST(LocalLightsReference, StreetOccludersOnlyEverTakeLightAway) {
  const Scene street = msm::scene::load_scene_file(std::filesystem::path(MSM_SCENES_DIR) / "street.json");
  ASSERT_EQ(street.light_count(msm::scene::LightKind::point), 2u);
  ASSERT_EQ(street.light_count(msm::scene::LightKind::spot), 1u);
  Settings s;
  s.effect = Effect::hard;
  s.width = 192;
  s.height = 108;
  const Result all = render(street, s);
  for (int y = 0; y < s.height; ++y)
    for (int x = 0; x < s.width; ++x)
      for (int c = 0; c < 3; ++c) ASSERT_TRUE(std::isfinite(all.radiance.at(x, y, c))) << x << ", " << y;
  EXPECT_GT(all.mean_visibility, 0.2);
  EXPECT_LT(all.mean_visibility, 0.98);
  for (const std::string& occluder : {std::string("fence"), std::string("column")}) {
    SCOPED_TRACE(occluder);
    Scene without = street;
    std::erase_if(without.objects, [&](const msm::scene::Object& o) { return o.name.starts_with(occluder); });
    ASSERT_LT(without.objects.size(), street.objects.size());
    const Result open = render(without, s);
    std::size_t brighter = 0, compared = 0;
    for (int y = 0; y < s.height; ++y)
      for (int x = 0; x < s.width; ++x) {
        // Only pixels that see the same object in both (not the occluder itself, nor behind it).
        const int seen = int(all.surface.at(x, y, 1)), seen_open = int(open.surface.at(x, y, 1));
        if (seen < 0 || seen_open < 0 || street.objects[seen].name != without.objects[seen_open].name) continue;
        ++compared;
        const float before = all.radiance.at(x, y, 1), after = open.radiance.at(x, y, 1);
        EXPECT_GE(after, before - 1e-6f * std::max(1.0f, before)) << x << ", " << y;
        brighter += after > before * 1.01f + 1e-6f;
      }
    EXPECT_GT(brighter, compared / 100) << brighter << " of " << compared << " pixels brighter";
  }
}

} // namespace
