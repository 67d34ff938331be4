// The rectification of prefiltered single scattering (include/msm/rectification.h, JCGT §5.1.1,
// Appendix A): every pixel of the view maps into the map, the bounds are tight, the per-slice
// inclinations and the prefix-sum weights integrate what they claim. Geometry here is computed
// independently in double precision (camera basis, pixel directions, spherical coordinates).
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>
#include <random>
#include <vector>

#include <gtest/gtest.h>

#include "msm/rectification.h"

namespace {

using glm::dvec3;

struct View {
  dvec3 camera, forward, right, up;
  double tan_half_y, aspect, far;
  dvec3 towards_light;
  // Direction of NDC (x, y) in [-1,1]² (unnormalized, forward component 1).
  dvec3 direction(double x, double y) const {
    return forward + (x * tan_half_y * aspect) * right + (y * tan_half_y) * up;
  }
  glm::mat4x3 far_corners() const {
    auto corner = [&](double x, double y) { return glm::vec3(camera + far * direction(x, y)); };
    return glm::mat4x3(corner(-1, -1), corner(1, -1), corner(1, 1), corner(-1, 1)); // in order around the quad
  }
  // The rectification of this view (in float, as the shaders compute it) and its bounds.
  msm::RectificationFrame frame() const {
    return msm::msm_rectification_frame(glm::vec3(camera), glm::vec3(towards_light));
  }
  msm::RectifiedBounds bounds() const { return msm::msm_rectification_bounds(frame(), far_corners()); }
};

dvec3 random_unit(std::mt19937& rng) {
  std::normal_distribution<double> n;
  return glm::normalize(dvec3(n(rng), n(rng), n(rng)));
}

View make_view(std::mt19937& rng, dvec3 forward, dvec3 towards_light) {
  std::uniform_real_distribution<double> u(0.0, 1.0);
  View v;
  v.camera = dvec3(20.0 * u(rng) - 10.0, 20.0 * u(rng) - 10.0, 20.0 * u(rng) - 10.0);
  v.forward = glm::normalize(forward);
  const dvec3 helper = std::abs(v.forward.y) < 0.9 ? dvec3(0, 1, 0) : dvec3(1, 0, 0);
  const double roll = 2.0 * M_PI * u(rng);
  const dvec3 r0 = glm::normalize(glm::cross(v.forward, helper)), u0 = glm::cross(r0, v.forward);
  v.right = std::cos(roll) * r0 + std::sin(roll) * u0;
  v.up = glm::cross(v.right, v.forward);
  v.tan_half_y = std::tan(0.5 * (20.0 + 80.0 * u(rng)) * M_PI / 180.0);
  v.aspect = 0.5 + 1.9 * u(rng);
  v.far = 5.0 + 500.0 * u(rng);
  v.towards_light = glm::normalize(towards_light);
  return v;
}

// 64 configurations: random ones (epipole mostly out of view), the light in view (looking into
// it), behind the camera (looking away: the anti-epipole in view), exactly along the view axis
// both ways, and grazing the frustum's side.
std::vector<View> configurations() {
  std::mt19937 rng(14);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  std::vector<View> views;
  for (int i = 0; i < 64; ++i) {
    const dvec3 forward = random_unit(rng);
    View v = make_view(rng, forward, random_unit(rng));
    const int kind = i % 8;
    // Directions inside the view: forward tilted by less than the half-angles.
    const dvec3 inside =
        glm::normalize(v.direction(0.8 * u(rng), 0.8 * u(rng))); // the light's direction seen in the view
    if (kind == 1) v.towards_light = inside;                     // looking into the light
    if (kind == 2) v.towards_light = -inside;                    // looking away: +z in view
    if (kind == 3) v.towards_light = v.forward;                  // the light parallel to the view
    if (kind == 4) v.towards_light = -v.forward;
    if (kind == 5) v.towards_light = glm::normalize(v.direction(1.0, 0.3 * u(rng))); // on the side plane
    if (kind == 6) v.towards_light = glm::normalize(v.direction(-1.0, -1.0));        // through a corner
    views.push_back(v);
  }
  return views;
}

// (r, φ, θ) in double, rectification space of the frame under test.
dvec3 spherical(const msm::RectificationFrame& f, dvec3 world) {
  const dvec3 d = world - dvec3(f.origin);
  const double x = glm::dot(dvec3(f.x_axis), d), y = glm::dot(dvec3(f.y_axis), d), z = glm::dot(dvec3(f.z_axis), d);
  const double r = std::hypot(x, y);
  double phi = std::atan2(y, x);
  if (phi < 0.0) phi += 2.0 * M_PI;
  return dvec3(r, phi, std::atan2(r, z));
}

double wrap_from(double phi, double phi_min) {
  double d = phi - phi_min;
  while (d < 0.0) d += 2.0 * M_PI;
  while (d >= 2.0 * M_PI) d -= 2.0 * M_PI;
  return d;
}

} // namespace

TEST(Rectification, FrameIsOrthonormalWithZAlongTheLightsTravel) {
  std::mt19937 rng(1);
  for (int i = 0; i < 100; ++i) {
    const glm::vec3 l = glm::vec3(random_unit(rng));
    const msm::RectificationFrame f = msm::msm_rectification_frame(glm::vec3(1, 2, 3), l);
    EXPECT_NEAR(glm::dot(f.z_axis, -l), 1.0f, 1e-6f);
    EXPECT_NEAR(glm::dot(f.x_axis, f.z_axis), 0.0f, 1e-6f);
    EXPECT_NEAR(glm::dot(f.y_axis, f.z_axis), 0.0f, 1e-6f);
    EXPECT_NEAR(glm::dot(f.x_axis, f.y_axis), 0.0f, 1e-6f);
    EXPECT_NEAR(glm::length(f.x_axis), 1.0f, 1e-6f);
    EXPECT_NEAR(glm::dot(glm::cross(f.x_axis, f.y_axis), f.z_axis), 1.0f, 1e-6f); // right-handed
    const glm::vec3 p(0.3f, -2.0f, 5.0f);
    const glm::vec3 back = msm::msm_from_rectification_space(f, msm::msm_to_rectification_space(f, p));
    EXPECT_NEAR(glm::length(back - p), 0.0f, 1e-5f);
  }
}

TEST(Rectification, DepthGrowsAwayFromTheLightAlongALightRay) {
  // A light ray has constant (r, φ): one texel, and its depth increases along the light's travel.
  const msm::RectificationFrame f = msm::msm_rectification_frame(glm::vec3(0), glm::vec3(0.2f, 0.9f, 0.1f));
  msm::RectifiedBounds b{};
  b.r_max = 10.0f, b.phi_min = 0.0f, b.phi_span = msm::MSM_TWO_PI, b.theta_min = 0.0f, b.theta_max = msm::MSM_PI;
  const glm::vec3 start = msm::msm_from_rectification_space(f, glm::vec3(1.0f, 2.0f, -30.0f));
  glm::vec3 previous = msm::msm_rectified_coordinates(b, msm::msm_to_rectification_space(f, start));
  for (int i = 1; i <= 60; ++i) {
    const glm::vec3 c =
        msm::msm_rectified_coordinates(b, msm::msm_to_rectification_space(f, start + float(i) * f.z_axis));
    EXPECT_NEAR(c.x, previous.x, 1e-5f);
    EXPECT_NEAR(c.y, previous.y, 1e-5f);
    EXPECT_GT(c.z, previous.z);
    previous = c;
  }
  // A view ray has constant (φ, θ): one row, one depth; u grows with the distance.
  const glm::vec3 dir = glm::normalize(glm::vec3(0.3f, -0.2f, 0.9f));
  const glm::vec3 first = msm::msm_rectified_coordinates(b, msm::msm_to_rectification_space(f, dir));
  for (float t : {2.0f, 5.0f, 40.0f}) {
    const glm::vec3 c = msm::msm_rectified_coordinates(b, msm::msm_to_rectification_space(f, t * dir));
    EXPECT_NEAR(c.x, t * first.x, 1e-4f * t);
    EXPECT_NEAR(c.y, first.y, 1e-5f);
    EXPECT_NEAR(c.z, first.z, 1e-5f);
  }
}

TEST(Rectification, CoversEveryPixelOf64Views) {
  int with_epipole = 0;
  for (const View& view : configurations()) {
    const msm::RectificationFrame f = view.frame();
    const msm::RectifiedBounds b = view.bounds();
    if (b.phi_span == msm::MSM_TWO_PI) ++with_epipole;
    ASSERT_GT(b.r_max, 0.0f);
    ASSERT_GT(b.theta_max, b.theta_min);
    ASSERT_GE(b.theta_min, 0.0f);
    ASSERT_LE(b.theta_max, msm::MSM_PI);
    double r_hi = 0.0, th_lo = 10.0, th_hi = -1.0, phi_hi = 0.0;
    const int n = 96; // pixels per axis, the image's edges included
    for (int iy = 0; iy <= n; ++iy)
      for (int ix = 0; ix <= n; ++ix) {
        const dvec3 d = view.direction(2.0 * ix / n - 1.0, 2.0 * iy / n - 1.0);
        for (double t : {1e-3, 0.01, 0.3, 1.0}) { // depth as a fraction of the far plane
          const dvec3 world = view.camera + t * view.far * d;
          const dvec3 s = spherical(f, world);
          const glm::vec3 c = msm::msm_rectified_coordinates(b, msm::msm_to_rectification_space(f, glm::vec3(world)));
          // float coordinates (what the shader computes) inside the map
          ASSERT_TRUE(c.x >= 0.0f && c.x <= 1.0f && c.y >= 0.0f && c.y <= 1.0f && c.z >= 0.0f && c.z <= 1.0f)
              << "u " << c.x << " v " << c.y << " depth " << c.z << " at pixel " << ix << "," << iy;
          r_hi = std::max(r_hi, s.x / b.r_max);
          if (s.x > 1e-9 * view.far) phi_hi = std::max(phi_hi, wrap_from(s.y, b.phi_min) / b.phi_span);
          th_lo = std::min(th_lo, s.z);
          th_hi = std::max(th_hi, s.z);
        }
      }
    // Tight: the far corners reach r_max; the view's inclinations span the unguarded range.
    EXPECT_GT(r_hi, 1.0 - 2e-4);
    EXPECT_LE(th_lo, b.view_theta_min + 0.03);
    EXPECT_GE(th_hi, b.view_theta_max - 0.03);
    EXPECT_GE(th_lo, b.view_theta_min - 1e-3);
    EXPECT_LE(th_hi, b.view_theta_max + 1e-3);
    if (b.phi_span < msm::MSM_TWO_PI) { EXPECT_GT(phi_hi * b.phi_span, b.phi_span - 3.0 * msm::MSM_RECT_PHI_PAD); }
    // The guard band: 10% of the view's θ range (5% each side) unless clamped at 0 or π.
    const double guard = 0.05 * (b.view_theta_max - b.view_theta_min);
    EXPECT_NEAR(b.theta_min, std::max(0.0, b.view_theta_min - guard), 1e-5);
    EXPECT_NEAR(b.theta_max, std::min(M_PI, b.view_theta_max + guard), 1e-5);
  }
  EXPECT_GE(with_epipole, 24); // kinds 1-4 (and corner/side cases within the tolerance)
}

TEST(Rectification, SliceInclinationsAreTheViewsInThatSlice) {
  // The range of θ in slice φ: just inside its ends the direction projects into the image, just
  // outside (unless the end is 0 or π) it does not. Projection in double, by the camera basis.
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  int checked = 0;
  for (const View& view : configurations()) {
    const msm::RectificationFrame f = view.frame();
    const msm::RectifiedBounds b = view.bounds();
    auto in_view = [&](double theta, double phi) {
      const dvec3 d = std::sin(theta) * std::cos(phi) * dvec3(f.x_axis) +
                      std::sin(theta) * std::sin(phi) * dvec3(f.y_axis) + std::cos(theta) * dvec3(f.z_axis);
      const double z = glm::dot(d, view.forward);
      if (z <= 0.0) return false;
      const double x = glm::dot(d, view.right) / (z * view.tan_half_y * view.aspect),
                   y = glm::dot(d, view.up) / (z * view.tan_half_y);
      return std::abs(x) <= 1.0 && std::abs(y) <= 1.0;
    };
    for (int k = 0; k < 16; ++k) {
      const double v = 0.02 + 0.96 * u(rng);
      const double phi = b.phi_min + v * b.phi_span;
      // Only slices that the view crosses (with the φ padding, the ends may not).
      bool crossed = false;
      for (int i = 1; i < 400 && !crossed; ++i) crossed = in_view(M_PI * i / 400.0, phi);
      if (!crossed) continue;
      const glm::vec2 range = msm::msm_slice_inclination_range(b, float(phi));
      const double eps = 2e-3;
      EXPECT_TRUE(in_view(0.5 * (range.x + range.y), phi));
      if (range.y - range.x > 4.0 * eps) {
        EXPECT_TRUE(in_view(range.x + eps, phi)) << range.x;
        EXPECT_TRUE(in_view(range.y - eps, phi)) << range.y;
      }
      if (range.x > eps) { EXPECT_FALSE(in_view(range.x - eps, phi)); }
      if (range.y < M_PI - eps) { EXPECT_FALSE(in_view(range.y + eps, phi)); }
      ++checked;
    }
  }
  EXPECT_GT(checked, 500);
}

TEST(Rectification, InverseMapsTexelsToTheirLightRays) {
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  for (const View& view : configurations()) {
    const msm::RectificationFrame f = view.frame();
    const msm::RectifiedBounds b = view.bounds();
    for (int k = 0; k < 8; ++k) {
      const glm::vec2 uv(float(u(rng)), float(u(rng)));
      const glm::vec3 p = msm::msm_rectified_light_ray_point(f, b, uv);
      for (float s : {-3.0f, 0.0f, 7.0f}) { // anywhere along the light ray: the same texel
        const glm::vec3 c = msm::msm_rectified_coordinates(b, msm::msm_to_rectification_space(f, p + s * f.z_axis));
        EXPECT_NEAR(c.x, uv.x, 1e-4f);
        if (uv.x > 1e-3f) { EXPECT_NEAR(std::remainder(c.y - uv.y, 2.0 * M_PI / b.phi_span), 0.0, 1e-3 / b.phi_span); }
        // depth of a point on the ray: msm_rectified_depth_of_rz is the clamped coordinate
        EXPECT_NEAR(msm::msm_rectified_depth_of_rz(b, uv.x * b.r_max, s), std::clamp(c.z, 0.0f, 1.0f), 1e-4f);
      }
    }
  }
}

TEST(Rectification, PrefixSumWeightsIntegrateTheTransmittance) {
  // Σ_{j<n} w_j telescopes to ∫_0^{nΔ} exp(−σt t) dt.
  for (double sigma : {1e-4, 0.05, 2.0})
    for (double delta : {1e-3, 0.1, 3.0}) {
      double sum = 0.0;
      for (int j = 0; j < 512; ++j) sum += msm::msm_prefix_sum_weight(float(sigma), float(delta), float(j));
      const double exact = -std::expm1(-sigma * 512.0 * delta) / sigma;
      EXPECT_NEAR(sum / exact, 1.0, 2e-5) << sigma << " " << delta;
    }
}

// App. D.5's level: log2 of the smaller footprint (along and across the rows, each the larger
// derivative in texels), none below one texel; where φ spans the full circle a derivative across
// the seam (v from 0.99 to 0.01 between neighbours) is the short way round, else the long way.
TEST(Rectification, PrefixSumLevelFollowsTheSmallerFootprint) {
  const glm::vec2 size(512.0f, 256.0f), wide(1.0f); // wide: a footprint of 512 texels along the rows
  using msm::msm_prefix_sum_lod;
  EXPECT_FLOAT_EQ(msm_prefix_sum_lod(wide, glm::vec2(1.0f / 256.0f, 0.0f), size, false), 0.0f);
  EXPECT_FLOAT_EQ(msm_prefix_sum_lod(wide, glm::vec2(0.1f / 256.0f, 0.0f), size, false), 0.0f);
  EXPECT_NEAR(msm_prefix_sum_lod(wide, glm::vec2(-2.0f / 256.0f, 8.0f / 256.0f), size, false), 3.0f, 1e-5f);
  EXPECT_NEAR(msm_prefix_sum_lod(wide, glm::vec2(-0.98f, 0.0f), size, true), std::log2(0.02f * 256.0f), 1e-3f);
  EXPECT_NEAR(msm_prefix_sum_lod(wide, glm::vec2(-0.98f, 0.0f), size, false), std::log2(0.98f * 256.0f), 1e-4f);
  EXPECT_NEAR(msm_prefix_sum_lod(wide, glm::vec2(0.0f, 0.75f), size, true), 6.0f, 1e-5f); // a quarter of 256 rows
  // The footprint along the rows bounds it: 4 texels of u against 64 rows, and the other way round.
  EXPECT_NEAR(msm_prefix_sum_lod(glm::vec2(0.0f, -4.0f / 512.0f), glm::vec2(0.25f, 0.0f), size, false), 2.0f, 1e-5f);
  EXPECT_NEAR(msm_prefix_sum_lod(glm::vec2(0.25f, 0.0f), glm::vec2(0.0f, 4.0f / 256.0f), size, false), 2.0f, 1e-5f);
}

TEST(Rectification, PrefixSumLookupIntegratesAStepAlongAViewRay) {
  // One row: texel j holds visibility 1 while the view ray is lit (t < T), else 0; the prefix
  // sums read at a ray of length s with linear filtering give ∫_0^s e^{−σ t} V dt / ∫_0^s e^{−σ t} dt.
  const int width = 1024;
  msm::RectifiedBounds b{};
  b.r_max = 50.0f, b.phi_min = 0.0f, b.phi_span = msm::MSM_TWO_PI, b.theta_min = 0.0f, b.theta_max = msm::MSM_PI;
  b.side0 = b.side1 = b.side2 = b.side3 = glm::vec3(0.0f, 0.0f, 1.0f); // the slice's θ in [0, π/2]
  const glm::vec2 range = msm::msm_slice_inclination_range(b, 1.0f);
  EXPECT_NEAR(range.x, 0.0f, 1e-6f);
  EXPECT_NEAR(range.y, 0.5f * msm::MSM_PI, 1e-6f);
  const float delta = msm::msm_rectified_row_step(b, 0.5f, float(width));
  const float sin_theta = std::sin(0.25f * msm::MSM_PI); // the view ray at the slice's mean inclination
  EXPECT_NEAR(delta, 50.0f / width / sin_theta, 1e-5f);
  const float sigma = 0.05f, lit_until = 23.7f;
  std::vector<double> prefix(width);
  double num = 0.0, den = 0.0;
  for (int j = 0; j < width; ++j) {
    const double w = msm::msm_prefix_sum_weight(sigma, delta, float(j));
    const double t0 = j * delta, t1 = (j + 1) * delta;
    const double lit = std::clamp((lit_until - t0) / (t1 - t0), 0.0, 1.0); // box-filtered texel
    num += w * lit;
    den += w;
    prefix[j] = num / den;
  }
  for (float s : {3.0f, 20.0f, 23.7f, 30.0f, 55.0f}) {
    const float u = msm::msm_prefix_sum_lookup_u(b, s * sin_theta, float(width));
    const double x = std::clamp(double(u) * width - 0.5, 0.0, double(width - 1));
    const int i = std::min(int(x), width - 2);
    const double read = prefix[i] + (x - i) * (prefix[i + 1] - prefix[i]);
    const double exact = -std::expm1(-sigma * std::min(s, lit_until)) / -std::expm1(-sigma * s);
    EXPECT_NEAR(read, exact, 2e-3) << "s " << s;
  }
}

TEST(Rectification, ResamplingLevelIsTheTexelsFootprintInTheShadowMap) {
  // The mip level of the filtered resampling (§5.2) against the footprint measured directly: the
  // shadow-map texel coordinates of the light rays through the neighbouring texel centres (an
  // orthographic light along z: any rotation and scale across it, an offset), in double; the level
  // is log2 of the longer central difference, never below 0.
  std::mt19937 rng(17);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  int above_zero = 0;
  for (const View& view : configurations()) {
    const msm::RectificationFrame f = view.frame();
    const msm::RectifiedBounds b = view.bounds();
    const int width = 1 << (8 + int(4.0 * u(rng))), height = width;
    // Shadow-map texels per world unit, the light's x axis at angle a to the frame's, either hand.
    const double scale = std::exp(std::log(0.05) + u(rng) * std::log(4000.0)), a = 2.0 * M_PI * u(rng);
    const double hand = u(rng) < 0.5 ? -1.0 : 1.0;
    const glm::dvec2 per_x = scale * glm::dvec2(hand * std::cos(a), std::sin(a));
    const glm::dvec2 per_y = scale * glm::dvec2(-hand * std::sin(a), std::cos(a));
    const glm::dvec2 offset(100.0 * u(rng), 100.0 * u(rng));
    auto map_texel = [&](double i, double j) { // of the light ray through texel coordinates (i, j)
      const double r = (i + 0.5) / width * double(b.r_max);
      const double phi = double(b.phi_min) + (j + 0.5) / height * double(b.phi_span);
      return offset + r * std::cos(phi) * per_x + r * std::sin(phi) * per_y;
    };
    for (int k = 0; k < 16; ++k) {
      const double i = 1.0 + u(rng) * (width - 2), j = 1.0 + u(rng) * (height - 2);
      const double fu = glm::length(map_texel(i + 0.5, j) - map_texel(i - 0.5, j));
      // Along v the rays turn on a circle: the chord of one texel step, 2 r sin(Δφ/2), is the
      // tangent r Δφ to within (Δφ)²/24 relative.
      const double fv = glm::length(map_texel(i, j + 0.5) - map_texel(i, j - 0.5));
      const double expected = std::log2(std::max({fu, fv, 1.0}));
      const glm::vec2 uv(float((i + 0.5) / width), float((j + 0.5) / height));
      const float lod = msm::msm_rectified_resampling_lod(msm::msm_rectified_r_phi(b, uv),
                                                          glm::vec2(b.r_max / float(width), b.phi_span / float(height)),
                                                          glm::vec2(per_x), glm::vec2(per_y));
      EXPECT_NEAR(lod, expected, 1e-4) << "texel " << i << ", " << j << " of " << width;
      above_zero += expected > 0.5;
    }
  }
  EXPECT_GT(above_zero, 64 * 16 / 4); // the test reaches the mips, not only the floor at 0
}

// ---- Transmittance layers ----

TEST(Rectification, TransmittanceLayersCoverEveryViewRaysStep) {
  // The layers' range holds the step Δ = (r_max / width) / sin θ of every view ray of 64 views
  // (sin θ in double), or the step is beyond a clamp (σt Δ above MAX_TAU or σt Δ width below
  // MIN_TAU, where the weights no longer change); the steps Δ_k grow geometrically from Δ_lo to Δ_hi,
  // and the lookup of Δ_k reads layer k alone.
  const float width = 512.0f;
  int clamped_hi = 0, inside = 0;
  for (const View& view : configurations()) {
    const msm::RectificationFrame f = view.frame();
    const msm::RectifiedBounds b = view.bounds();
    for (float sigma : {0.001f, 0.03f, 0.5f}) {
      const glm::vec2 range = msm::msm_transmittance_layer_range(b, sigma, width);
      ASSERT_GT(range.x, 0.0f);
      ASSERT_LE(range.x, range.y);
      const double lo_clamp = msm::MSM_RECT_LAYER_MIN_TAU / (double(sigma) * width);
      const double hi_clamp = msm::MSM_RECT_LAYER_MAX_TAU / double(sigma);
      const int n = 24;
      for (int iy = 0; iy <= n; ++iy)
        for (int ix = 0; ix <= n; ++ix) {
          const dvec3 d = glm::normalize(view.direction(2.0 * ix / n - 1.0, 2.0 * iy / n - 1.0));
          const double cos_theta = glm::dot(d, dvec3(f.z_axis));
          const double sin_theta = std::max(std::sqrt(std::max(0.0, 1.0 - cos_theta * cos_theta)), 1e-3);
          const double step = double(b.r_max) / (width * sin_theta);
          const float shader_step = msm::msm_rectified_view_ray_step(f, b, glm::vec3(d), width);
          EXPECT_NEAR(shader_step / step, 1.0, 2e-3);
          if (step > hi_clamp) {
            ++clamped_hi;
            EXPECT_GE(range.y, hi_clamp * (1.0 - 1e-5));
          } else if (step < lo_clamp) {
            EXPECT_LE(range.x, lo_clamp * (1.0 + 1e-5));
          } else {
            ++inside;
            EXPECT_GE(step, range.x * (1.0 - 2e-3));
            EXPECT_LE(step, range.y * (1.0 + 2e-3));
          }
        }
      for (float layers : {2.0f, 4.0f, 16.0f})
        for (float k = 0.0f; k < layers; k += 1.0f) {
          const double dk = msm::msm_transmittance_layer_step(range, k, layers);
          const double expected = double(range.x) * std::pow(double(range.y) / range.x, k / (layers - 1.0));
          EXPECT_NEAR(dk / expected, 1.0, 1e-5);
          const glm::vec2 look = msm::msm_transmittance_layer_lookup(range, float(dk), layers);
          // layer k alone: (k, 0), or for the last layer (K − 2, 1); a clamped, empty range (all
          // steps equal) reads (0, 0)
          EXPECT_NEAR(look.x + look.y, range.y > range.x ? k : 0.0f, 1e-3f);
          EXPECT_GE(look.x, 0.0f);
          EXPECT_LE(look.x, layers - 2.0f);
          EXPECT_GE(look.y, 0.0f);
          EXPECT_LE(look.y, 1.0f);
        }
    }
  }
  EXPECT_GT(inside, 0);
  EXPECT_GT(clamped_hi, 0); // the epipole's rays
}

// The prefix sum of one row at texel reach n (linear filtering as the lookup, box-filtered step
// visibility) with weights of step delta, in double.
double layered_row_read(const std::vector<double>& lit, double sigma, double delta, double reach) {
  double num = 0.0, den = 0.0;
  std::vector<double> prefix(lit.size());
  for (std::size_t j = 0; j < lit.size(); ++j) {
    const double w = std::exp(-sigma * delta * double(j)); // w(j) up to a factor that cancels
    num += w * lit[j];
    den += w;
    prefix[j] = num / den;
  }
  const double x = std::clamp(reach - 0.5, 0.0, double(lit.size() - 1));
  const std::size_t i = std::min(std::size_t(x), lit.size() - 2);
  return prefix[i] + (x - double(i)) * (prefix[i + 1] - prefix[i]);
}

TEST(Rectification, TransmittanceLayersApproachTheRaysOwnWeights) {
  // A row of 512 texels with random shadowed runs (a light ray's visibility); view rays of
  // inclinations from 0.002 to π/2 and lengths up to the far plane read it. Exact: the prefix sums
  // with the ray's own step, in double. Layered: K prefix sums with the steps Δ_k, mixed at the
  // ray's step (msm_transmittance_layer_lookup), also in double. The paper's single Δ: the prefix
  // sums at the mean inclination's step. Measured (seed 5): mean |layered − exact| 0.0201 (K = 2),
  // 0.0142 (4), 0.0006 (16); the single Δ 0.0620.
  const int width = 512;
  const double sigma = 0.03, r_max = 120.0, far = 200.0;
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  std::vector<double> lit(width, 1.0);
  for (int run = 0; run < 12; ++run) { // shadowed runs
    const int start = int(u(rng) * width), length = 1 + int(u(rng) * 60.0);
    for (int j = start; j < std::min(width, start + length); ++j) lit[j] = 0.0;
  }
  msm::RectifiedBounds b{};
  b.r_max = float(r_max);
  b.view_theta_min = 0.0f; // the epipole in view
  b.view_theta_max = 2.0f;
  const glm::vec2 range = msm::msm_transmittance_layer_range(b, float(sigma), float(width));
  const double paper_step = r_max / (width * std::sin(1.0)); // the mean inclination 1.0
  std::map<int, double> error;
  double paper = 0.0;
  int n = 0;
  for (int i = 0; i < 400; ++i) {
    const double theta = std::exp(std::log(0.002) + u(rng) * (std::log(0.5 * M_PI) - std::log(0.002)));
    const double s = far * (0.05 + 0.95 * u(rng));
    const double step = r_max / (width * std::sin(theta));
    const double reach = std::min(s / step, double(width)); // texels
    const double exact = layered_row_read(lit, sigma, step, reach);
    paper += std::abs(layered_row_read(lit, sigma, paper_step, reach) - exact);
    for (int layers : {2, 4, 16}) {
      const glm::vec2 k = msm::msm_transmittance_layer_lookup(range, float(step), float(layers));
      const double d0 = msm::msm_transmittance_layer_step(range, k.x, float(layers));
      const double d1 = msm::msm_transmittance_layer_step(range, k.x + 1.0f, float(layers));
      const double read =
          (1.0 - k.y) * layered_row_read(lit, sigma, d0, reach) + k.y * layered_row_read(lit, sigma, d1, reach);
      error[layers] += std::abs(read - exact);
    }
    ++n;
  }
  for (auto& [layers, e] : error) e /= n;
  paper /= n;
  std::printf("[transmittance layers] mean |error| K = 2 %.4f, 4 %.4f, 16 %.4f; single delta %.4f\n", error[2],
              error[4], error[16], paper);
  EXPECT_LT(error[16], 0.1 * error[4]); // measured 0.04x
  EXPECT_LT(error[4], 0.8 * error[2]);  // 0.71x
  EXPECT_LT(error[2], 0.5 * paper);     // 0.32x
  EXPECT_LT(error[16], 0.002);
}
