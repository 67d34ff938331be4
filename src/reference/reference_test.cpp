// Tests of msm::reference against scenes with analytic answers:
//   - hard:        a ground plane under a half-plane occluder; every pixel against the exact edge
//                  (straight-down and tilted light), image orientation and the radiance formula;
//   - filtered:    the same scene: the profile across the edge against the integral of the
//                  sum-of-tents Gaussian kernel, along the light-space axis the edge crosses;
//   - soft:        the built-in scene "disc" (a thin disc occluder under a disc light) against
//                  disc_occluder_visibility of analytic.h, the intersection area of two circles
//                  (exact for the planar light model, see reference.h), itself checked against a
//                  numeric integral over the light; a rectangle light over the half-plane (a
//                  linear ramp); error convergence with the sample count;
//   - translucent: k parallel planes of opacity a give (1 - a)^k in every channel; planes with
//                  transmission colours give the product per channel, their mean as visibility;
//   - determinism across thread counts, and bad input.
// The analytic side uses its own camera model (look-at basis and tan(fov / 2)), not the library's
// matrices, so that the conventions themselves are checked.
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <numbers>
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <tbb/global_control.h>
#include <tbb/task_arena.h>

#include "msm/light_probe.h"
#include "msm/reference/analytic.h"
#include "msm/reference/reference.h"
#include "msm/scattering.h"
#include "msm/scene/scene.h"
#include "msm/test/reference_settings.h"

namespace {

using namespace msm::reference;
using msm::image::Image;
using msm::scene::Scene;

constexpr double kPi = std::numbers::pi;

std::string num(double v) {
  std::ostringstream s;
  s.precision(17);
  s << v;
  return s.str();
}
std::string vec(glm::dvec3 v) { return "[" + num(v.x) + ", " + num(v.y) + ", " + num(v.z) + "]"; }

struct CameraSpec {
  glm::dvec3 position, target, up{0.0, 1.0, 0.0};
  double fov_deg = 45.0, near = 0.01, far = 100.0;
  std::string json() const {
    return R"("camera": {"position": )" + vec(position) + R"(, "target": )" + vec(target) + R"(, "up": )" + vec(up) +
           R"(, "fov_y_deg": )" + num(fov_deg) + R"(, "near": )" + num(near) + R"(, "far": )" + num(far) + "}";
  }
  // The ray through the centre of pixel (x, y), y = 0 the top row (an independent model of the
  // rasterizer's conventions: look-at basis, vertical fov, aspect W / H).
  glm::dvec3 ray(int x, int y, int W, int H) const {
    const glm::dvec3 f = glm::normalize(target - position);
    const glm::dvec3 r = glm::normalize(glm::cross(f, up));
    const glm::dvec3 u = glm::cross(r, f);
    const double t = std::tan(fov_deg * kPi / 360.0);
    const double sx = ((x + 0.5) / W * 2.0 - 1.0) * t * double(W) / H;
    const double sy = ((y + 0.5) / H * 2.0 - 1.0) * t;
    return glm::normalize(f + sx * r - sy * u);
  }
};

Scene make_scene(const CameraSpec& camera, const std::string& light, const std::string& objects,
                 const std::string& extra = "") {
  const std::string json =
      R"({"msm_scene": 1, )" + camera.json() + ", " + light + ", " + extra + R"("objects": [)" + objects + "]}";
  return msm::scene::load_scene_json(json, std::filesystem::current_path(), "test.json");
}

std::string light_json(glm::dvec3 towards, double extent_deg = 0.0) {
  return R"("light": {"towards_light": )" + vec(towards) + R"(, "irradiance": [2, 2, 2], "angular_extent_deg": )" +
         num(extent_deg) + "}";
}

// Where the pixel's ray meets the ground y = 0 (the camera is above it, looking down).
glm::dvec3 ground_point(const CameraSpec& c, int x, int y, int W, int H) {
  const glm::dvec3 d = c.ray(x, y, W, H);
  return c.position + (-c.position.y / d.y) * d;
}

// The ground (20 x 20, albedo 0.5) and a half-plane occluder covering x < 0 at height h.
std::string ground_and_half_plane(double h, bool double_sided = false) {
  return R"({"name": "ground", "primitive": {"type": "plane", "size": [20, 20]}, "material": {"albedo": [0.5, 0.5, 0.5]}},
              {"name": "half", "primitive": {"type": "plane", "size": [10, 20]},
               "material": {"double_sided": )" +
         std::string(double_sided ? "true" : "false") + R"(}, "transform": {"translate": [-5, )" + num(h) + R"(, 0]}})";
}

// ---- The filter kernel, independently: k(s) = sum_k w_k tent(s - k), CDF per tap ---------------

double kernel_cdf(double s, int size, double sigma) {
  const int r = (size - 1) / 2;
  double total = 0.0, c = 0.0;
  for (int k = -r; k <= r; ++k) total += std::exp(-k * k / (2.0 * sigma * sigma));
  for (int k = -r; k <= r; ++k) {
    const double u = s - k;
    const double tent = u <= -1.0  ? 0.0
                        : u >= 1.0 ? 1.0
                        : u < 0.0  ? 0.5 * (u + 1) * (u + 1)
                                   : 1.0 - 0.5 * (1 - u) * (1 - u);
    c += std::exp(-k * k / (2.0 * sigma * sigma)) / total * tent;
  }
  return c;
}

float channel(const Image& image, const char* name, int x, int y) {
  const int c = image.find_channel(name);
  if (c < 0) throw std::runtime_error(std::string("no channel ") + name);
  return image.at(x, y, c);
}

template <class F>
void expect_invalid(F&& f, const std::string& fragment) {
  try {
    f();
    ADD_FAILURE() << "no exception (expected one mentioning '" << fragment << "')";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find(fragment), std::string::npos) << "'" << fragment << "' not in: " << e.what();
  }
}

} // namespace

// ---- hard ----------------------------------------------------------------------------------------

// Every pixel of a ground plane under a half-plane occluder (x < 0 at height 1) against the exact
// shadow edge x = -h Lx / Ly; only pixels whose centre lies within 1e-5 of the edge (or 1e-3 of a
// plane's rim) are skipped. Also: background where the ray misses, the occluder's back face seen
// from below (double-sided: visible to the light from its upper side, unlit on the viewer's side;
// single-sided: culled as the rasterizer culls it, the ray goes on to the background), and the
// radiance formula.
TEST(reference_hard, HalfPlaneEdgeIsExactPerPixel) {
  const double h = 1.0, inf = std::numeric_limits<double>::infinity();
  for (const glm::dvec3& towards : {glm::dvec3(0, 1, 0), glm::normalize(glm::dvec3(0.4, 1.0, 0.3))}) {
    SCOPED_TRACE("towards_light " + vec(towards));
    // Below the occluder, looking down and to the side, so that the edge runs diagonally
    // across the image; the top rows see the occluder from below, or nothing.
    const CameraSpec camera{{0.3, 0.6, 1.5}, {-0.6, 0.0, -0.5}};
    const Scene scene = make_scene(camera, light_json(towards), ground_and_half_plane(h, true));
    Settings s;
    s.effect = Effect::hard;
    s.width = 160;
    s.height = 120;
    const Result r = render(scene, s);
    const Result culled = render(make_scene(camera, light_json(towards), ground_and_half_plane(h, false)), s);
    ASSERT_EQ(r.visibility.channel_names(), (std::vector<std::string>{"visibility", "background"}));
    ASSERT_EQ(r.radiance.channels(), 3);
    const double edge_x = -h * towards.x / towards.y;
    int lit = 0, shadowed = 0, background = 0, underside = 0, skipped = 0;
    for (int y = 0; y < s.height; ++y)
      for (int x = 0; x < s.width; ++x) {
        const glm::dvec3 d = camera.ray(x, y, s.width, s.height);
        // Analytic first hit: the ground (y = 0, |x|, |z| < 10) or the occluder (y = h,
        // -10 < x < 0, |z| < 10).
        const double tg = d.y < 0.0 ? -camera.position.y / d.y : inf;
        const double to = d.y > 0.0 ? (h - camera.position.y) / d.y : inf;
        const glm::dvec3 pg = camera.position + (std::isfinite(tg) ? tg : 0.0) * d;
        const glm::dvec3 po = camera.position + (std::isfinite(to) ? to : 0.0) * d;
        const double rim_g = std::min(10.0 - std::abs(pg.x), 10.0 - std::abs(pg.z));
        const double rim_o = std::min({-po.x, 10.0 + po.x, 10.0 - std::abs(po.z)});
        const bool ground = std::isfinite(tg) && rim_g > 0.0;
        const bool occluder = std::isfinite(to) && rim_o > 0.0;
        if ((std::isfinite(tg) && std::abs(rim_g) < 1e-3) || (std::isfinite(to) && std::abs(rim_o) < 1e-3)) {
          ++skipped;
          continue;
        }
        const float v = channel(r.visibility, "visibility", x, y);
        const float bg = channel(r.visibility, "background", x, y);
        if (!ground && !occluder) {
          ASSERT_EQ(bg, 1.0f) << x << "," << y;
          ASSERT_EQ(v, 1.0f);
          ASSERT_EQ(r.radiance.at(x, y, 0), 0.0f);
          ++background;
          continue;
        }
        ASSERT_EQ(bg, 0.0f) << x << "," << y;
        if (occluder) { // seen from below: nothing above it; n faces the viewer, n.l < 0
          ASSERT_EQ(v, 1.0f) << x << "," << y;
          ASSERT_NEAR(r.radiance.at(x, y, 0), 0.03 * 0.8, 1e-7);
          ASSERT_EQ(channel(culled.visibility, "background", x, y), 1.0f) << "single-sided: culled";
          ++underside;
          continue;
        }
        ASSERT_EQ(channel(culled.visibility, "visibility", x, y), v) << x << "," << y;
        if (std::abs(pg.x - edge_x) < 1e-5) {
          ++skipped;
          continue;
        }
        const float expected = pg.x > edge_x ? 1.0f : 0.0f;
        ASSERT_EQ(v, expected) << "pixel " << x << "," << y << " ground x " << pg.x << " edge " << edge_x;
        (expected > 0.5f ? lit : shadowed)++;
        // albedo * E * cos / pi * V + 0.03 albedo, with n = +Y.
        const double radiance = 0.5 * 2.0 * towards.y / kPi * expected + 0.03 * 0.5;
        for (int c = 0; c < 3; ++c) ASSERT_NEAR(r.radiance.at(x, y, c), radiance, 1e-6 * radiance);
      }
    EXPECT_GT(lit, 2000);
    EXPECT_GT(shadowed, 2000);
    EXPECT_GT(background, 200);
    EXPECT_GT(underside, 200);
    EXPECT_LE(skipped, 10);
    RecordProperty(towards.x == 0.0 ? "pixels_straight" : "pixels_tilted",
                   std::to_string(lit) + " lit, " + std::to_string(shadowed) + " shadowed, " +
                       std::to_string(underside) + " occluder, " + std::to_string(background) + " background, " +
                       std::to_string(skipped) + " skipped");
    EXPECT_NEAR(double(r.background_pixels), background, skipped);
    EXPECT_EQ(r.samples, 1);
    // One primary ray per pixel, one shadow ray per covered pixel.
    EXPECT_EQ(r.rays, std::uint64_t(s.width * s.height) * 2 - r.background_pixels);
  }
}

// Row 0 is the top of the image and column 0 its left: a box to the right of and above the view
// centre shows up in the top-right quadrant; the ground fills the bottom rows.
TEST(reference_hard, ImageOrientation) {
  const CameraSpec camera{{0, 1, 5}, {0, 1, 0}};
  const Scene scene = make_scene(camera, light_json({0, 1, 0}),
                                 R"({"primitive": {"type": "plane", "size": [1000, 1000]}},
                                      {"primitive": {"type": "box", "size": [0.4, 0.4, 0.4]}, "transform": {"translate": [1, 1.6, 0]}})");
  Settings s;
  s.width = 40;
  s.height = 30;
  const Result r = render(scene, s);
  int box_pixels = 0;
  for (int y = 0; y < s.height; ++y)
    for (int x = 0; x < s.width; ++x) {
      const bool bg = channel(r.visibility, "background", x, y) > 0.5f;
      if (y >= s.height / 2) { EXPECT_FALSE(bg) << "bottom half must show the ground: " << x << "," << y; }
      if (y < s.height / 2 && !bg) {
        EXPECT_GE(x, s.width / 2) << "the box is to the right";
        ++box_pixels;
      }
    }
  EXPECT_GT(box_pixels, 4);
  EXPECT_EQ(channel(r.visibility, "background", 0, 0), 1.0f);
}

// ---- filtered ------------------------------------------------------------------------------------

struct ProfileCase {
  glm::dvec3 towards;
  double texel;   // the texel size along the light-space axis the edge crosses
  double stretch; // ground distance per light-space distance across the edge (1 / cos)
};

// The filtered visibility across the half-plane's edge is the kernel's 1D CDF of the light-space
// distance to the edge in texels: V(p) = K1((p.x - edge) / stretch / texel). Straight-down light:
// light-space x is world x (texel 6/256). Light tilted by 30 degrees in the x-y plane: the edge
// crosses light-space y (texel 8/256) and the receiver plane stretches it by 1 / cos 30.
TEST(reference_filtered, EdgeProfileMatchesTheKernel) {
  const double h = 1.0, phi = 30.0 * kPi / 180.0;
  const ProfileCase cases[] = {{{0, 1, 0}, 6.0 / 256, 1.0},
                               {{std::sin(phi), std::cos(phi), 0}, 8.0 / 256, 1.0 / std::cos(phi)}};
  for (const ProfileCase& pc : cases) {
    SCOPED_TRACE("towards_light " + vec(pc.towards));
    const double edge_x = -h * pc.towards.x / pc.towards.y;
    const CameraSpec camera{{edge_x, 0.06, 0.0}, {edge_x, 0.0, 0.0}, {0, 0, -1}};
    const Scene scene = make_scene(
        camera, light_json(pc.towards), ground_and_half_plane(h),
        R"("shadow_map": {"framing": "explicit", "center": [0, 0.5, 0], "extent": [6, 8], "depth_range": [-5, 5]}, )");
    const LightFrame frame = scene.light_frame();
    EXPECT_NEAR(frame.extent.x, 6.0, 1e-5);
    EXPECT_NEAR(frame.extent.y, 8.0, 1e-5);
    Settings s = msm::test::reference_settings(Effect::filtered, 96, 8, 4096);
    s.shadow_size = 256;
    s.seed = 7;
    const Result r = render(scene, s);
    ASSERT_EQ(r.visibility.channel_names(),
              (std::vector<std::string>{"visibility", "background", "sample_count", "std_error"}));
    double sum_err = 0, sum_err2 = 0, sum_var = 0, sum_iid_var = 0, worst = 0;
    int penumbra = 0;
    for (int y = 0; y < s.height; ++y)
      for (int x = 0; x < s.width; ++x) {
        const glm::dvec3 p = ground_point(camera, x, y, s.width, s.height);
        const double expected = kernel_cdf((p.x - edge_x) / pc.stretch / pc.texel, 9, 2.4);
        const double v = channel(r.visibility, "visibility", x, y);
        const double se = channel(r.visibility, "std_error", x, y);
        ASSERT_EQ(channel(r.visibility, "sample_count", x, y), 4096.0f);
        ASSERT_EQ(channel(r.visibility, "background", x, y), 0.0f);
        // The error bound: 4 standard errors of independent sampling (an upper bound of
        // the stratified sampler's error), reported or from the true value, + 1e-6.
        const double iid = std::sqrt(expected * (1.0 - expected) / s.samples);
        ASSERT_LE(std::abs(v - expected), 4.0 * std::max(se, iid) + 1e-6)
            << "pixel " << x << "," << y << " ground x " << p.x << " expected " << expected << " got " << v;
        worst = std::max(worst, std::abs(v - expected));
        if (expected > 0.02 && expected < 0.98) {
          ++penumbra;
          sum_err += v - expected;
          sum_err2 += (v - expected) * (v - expected);
          sum_var += se * se;
          sum_iid_var += iid * iid;
        }
      }
    ASSERT_GT(penumbra, 200);
    // No bias: the mean error over the penumbra within 4 of its standard errors.
    EXPECT_LE(std::abs(sum_err / penumbra), 4.0 * std::sqrt(sum_var) / penumbra);
    // The reported standard error is that of independent samples (within 10 %), and the
    // stratified estimate is at least that good (RMS error below the RMS standard error).
    EXPECT_NEAR(std::sqrt(sum_var / sum_iid_var), 1.0, 0.1);
    EXPECT_LT(std::sqrt(sum_err2 / penumbra), std::sqrt(sum_var / penumbra));
    RecordProperty("rms_max_error_" + std::to_string(int(pc.texel * 256)),
                   num(std::sqrt(sum_err2 / penumbra)) + " " + num(worst) + " over " + std::to_string(penumbra));
  }
}

TEST(reference_filtered, KernelSamplingHasTheKernelsDistribution) {
  // FilterKernel::sample maps uniform u to offsets with CDF cdf(); cdf matches the test's own,
  // computed in double from the Gaussian. The kernel's weights are the renderer's floats
  // (msm/filter.h): they sum to 1 and follow the double Gaussian within float rounding (each
  // weight within 1 ulp, 6e-8 relative, of its double value).
  const FilterKernel k(9, 2.4);
  double total = 0.0;
  for (double w : k.weights()) total += w;
  EXPECT_NEAR(total, 1.0, 1e-7);
  for (double s = -6.0; s <= 6.0; s += 0.37)
    EXPECT_NEAR(k.cdf(s), kernel_cdf(s, 9, 2.4), 1e-7 * kernel_cdf(s, 9, 2.4) + 1e-15);
  // Empirical CDF of 2^16 evenly spaced u against cdf(): Kolmogorov distance ~ 1 / 2^16.
  std::vector<double> samples;
  const int n = 1 << 16;
  samples.reserve(n);
  for (int i = 0; i < n; ++i) samples.push_back(k.sample((i + 0.5) / n));
  std::sort(samples.begin(), samples.end());
  double worst = 0.0;
  for (int i = 0; i < n; i += 7) worst = std::max(worst, std::abs(k.cdf(samples[i]) - (i + 0.5) / n));
  EXPECT_LT(worst, 2e-5);
  EXPECT_THROW(FilterKernel(8, 2.4), std::invalid_argument);
  EXPECT_THROW(FilterKernel(9, 0.0), std::invalid_argument);
}

// ---- soft ----------------------------------------------------------------------------------------

namespace {

// The built-in scene "disc" (scenes/disc.json): a disc occluder (a cylinder 1e-4 thick, 1024
// segments) of radius 0.25 centred 1 above the origin; the ground seen from between the two,
// straight down; the light straight down. The answer is disc_occluder_visibility (analytic.h),
// whose defaults are the scene's values (checked by BuiltinDiscSceneHasTheAnalyticGeometry).
struct DiscScene {
  Scene scene;
  CameraSpec camera; // the scene's camera, for the test's own camera model
  explicit DiscScene(double extent_deg) : scene(msm::scene::builtin_scene("disc")) {
    scene.lights[0].angular_extent_deg = float(extent_deg);
    const msm::scene::Camera& c = scene.camera;
    camera = CameraSpec{glm::dvec3(c.position), glm::dvec3(c.target), glm::dvec3(c.up), double(c.fov_y_deg)};
  }
};

struct SoftErrors {
  double rms = 0.0, worst = 0.0; // over the penumbra; over every pixel
  int penumbra = 0, umbra = 0, lit = 0;
};

// The ray-traced soft visibility of the disc scene against disc_occluder_visibility at each
// pixel's ground point. With check_bound, every pixel within 4 standard errors (of independent
// sampling, an upper bound for the stratified sampler) + 1e-4 (the model's own error, see
// analytic.h), with all its samples taken.
SoftErrors soft_errors(const DiscScene& ds, const Settings& s, bool check_bound) {
  const Result r = render(ds.scene, s);
  EXPECT_NEAR(r.light_extent_deg, 10.0, 1e-12);
  EXPECT_EQ(r.background_pixels, 0u);
  double sum2 = 0.0;
  SoftErrors e;
  for (int y = 0; y < s.height; ++y)
    for (int x = 0; x < s.width; ++x) {
      const glm::dvec3 p = ground_point(ds.camera, x, y, s.width, s.height);
      const double expected = disc_occluder_visibility(p, 10.0);
      const double v = channel(r.visibility, "visibility", x, y);
      const double se = channel(r.visibility, "std_error", x, y);
      if (check_bound) {
        EXPECT_EQ(channel(r.visibility, "sample_count", x, y), float(s.samples));
        const double iid = std::sqrt(expected * (1.0 - expected) / s.samples);
        EXPECT_LE(std::abs(v - expected), 4.0 * std::max(se, iid) + 1e-4)
            << "pixel " << x << "," << y << " expected " << expected << " got " << v << " se " << se;
      }
      e.worst = std::max(e.worst, std::abs(v - expected));
      if (expected > 0.01 && expected < 0.99) {
        sum2 += (v - expected) * (v - expected);
        ++e.penumbra;
      }
      e.umbra += expected == 0.0;
      e.lit += expected == 1.0;
    }
  e.rms = std::sqrt(sum2 / e.penumbra);
  return e;
}

// The same at 64 x 64 with this sampler, sample count and seed.
SoftErrors soft_errors(const DiscScene& ds, Sampler sampler, int samples, std::uint64_t seed, bool check_bound) {
  Settings s = msm::test::reference_settings(Effect::soft, 64, 64, samples);
  s.seed = seed;
  s.sampler = sampler;
  return soft_errors(ds, s, check_bound);
}

} // namespace

// The scene file and the analytic model describe the same geometry: DiscOccluder's defaults are
// the "disc" scene's values, the light is straight down, and the camera sits between the ground
// and the disc (it sees ground points only).
TEST(reference_soft, BuiltinDiscSceneHasTheAnalyticGeometry) {
  const Scene scene = msm::scene::builtin_scene("disc");
  const DiscOccluder disc;
  ASSERT_EQ(scene.objects.size(), 2u);
  const msm::scene::Object& ground = scene.objects[0];
  const msm::scene::Object& occluder = scene.objects[1];
  EXPECT_EQ(ground.name, "ground");
  EXPECT_EQ(occluder.name, "disc");
  EXPECT_EQ(ground.bounds.min.y, 0.0f);
  EXPECT_EQ(ground.bounds.max.y, 0.0f);
  // The 1024-gon has vertices on the four axis directions: its bounds are the disc's, up to
  // float rounding of the radius and of the height (1 +- 5e-5 rounds to 6e-8).
  EXPECT_NEAR(occluder.bounds.min.x, -disc.radius, 1e-6);
  EXPECT_NEAR(occluder.bounds.max.x, disc.radius, 1e-6);
  EXPECT_NEAR(occluder.bounds.min.z, -disc.radius, 1e-6);
  EXPECT_NEAR(occluder.bounds.max.z, disc.radius, 1e-6);
  EXPECT_NEAR(occluder.bounds.min.y, disc.center_height - 0.5 * disc.thickness, 1e-6);
  EXPECT_NEAR(occluder.bounds.max.y, disc.center_height + 0.5 * disc.thickness, 1e-6);
  EXPECT_EQ(occluder.mesh.triangle_count(), 4u * 1024u);
  EXPECT_EQ(scene.light().towards_light, glm::vec3(0.0f, 1.0f, 0.0f));
  EXPECT_EQ(scene.light().angular_extent_deg, 10.0f);
  EXPECT_GT(scene.camera.position.y, 0.0f);
  EXPECT_LT(scene.camera.position.y, occluder.bounds.min.y);
}

// disc_occluder_visibility against a midpoint-rule integral over the light's disc (a 1200 x 1200
// grid over its bounding square in the plane at unit distance; a direction is blocked when the
// ray from p meets the lower face within the disc's radius). The grid's error is about the
// rim's share of cells, ~ 2 / 1200 of the light at most: tolerance 2e-3. Also the limits: far
// away 1; under the centre 0 while the light is smaller than the occluder (10 degrees) and above 0
// when it is larger (60 degrees: the light's image has radius tan 30 = 0.58 > 0.25); extent 0
// is the hard shadow; a bad extent throws.
TEST(reference_soft, DiscVisibilityFormulaMatchesNumericIntegration) {
  const DiscOccluder disc;
  const double h = disc.center_height - 0.5 * disc.thickness;
  const auto integral = [&](glm::dvec3 p, double extent_deg) {
    const double t = std::tan(extent_deg * kPi / 360.0);
    const int n = 1200;
    long inside = 0, visible = 0;
    for (int i = 0; i < n; ++i)
      for (int j = 0; j < n; ++j) {
        const double a = ((i + 0.5) / n * 2.0 - 1.0) * t, b = ((j + 0.5) / n * 2.0 - 1.0) * t;
        if (a * a + b * b > t * t) continue;
        ++inside;
        // The ray p + s (a, 1, b) reaches y = h at s = h.
        visible += std::hypot(p.x + h * a, p.z + h * b) >= disc.radius;
      }
    return double(visible) / double(inside);
  };
  for (double extent : {2.0, 10.0, 30.0})
    for (double r : {0.0, 0.2, 0.24, 0.25, 0.26, 0.3, 0.4}) {
      const glm::dvec3 p(r * 0.6, 0.0, -r * 0.8);
      SCOPED_TRACE("extent " + num(extent) + " r " + num(r));
      EXPECT_NEAR(disc_occluder_visibility(p, extent), integral(p, extent), 2e-3);
    }
  EXPECT_EQ(disc_occluder_visibility({2.0, 0.0, 0.0}, 10.0), 1.0);
  EXPECT_EQ(disc_occluder_visibility({0.0, 0.0, 0.0}, 10.0), 0.0);
  EXPECT_GT(disc_occluder_visibility({0.0, 0.0, 0.0}, 60.0), 0.1);
  EXPECT_NEAR(disc_occluder_visibility({0.0, 0.0, 0.0}, 60.0), integral({0.0, 0.0, 0.0}, 60.0), 2e-3);
  EXPECT_EQ(disc_occluder_visibility({0.2499, 0.0, 0.0}, 0.0), 0.0);
  EXPECT_EQ(disc_occluder_visibility({0.2501, 0.0, 0.0}, 0.0), 1.0);
  // Scaling the scene leaves the visibility unchanged (it depends on ratios only).
  EXPECT_NEAR(disc_occluder_visibility({0.6, 0.0, 0.0}, 10.0, {0.5, 2.0, 2e-4}),
              disc_occluder_visibility({0.3, 0.0, 0.0}, 10.0), 1e-12);
  EXPECT_THROW(disc_occluder_visibility({0.0, 0.0, 0.0}, 90.0), std::invalid_argument);
  EXPECT_THROW(disc_occluder_visibility({0.0, 0.0, 0.0}, -1.0), std::invalid_argument);
}

// The built-in "disc" scene as it is (its 10-degree light, its camera, 16:9): every pixel of the
// ray-traced soft visibility against disc_occluder_visibility at the pixel's ground point, within
// 4 standard errors (of independent sampling, an upper bound for the stratified sampler) + 1e-4
// (the model's own error, see analytic.h); RMS over the penumbra below 0.01 at 256 samples.
TEST(reference_soft, DiscLightOverDiscOccluderMatchesTheCircleIntersection) {
  Settings s = msm::test::reference_settings(Effect::soft, 160, 90, 256);
  s.seed = 3;
  const SoftErrors e = soft_errors(DiscScene(10.0), s, true);
  // The view holds the whole shadow: umbra (r < 0.1625), penumbra ring and lit ground.
  EXPECT_GT(e.penumbra, 3500);
  EXPECT_GT(e.umbra, 1000);
  EXPECT_GT(e.lit, 5000);
  EXPECT_LT(e.rms, 0.01);
  RecordProperty("rms_max_error_256_stratified",
                 num(e.rms) + " " + num(e.worst) + " over " + std::to_string(e.penumbra));
}

// Plain Monte Carlo (independent samples): the RMS error halves when the samples quadruple
// (ratio 2, accepted in [1.6, 2.5]); stratified samples converge at least as fast and are more
// accurate at equal count.
TEST(reference_soft, ErrorConvergence) {
  const DiscScene ds(10.0);
  const SoftErrors i16 = soft_errors(ds, Sampler::independent, 16, 11, true);
  const SoftErrors i64 = soft_errors(ds, Sampler::independent, 64, 12, true);
  const SoftErrors i256 = soft_errors(ds, Sampler::independent, 256, 13, true);
  const SoftErrors s16 = soft_errors(ds, Sampler::stratified, 16, 14, true);
  const SoftErrors s64 = soft_errors(ds, Sampler::stratified, 64, 15, true);
  EXPECT_GE(i16.rms / i64.rms, 1.6);
  EXPECT_LE(i16.rms / i64.rms, 2.5);
  EXPECT_GE(i64.rms / i256.rms, 1.6);
  EXPECT_LE(i64.rms / i256.rms, 2.5);
  EXPECT_GE(s16.rms / s64.rms, 1.6);
  EXPECT_LT(s16.rms, i16.rms);
  EXPECT_LT(s64.rms, i64.rms);
  RecordProperty("rms_independent_16_64_256", num(i16.rms) + " " + num(i64.rms) + " " + num(i256.rms));
  RecordProperty("rms_stratified_16_64", num(s16.rms) + " " + num(s64.rms));
  std::printf("RMS error, independent 16/64/256: %.5f %.5f %.5f; stratified 16/64: %.5f %.5f\n", i16.rms, i64.rms,
              i256.rms, s16.rms, s64.rms);
}

// A rectangle light 8 x 20 degrees over the half-plane occluder, light straight down: light-space
// x is world x, so the visibility is a linear ramp across the light's 8-degree WIDTH:
// V = clamp((x / h + tan 4) / (2 tan 4), 0, 1).
TEST(reference_soft, RectangleLightOverHalfPlaneIsALinearRamp) {
  const double h = 1.0, tw = std::tan(4.0 * kPi / 180.0);
  const CameraSpec camera{{0.0, 0.06, 0.0}, {0.0, 0.0, 0.0}, {0, 0, -1}};
  const Scene scene = make_scene(camera, light_json({0, 1, 0}), ground_and_half_plane(h));
  Settings s = msm::test::reference_settings(Effect::soft, 96, 8, 256);
  s.light_shape = LightShape::rectangle;
  s.light_width_deg = 8.0;
  s.light_height_deg = 20.0;
  const Result r = render(scene, s);
  EXPECT_DOUBLE_EQ(r.light_width_deg, 8.0);
  EXPECT_DOUBLE_EQ(r.light_height_deg, 20.0);
  int ramp = 0;
  for (int y = 0; y < s.height; ++y)
    for (int x = 0; x < s.width; ++x) {
      const glm::dvec3 p = ground_point(camera, x, y, s.width, s.height);
      const double expected = std::clamp((p.x / h + tw) / (2.0 * tw), 0.0, 1.0);
      const double v = channel(r.visibility, "visibility", x, y);
      const double se = channel(r.visibility, "std_error", x, y);
      const double iid = std::sqrt(expected * (1.0 - expected) / s.samples);
      ASSERT_LE(std::abs(v - expected), 4.0 * std::max(se, iid) + 1e-5)
          << "pixel " << x << "," << y << " ground x " << p.x << " expected " << expected << " got " << v;
      ramp += expected > 0.05 && expected < 0.95;
    }
  EXPECT_GT(ramp, 100);
}

// A scene light declared as a rectangle (angular_height_deg) is traced as that rectangle without any
// override: the same image, sample for sample, as the explicit --light-shape rectangle with its
// extents; --light-shape disc and --light-extent-deg alone (which makes it a disc, as in the renderer:
// scene::overridden_light) trace the disc; --light-height-deg keeps the scene's width.
TEST(reference_soft, SceneRectangleLightIsTracedAsDeclared) {
  const CameraSpec camera{{0.0, 0.06, 0.0}, {0.0, 0.0, 0.0}, {0, 0, -1}};
  const std::string light =
      R"("light": {"towards_light": [0, 1, 0], "angular_extent_deg": 8, "angular_height_deg": 20})";
  const Scene scene = make_scene(camera, light, ground_and_half_plane(1.0));
  Settings s = msm::test::reference_settings(Effect::soft, 48, 8, 64);
  const Result declared = render(scene, s);
  EXPECT_EQ(declared.light_shape, LightShape::rectangle);
  EXPECT_DOUBLE_EQ(declared.light_width_deg, 8.0);
  EXPECT_DOUBLE_EQ(declared.light_height_deg, 20.0);
  Settings explicit_rectangle = s;
  explicit_rectangle.light_shape = LightShape::rectangle;
  explicit_rectangle.light_width_deg = 8.0;
  explicit_rectangle.light_height_deg = 20.0;
  EXPECT_EQ(declared.visibility, render(scene, explicit_rectangle).visibility);
  Settings disc = s;
  disc.light_shape = LightShape::disc;
  const Result as_disc = render(scene, disc);
  EXPECT_EQ(as_disc.light_shape, LightShape::disc);
  EXPECT_DOUBLE_EQ(as_disc.light_height_deg, 8.0);
  EXPECT_NE(as_disc.visibility, declared.visibility);
  Settings extent = s;
  extent.light_extent_deg = 8.0;
  const Result extent_disc = render(scene, extent);
  EXPECT_EQ(extent_disc.light_shape, LightShape::disc);
  EXPECT_EQ(extent_disc.visibility, as_disc.visibility);
  Settings height = s;
  height.light_height_deg = 4.0;
  const TracedLight lower = traced_light(scene.light(), height);
  EXPECT_EQ(lower.shape, LightShape::rectangle);
  EXPECT_DOUBLE_EQ(lower.width_deg, 8.0);
  EXPECT_DOUBLE_EQ(lower.height_deg, 4.0);
  // A width or height with a disc is refused.
  disc.light_height_deg = 4.0;
  EXPECT_THROW(validate(disc), std::invalid_argument);
}

TEST(reference_soft, ZeroExtentIsTheHardShadow) {
  const DiscScene ds(0.0);
  Settings s;
  s.width = s.height = 24;
  s.effect = Effect::hard;
  const Result hard = render(ds.scene, s);
  s.effect = Effect::soft;
  s.samples = 4;
  const Result soft = render(ds.scene, s);
  EXPECT_EQ(hard.visibility.channel("visibility"), soft.visibility.channel("visibility"));
  EXPECT_EQ(soft.visibility.channel("std_error"), Image(24, 24, 1, 0.0f));
}

// The radiance of an unoccluded ground under a disc light of 60° (α = 30°) at elevations where the
// cone is above the horizon (exact: n·L), straddles it and is mostly below it: the sampled
// cosine integral (in units of the irradiance on a facing surface) against msm_cone_cosine
// (msm/light_probe.h), which the renderer shades with. The image mean must lie within 4 standard
// errors (of the per-pixel spread) of it: measured 0.2-0.7 standard errors, the worst pixel 0.0032
// off (bound 0.01) where max(n·L, 0) is 0.076 off at -5°. A 20° x 60° rectangle above the horizon:
// exactly n·L.
TEST(reference_soft, RadianceIntegratesTheCosineOverTheLightAndItsHorizon) {
  const CameraSpec camera{{0.0, 3.0, -3.0}, {0.0, 0.0, 0.0}};
  const std::string ground =
      R"({"primitive": {"type": "plane", "size": [20, 20]}, "material": {"albedo": [0.5, 0.5, 0.5]}})";
  for (double elevation : {50.0, 20.0, 5.0, -5.0, -25.0}) {
    const double e = elevation * kPi / 180.0;
    const glm::dvec3 towards(0.0, std::sin(e), std::cos(e));
    const Scene scene = make_scene(camera, light_json(towards, 60.0), ground);
    Settings s = msm::test::reference_settings(Effect::soft, 16, 16, 256);
    const Result r = render(scene, s);
    ASSERT_EQ(r.background_pixels, 0u);
    const double lit = msm::msm_cone_cosine(float(towards.y), float(kPi / 6.0));
    double sum = 0.0, sum2 = 0.0, worst = 0.0;
    const int n = s.width * s.height;
    for (int y = 0; y < s.height; ++y)
      for (int x = 0; x < s.width; ++x) {
        const double direct = (r.radiance.at(x, y, 1) - 0.03 * 0.5) / (0.5 * 2.0 / kPi);
        sum += direct;
        sum2 += direct * direct;
        worst = std::max(worst, std::abs(direct - lit));
        if (elevation > 30.0) { ASSERT_NEAR(direct, towards.y, 1e-5 * towards.y) << x << "," << y; }
      }
    const double mean = sum / n, se = std::sqrt(std::max(sum2 / n - mean * mean, 0.0) / (n - 1));
    std::printf("[reference soft, 60° disc %+.0f° above the ground] msm_cone_cosine %.5f, image mean %.5f (standard "
                "error %.1e), worst pixel %.1e off\n",
                elevation, lit, mean, se, worst);
    EXPECT_LE(std::abs(mean - lit), 4.0 * se + 1e-4) << elevation;
    EXPECT_LT(worst, 0.01) << elevation;
  }
  const glm::dvec3 towards = glm::normalize(glm::dvec3(0.2, 1.0, 0.4));
  const Scene scene = make_scene(camera, light_json(towards, 10.0), ground);
  Settings s;
  s.effect = Effect::soft;
  s.light_shape = LightShape::rectangle;
  s.light_width_deg = 20.0;
  s.light_height_deg = 60.0;
  s.width = s.height = 8;
  s.samples = 64;
  const Result r = render(scene, s);
  for (int y = 0; y < s.height; ++y)
    for (int x = 0; x < s.width; ++x)
      ASSERT_NEAR(r.radiance.at(x, y, 1), 0.5 * 2.0 * towards.y / kPi + 0.03 * 0.5, 1e-5) << x << "," << y;
}

// ---- translucent ---------------------------------------------------------------------------------

// k parallel planes of opacity a between the ground and a tilted light: T = (1 - a)^k.
TEST(reference_translucent, StackOfPlanesGivesPowerOfOneMinusOpacity) {
  const double alpha = 0.3;
  const glm::dvec3 towards = glm::normalize(glm::dvec3(0.3, 1.0, 0.2));
  const CameraSpec camera{{0.0, 0.5, 0.3}, {0.0, 0.0, -0.2}};
  for (int k = 0; k <= 4; ++k) {
    std::string objects =
        R"({"primitive": {"type": "plane", "size": [10, 10]}, "material": {"albedo": [0.5, 0.5, 0.5]}})";
    for (int i = 1; i <= k; ++i)
      objects += R"(, {"primitive": {"type": "plane", "size": [60, 60]}, "transform": {"translate": [0, )" + num(i) +
                 R"(, 0]}, "material": {"opacity": )" + num(alpha) + "}}";
    const Scene scene = make_scene(camera, light_json(towards), objects);
    Settings s;
    s.effect = Effect::translucent;
    s.width = s.height = 16;
    const Result r = render(scene, s);
    ASSERT_EQ(r.background_pixels, 0u);
    const double expected = std::pow(1.0 - alpha, k);
    double worst = 0.0;
    for (int y = 0; y < s.height; ++y)
      for (int x = 0; x < s.width; ++x) {
        ASSERT_NEAR(channel(r.visibility, "visibility", x, y), expected, 1e-6)
            << "k " << k << " pixel " << x << "," << y;
        worst = std::max(worst, std::abs(channel(r.visibility, "visibility", x, y) - expected));
        // Grey materials: three equal channels, exactly the scalar visibility.
        for (const char* c : {"visibility_r", "visibility_g", "visibility_b"})
          ASSERT_EQ(channel(r.visibility_rgb, c, x, y), channel(r.visibility, "visibility", x, y)) << c;
        const double radiance = 0.5 * 2.0 * towards.y / kPi * expected + 0.03 * 0.5;
        for (int c = 0; c < 3; ++c) ASSERT_NEAR(r.radiance.at(x, y, c), radiance, 1e-6);
        ASSERT_EQ(r.radiance.at(x, y, 0), r.radiance.at(x, y, 2));
      }
    RecordProperty("max_error_k" + std::to_string(k), num(worst));
    if (k == 4) { // the crossing cap counts the first max_crossings surfaces only
      s.max_crossings = 2;
      const Result capped = render(scene, s);
      EXPECT_NEAR(channel(capped.visibility, "visibility", 5, 5), (1.0 - alpha) * (1.0 - alpha), 1e-6);
    }
  }
}

// Coloured transmission (JCGT 2017, Sec. 3): under plane 1 (alpha 0.6, transmission colour
// (1, 0, 0)) and plane 2 (alpha 0.5, (0, 0, 1)), lit straight down, T = (1 * 0.5, 0.4 * 0.5,
// 0.4 * 1) = (0.5, 0.2, 0.4) and visibility = their mean; radiance per channel. A stained glass of
// opacity 1 lets its colour through and is looked through by the primary rays.
TEST(reference_translucent, TransmissionColourPerChannel) {
  const glm::dvec3 towards(0, 1, 0);
  const std::string ground =
      R"({"primitive": {"type": "plane", "size": [10, 10]}, "material": {"albedo": [0.5, 0.5, 0.5]}})";
  const auto plane = [](double height, double alpha, const std::string& colour) {
    return R"(, {"primitive": {"type": "plane", "size": [20, 20]}, "transform": {"translate": [0, )" + num(height) +
           R"(, 0]}, "material": {"opacity": )" + num(alpha) + R"(, "transmission_color": )" + colour + "}}";
  };
  const auto check = [&](const Result& r, int W, int H, glm::dvec3 expected, const std::string& what) {
    SCOPED_TRACE(what);
    ASSERT_EQ(r.visibility.channel_names(), (std::vector<std::string>{"visibility", "background"}));
    ASSERT_EQ(r.visibility_rgb.channel_names(),
              (std::vector<std::string>{"visibility_r", "visibility_g", "visibility_b"}));
    ASSERT_EQ(r.background_pixels, 0u);
    const double mean = (expected.r + expected.g + expected.b) / 3.0;
    for (int y = 0; y < H; ++y)
      for (int x = 0; x < W; ++x) {
        ASSERT_NEAR(channel(r.visibility_rgb, "visibility_r", x, y), expected.r, 1e-5) << x << "," << y;
        ASSERT_NEAR(channel(r.visibility_rgb, "visibility_g", x, y), expected.g, 1e-5) << x << "," << y;
        ASSERT_NEAR(channel(r.visibility_rgb, "visibility_b", x, y), expected.b, 1e-5) << x << "," << y;
        ASSERT_NEAR(channel(r.visibility, "visibility", x, y), mean, 1e-5) << x << "," << y;
        for (int c = 0; c < 3; ++c)
          ASSERT_NEAR(r.radiance.at(x, y, c), 0.5 * 2.0 / kPi * expected[c] + 0.03 * 0.5, 1e-5) << x << "," << y;
      }
    EXPECT_NEAR(r.mean_visibility, mean, 1e-5);
  };
  Settings s;
  s.effect = Effect::translucent;
  s.width = s.height = 12;
  // Camera below the planes, looking straight down at the ground.
  const CameraSpec below{{0.0, 0.5, 0.0}, {0.0, 0.0, 0.0}, {0, 0, -1}};
  const std::string stack = ground + plane(1.0, 0.6, "[1, 0, 0]") + plane(2.0, 0.5, "[0, 0, 1]");
  check(render(make_scene(below, light_json(towards), stack), s), s.width, s.height, {0.5, 0.2, 0.4}, "stack");

  // Opacity 1, transmission colour (0.2, 0.5, 0.8): T = the colour; the camera above it sees the
  // ground through it.
  const CameraSpec above{{0.0, 3.0, 0.0}, {0.0, 0.0, 0.0}, {0, 0, -1}};
  const std::string glass = ground + plane(1.0, 1.0, "[0.2, 0.5, 0.8]");
  check(render(make_scene(above, light_json(towards), glass), s), s.width, s.height, {0.2, 0.5, 0.8}, "stained glass");

  // The other effects keep their channels; for them every surface blocks.
  s.effect = Effect::hard;
  const Result hard = render(make_scene(below, light_json(towards), stack), s);
  EXPECT_EQ(hard.visibility.channel_names(), (std::vector<std::string>{"visibility", "background"}));
  EXPECT_TRUE(hard.visibility_rgb.empty());
  EXPECT_EQ(channel(hard.visibility, "visibility", 5, 5), 0.0f);
}

// A closed box is crossed twice; an opaque plane stops the light; hard ignores opacity.
TEST(reference_translucent, ClosedMeshesAndOpaqueSurfaces) {
  const glm::dvec3 towards(0, 1, 0);
  const CameraSpec camera{{0.0, 0.5, 0.0}, {0.0, 0.0, 0.0}, {0, 0, -1}};
  const Scene box = make_scene(camera, light_json(towards),
                               R"({"primitive": {"type": "plane", "size": [10, 10]}},
                                    {"primitive": {"type": "box", "size": [20, 0.5, 20]}, "transform": {"translate": [0, 2, 0]},
                                     "material": {"opacity": 0.4}})");
  Settings s;
  s.effect = Effect::translucent;
  s.width = s.height = 8;
  Result r = render(box, s);
  EXPECT_NEAR(channel(r.visibility, "visibility", 3, 3), 0.36, 1e-6);
  s.effect = Effect::hard;
  r = render(box, s);
  EXPECT_EQ(channel(r.visibility, "visibility", 3, 3), 0.0f);

  const Scene opaque = make_scene(camera, light_json(towards),
                                  R"({"primitive": {"type": "plane", "size": [10, 10]}},
                                       {"primitive": {"type": "plane", "size": [20, 20]}, "transform": {"translate": [0, 2, 0]},
                                        "material": {"opacity": 0.5}},
                                       {"primitive": {"type": "plane", "size": [20, 20]}, "transform": {"translate": [0, 3, 0]},
                                        "material": {"opacity": 1}})");
  s.effect = Effect::translucent;
  r = render(opaque, s);
  EXPECT_EQ(channel(r.visibility, "visibility", 3, 3), 0.0f);
}

// ---- scattering -----------------------------------------------------------------------------------

namespace {

const char* kMediumJson =
    R"("medium": {"extinction": 0.3, "scattering_albedo": 0.8, "phase": "henyey_greenstein", "g": 0.4}, )";

// The phase term of the medium above, independently: ρ σt (1 − g²) / (4π (1 + g² − 2 g cos)^1.5).
double phase_term(double cos_theta) {
  const double g = 0.4;
  return 0.8 * 0.3 * (1.0 - g * g) / (4.0 * kPi * std::pow(1.0 + g * g - 2.0 * g * cos_theta, 1.5));
}

// ∫ exp(−σ t) dt over [a, b] ∩ [0, s] (empty: 0).
double exp_integral(double sigma, double a, double b, double s) {
  a = std::max(a, 0.0), b = std::min(b, s);
  return b > a ? (std::exp(-sigma * a) - std::exp(-sigma * b)) / sigma : 0.0;
}

// The interval of t where lo < o + t d < hi (one axis), intersected into [a, b].
void clip_axis(double o, double d, double lo, double hi, double& a, double& b) {
  if (d == 0.0) {
    if (!(o > lo && o < hi)) a = 1.0, b = 0.0;
    return;
  }
  double t0 = (lo - o) / d, t1 = (hi - o) / d;
  if (t0 > t1) std::swap(t0, t1);
  a = std::max(a, t0), b = std::min(b, t1);
}

} // namespace

// No occluder above the ground, light straight up: every shadow ray escapes, the visible fraction
// is exactly 1 and the in-scattered radiance the closed form f E (1 − exp(−σt s)) / σt, with s the
// distance from the camera to the ground or, on background pixels, to the far plane. The radiance
// adds the ground's attenuated by exp(−σt s).
TEST(reference_scattering, ClearAirIsTheClosedForm) {
  const CameraSpec camera{{0.5, 2.0, 4.0}, {-1.0, 1.0, -2.0}, {0.0, 1.0, 0.0}, 50.0, 0.05, 30.0};
  const Scene scene = make_scene(camera, light_json({0, 1, 0}),
                                 R"({"name": "ground", "primitive": {"type": "plane", "size": [20, 20]},
                                     "material": {"albedo": [0.5, 0.5, 0.5]}})",
                                 kMediumJson);
  Settings s = msm::test::reference_settings(Effect::scattering, 64, 48, 16);
  const Result r = render(scene, s);
  ASSERT_EQ(r.visibility.channel_names(),
            (std::vector<std::string>{"visibility", "background", "sample_count", "std_error"}));
  ASSERT_EQ(r.scattering.channel_names(), (std::vector<std::string>{"R", "G", "B", "length"}));
  const glm::dvec3 forward = glm::normalize(camera.target - camera.position);
  int ground = 0, sky = 0;
  for (int y = 0; y < s.height; ++y)
    for (int x = 0; x < s.width; ++x) {
      const glm::dvec3 d = camera.ray(x, y, s.width, s.height);
      const double tg = d.y < 0.0 ? -camera.position.y / d.y : -1.0;
      const glm::dvec3 pg = camera.position + tg * d;
      const bool hits = tg > 0.0 && std::abs(pg.x) < 10.0 && std::abs(pg.z) < 10.0;
      if (tg > 0.0 && std::min(10.0 - std::abs(pg.x), 10.0 - std::abs(pg.z)) < 1e-3) continue; // the rim
      // The far point comes from the float view-projection matrix (as the rasterizer's depth 1
      // does): its distance is known to ~1e-4 relative; the ground hit is exact.
      const double far_len = camera.far / glm::dot(d, forward);
      ASSERT_NEAR(channel(r.scattering, "length", x, y), hits ? tg : far_len, (hits ? 1e-5 : 1e-3) * far_len);
      const double len = hits ? tg : channel(r.scattering, "length", x, y);
      const double in = phase_term(d.y) * 2.0 * -std::expm1(-0.3 * len) / 0.3;
      ASSERT_EQ(channel(r.visibility, "visibility", x, y), 1.0f);
      ASSERT_EQ(channel(r.visibility, "std_error", x, y), 0.0f);
      ASSERT_EQ(channel(r.visibility, "sample_count", x, y), 16.0f);
      ASSERT_NEAR(channel(r.scattering, "R", x, y), in, 2e-5 * in) << x << "," << y;
      const double surface = hits ? 0.5 * 2.0 / kPi + 0.03 * 0.5 : 0.0; // lit ground, n = +Y
      ASSERT_NEAR(r.radiance.at(x, y, 1), std::exp(-0.3 * len) * surface + in, 2e-5 * (surface + in));
      (hits ? ground : sky)++;
    }
  EXPECT_GT(ground, 1000);
  EXPECT_GT(sky, 300);
  EXPECT_EQ(r.mean_visibility, 1.0);
}

// A half-plane occluder (y = 1 over -10 < x < 0, |z| < 10) above the ground, light straight up:
// a point of a view ray is shadowed iff it lies in the slab below the occluder, so the shadowed
// part of the ray is one interval [a, b] of t (the intersection of three axis ranges) and the
// visible fraction is 1 − ∫_a^b e^{−σ t} / ∫_0^s e^{−σ t} in closed form. Stratified sampling in
// proportion to the transmittance puts each of the interval's (at most two) ends in one stratum,
// so the estimate is within 2 / N of it, for every pixel.
TEST(reference_scattering, HalfPlaneShadowIsTheClosedForm) {
  const double h = 1.0, sigma = 0.3;
  const CameraSpec camera{{0.3, 0.6, 1.5}, {-0.6, 0.0, -0.5}};
  const Scene scene = make_scene(camera, light_json({0, 1, 0}), ground_and_half_plane(h, true), kMediumJson);
  Settings s = msm::test::reference_settings(Effect::scattering, 80, 60, 64);
  const Result r = render(scene, s);
  const double inf = std::numeric_limits<double>::infinity();
  double worst = 0.0, mean_error = 0.0, partial = 0;
  int n = 0;
  for (int y = 0; y < s.height; ++y)
    for (int x = 0; x < s.width; ++x) {
      const glm::dvec3 d = camera.ray(x, y, s.width, s.height);
      const glm::dvec3 o = camera.position;
      const double tg = d.y < 0.0 ? -o.y / d.y : inf, to = d.y > 0.0 ? (h - o.y) / d.y : inf;
      const glm::dvec3 pg = o + (std::isfinite(tg) ? tg : 0.0) * d, po = o + (std::isfinite(to) ? to : 0.0) * d;
      const double rim_g = std::min(10.0 - std::abs(pg.x), 10.0 - std::abs(pg.z));
      const double rim_o = std::min({-po.x, 10.0 + po.x, 10.0 - std::abs(po.z)});
      if ((std::isfinite(tg) && std::abs(rim_g) < 1e-3) || (std::isfinite(to) && std::abs(rim_o) < 1e-3)) continue;
      const double len = channel(r.scattering, "length", x, y); // the geometry is checked by ClearAir
      // Shadowed: −10 < x < 0, |z| < 10, y < h (and y > 0: the ray ends on the ground anyway).
      double a = 0.0, b = inf;
      clip_axis(o.x, d.x, -10.0, 0.0, a, b);
      clip_axis(o.z, d.z, -10.0, 10.0, a, b);
      clip_axis(o.y, d.y, -inf, h, a, b);
      const double total = exp_integral(sigma, 0.0, len, len);
      const double exact = 1.0 - (b > a ? exp_integral(sigma, a, b, len) : 0.0) / total;
      const double got = channel(r.visibility, "visibility", x, y);
      worst = std::max(worst, std::abs(got - exact));
      mean_error += std::abs(got - exact);
      if (exact > 0.05 && exact < 0.95) ++partial;
      ++n;
      ASSERT_LE(std::abs(got - exact), 2.0 / s.samples + 1e-6) << x << "," << y << " exact " << exact;
      const double in = phase_term(d.y) * 2.0 * exact * total;
      ASSERT_NEAR(channel(r.scattering, "G", x, y), in, 2.0 / s.samples * phase_term(d.y) * 2.0 * total + 1e-6);
    }
  std::printf("[scattering half-plane] %d pixels (%g partly shadowed): max |error| %.2e, mean %.2e (bound %.2e)\n", n,
              partial, worst, mean_error / n, 2.0 / s.samples);
  EXPECT_GT(partial, 500);
}

// Bad input: no medium; a camera inside a closed box (its inside faces are culled back faces:
// the view rays go on, the points inside are shadowed): finite everywhere, and the in-scattering
// of every ray is at most that of clear air.
TEST(reference_scattering, NoMediumAndCameraInsideAnOccluder) {
  const CameraSpec camera{{0.0, 1.0, 0.0}, {0.0, 0.0, -3.0}};
  const std::string objects = ground_and_half_plane(2.0) + R"(, {"name": "box", "primitive": {"type": "box",
      "size": [1, 1, 1]}, "transform": {"translate": [0, 1, 0]}})";
  Settings s = msm::test::reference_settings(Effect::scattering, 24, 16, 32);
  expect_invalid([&] { render(make_scene(camera, light_json({0.2, 1, 0.1}), objects), s); }, "medium");
  const Result r = render(make_scene(camera, light_json({0.2, 1, 0.1}), objects, kMediumJson), s);
  for (int y = 0; y < s.height; ++y)
    for (int x = 0; x < s.width; ++x) {
      const float v = channel(r.visibility, "visibility", x, y);
      ASSERT_TRUE(v >= 0.0f && v <= 1.0f) << x << "," << y;
      for (int c = 0; c < 3; ++c) ASSERT_TRUE(std::isfinite(r.radiance.at(x, y, c)));
      // The first 0.5 (at least) of every ray lies inside the box: shadowed.
      const double len = channel(r.scattering, "length", x, y);
      ASSERT_LE(v, 1.0 - (-std::expm1(-0.3 * 0.5)) / (-std::expm1(-0.3 * len)) + 2.0 / s.samples);
    }
}

// Two lights over the half plane, from above and from the side, with other colours: the
// in-scattered radiance of both is the sum of each one's alone up to float rounding (every light
// is tested at the same distances along the ray, the same random numbers either way), the surface
// is lit by both, and the visible fraction is the lights' weighted by msm_scattering_light_weight.
TEST(reference_scattering, TwoLightsScatterTheSumOfEach) {
  const CameraSpec camera{{0.3, 0.6, 1.5}, {-0.6, 0.0, -0.5}};
  const std::string lights = R"("lights": [{"towards_light": [0, 1, 0], "irradiance": [2, 2, 2]},
      {"towards_light": [0.6, 0.7, 0.2], "irradiance": [1.5, 0.8, 0.3]}])";
  const Scene both = make_scene(camera, lights, ground_and_half_plane(1.0, true), kMediumJson);
  ASSERT_EQ(both.lights.size(), 2u);
  Settings s = msm::test::reference_settings(Effect::scattering, 48, 36, 64);
  const Result r = render(both, s);
  Result alone[2];
  for (int l = 0; l < 2; ++l) {
    Scene one = both;
    one.lights = {both.lights[std::size_t(l)]};
    alone[l] = render(one, s);
  }
  double second = 0.0, partial = 0.0, brighter = 0.0;
  for (int y = 0; y < s.height; ++y)
    for (int x = 0; x < s.width; ++x) {
      for (int c = 0; c < 3; ++c) {
        const double a = alone[0].scattering.at(x, y, c), b = alone[1].scattering.at(x, y, c);
        ASSERT_NEAR(r.scattering.at(x, y, c), a + b, 1e-6 * (a + b)) << x << "," << y << " channel " << c;
        second += b / (a + b) / (3 * s.width * s.height);
      }
      const glm::dvec3 d = camera.ray(x, y, s.width, s.height);
      double weighted = 0.0, weight = 0.0;
      for (int l = 0; l < 2; ++l) {
        const msm::scene::DirectionalLight& light = both.lights[std::size_t(l)];
        const float phase = msm::msm_scattering_phase_term(0.3f, 0.8f, 0.4f, light.towards_light, glm::vec3(d));
        const double w = msm::msm_scattering_light_weight(light.irradiance, phase);
        weighted += w * channel(alone[l].visibility, "visibility", x, y);
        weight += w;
      }
      const double v = channel(r.visibility, "visibility", x, y);
      ASSERT_NEAR(v, weighted / weight, 1e-5) << x << "," << y;
      partial += v > 0.05 && v < 0.95;
      // Every surface the second light reaches is brighter under both lights than under the first alone.
      brighter += r.radiance.at(x, y, 0) > alone[0].radiance.at(x, y, 0) + 1e-6f;
    }
  const int n = s.width * s.height;
  std::printf("[scattering two lights] second light's share %.2f, partly lit %.2f, surfaces brighter %.2f\n", second,
              partial / n, brighter / n);
  // Measured (48 x 36, 64 spp): the second light's share 0.33, partly lit 0.73, every pixel brighter.
  EXPECT_GT(second, 0.2);
  EXPECT_GT(partial, 0.5 * n);
  EXPECT_GT(brighter, 0.95 * n); // every pixel gains the second light's in-scattering at least
}

// The built-in scattering scenes (scenes/README.md) stress what their figures show: shafts (view
// rays partly lit) in every one; the room mostly dark (shadowed air outside the window's shaft);
// the tower's view ray into the light ends on the tower just below its parapet, so the rays around
// it are dark while most of the image is lit.
TEST(reference_scattering, BuiltinScenesHaveShafts) {
  Settings s = msm::test::reference_settings(Effect::scattering, 64, 36, 16);
  for (const char* name : {"tower", "trees", "gate", "room"}) {
    SCOPED_TRACE(name);
    const Scene scene = msm::scene::builtin_scene(name);
    const Result r = render(scene, s);
    int partial = 0, dark = 0;
    for (int y = 0; y < s.height; ++y)
      for (int x = 0; x < s.width; ++x) {
        const float v = channel(r.visibility, "visibility", x, y);
        partial += v > 0.02f && v < 0.98f;
        dark += v <= 0.02f;
      }
    const int n = s.width * s.height;
    std::printf("[scattering scenes] %-5s partly lit %.2f, dark %.2f, mean %.3f\n", name, double(partial) / n,
                double(dark) / n, r.mean_visibility);
    // Measured (64 x 36, 16 spp): partly lit tower 0.91, trees 0.56, gate 0.92, room 0.06 (the
    // shaft); dark room 0.94.
    EXPECT_GT(partial, n / 25);
    if (std::string(name) == "room") { EXPECT_GT(dark, n / 2); }
    if (std::string(name) == "tower") {
      // Around the pixel through which the camera sees the light (a pixel here spans 1.4 degrees;
      // the light lies 0.5 degrees below the parapet's top edge): a dark ray, while the image is
      // mostly lit.
      const glm::vec4 c = scene.camera_view_projection(float(s.width) / s.height) *
                          glm::vec4(scene.camera.position + scene.light().towards_light, 1.0f);
      const int px = int((c.x / c.w * 0.5f + 0.5f) * s.width), py = int((c.y / c.w * 0.5f + 0.5f) * s.height);
      ASSERT_TRUE(px >= 1 && px < s.width - 1 && py >= 1 && py < s.height - 1);
      float darkest = 1.0f;
      for (int dy = -1; dy <= 1; ++dy)
        for (int dx = -1; dx <= 1; ++dx)
          darkest = std::min(darkest, channel(r.visibility, "visibility", px + dx, py + dy));
      EXPECT_LT(darkest, 0.1f);
      EXPECT_GT(r.mean_visibility, 0.5);
    }
  }
}

// ---- determinism ---------------------------------------------------------------------------------

TEST(reference_determinism, SameSeedSameImageForAnyThreadCount) {
  const DiscScene ds(10.0);
  Settings s = msm::test::reference_settings(Effect::soft, 32, 32, 16);
  s.seed = 42;
  Result one, many, again;
  {
    tbb::global_control limit(tbb::global_control::max_allowed_parallelism, 1);
    one = render(ds.scene, s);
    EXPECT_EQ(one.threads, 1u);
  }
  {
    tbb::global_control limit(tbb::global_control::max_allowed_parallelism, 8);
    tbb::task_arena arena(8);
    arena.execute([&] { many = render(ds.scene, s); });
    EXPECT_GT(many.threads, 1u);
  }
  again = render(ds.scene, s);
  EXPECT_TRUE(one.visibility == many.visibility);
  EXPECT_TRUE(one.radiance == many.radiance);
  EXPECT_TRUE(one.visibility == again.visibility);
  s.seed = 43;
  const Result other = render(ds.scene, s);
  EXPECT_FALSE(one.visibility == other.visibility) << "the seed must matter";

  s.effect = Effect::filtered;
  s.seed = 42;
  Result f1, f8;
  {
    tbb::global_control limit(tbb::global_control::max_allowed_parallelism, 1);
    f1 = render(ds.scene, s);
  }
  {
    tbb::global_control limit(tbb::global_control::max_allowed_parallelism, 8);
    tbb::task_arena arena(8);
    arena.execute([&] { f8 = render(ds.scene, s); });
  }
  EXPECT_TRUE(f1.visibility == f8.visibility);
}

TEST(reference_progress, ReportsEveryRowUpToTheTotal) {
  const DiscScene ds(10.0);
  Settings s;
  s.width = 16;
  s.height = 20;
  std::size_t last = 0, calls = 0;
  bool increasing = true;
  s.progress = [&](const Progress& p) {
    increasing = increasing && p.rows_done > last && p.rows_total == 20;
    last = p.rows_done;
    ++calls;
  };
  render(ds.scene, s);
  EXPECT_TRUE(increasing);
  EXPECT_EQ(last, 20u);
  EXPECT_GE(calls, 1u);
}

// ---- bad input -----------------------------------------------------------------------------------

TEST(reference_bad_input, SettingsAreValidated) {
  const auto with = [](auto change) {
    Settings s;
    change(s);
    return [s] { validate(s); };
  };
  EXPECT_NO_THROW(validate(Settings{}));
  expect_invalid(with([](Settings& s) { s.width = 0; }), "width: 0 is outside [1, 16384]");
  expect_invalid(with([](Settings& s) { s.height = 16385; }), "height: 16385 is outside");
  expect_invalid(with([](Settings& s) { s.samples = 0; }), "samples: 0 is outside");
  expect_invalid(with([](Settings& s) { s.samples = 1'000'001; }), "samples: 1000001 is outside");
  expect_invalid(with([](Settings& s) { s.shadow_size = 0; }), "shadow_size: 0 is outside");
  expect_invalid(with([](Settings& s) { s.filter_size = 8; }), "filter size 8");
  expect_invalid(with([](Settings& s) { s.filter_sigma = std::nan(""); }), "filter_sigma: nan is not a finite number");
  expect_invalid(with([](Settings& s) { s.light_extent_deg = 90.0; }), "light_extent_deg: 90 is outside [0, 89]");
  expect_invalid(with([](Settings& s) { s.light_width_deg = -1.0; }), "light_width_deg: -1 is outside");
  expect_invalid(with([](Settings& s) { s.max_crossings = 0; }), "max_crossings: 0 is outside");
  EXPECT_EQ(parse_effect("soft"), Effect::soft);
  EXPECT_FALSE(parse_effect("nope"));
  EXPECT_EQ(parse_light_shape("rectangle"), LightShape::rectangle);
  EXPECT_FALSE(parse_light_shape("square"));
}

TEST(reference_bad_input, NonFiniteVerticesAreReported) {
  // The loader rejects them (SceneError naming the file); a scene built in code is checked by
  // render() itself.
  const std::filesystem::path dir = std::filesystem::temp_directory_path() / "msm_reference_test_nan";
  std::filesystem::create_directories(dir);
  std::ofstream(dir / "nan.ply") << "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
                                    "property float z\nelement face 1\nproperty list uchar int vertex_indices\n"
                                    "end_header\nnan 0 0\n1 0 0\n0 1 0\n3 0 1 2\n";
  std::ofstream(dir / "scene.json")
      << R"({"msm_scene": 1, "light": {"towards_light": [0, 1, 0]}, "objects": [{"mesh": "nan.ply"}]})";
  try {
    msm::scene::load_scene((dir / "scene.json").string());
    ADD_FAILURE() << "no SceneError";
  } catch (const msm::scene::SceneError& e) {
    EXPECT_NE(std::string(e.what()).find("NaN or infinite"), std::string::npos) << e.what();
  }
  std::filesystem::remove_all(dir);

  Scene scene = DiscScene(1.0).scene;
  scene.objects[1].mesh.positions[3].y = std::nanf("");
  expect_invalid([&] { render(scene, Settings{}); }, "object 'disc': vertex 3 has a NaN or infinite position");
}
