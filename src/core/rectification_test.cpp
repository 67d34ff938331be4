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

// ---- Spot lights: the rectification of a point source ----

// The law of sines at a hand-picked triangle: d = 2, ψ = 30°, γ = 60°, so the angle at the point is
// 90°: t = d sin ψ = 1, r = d sin γ = √3; dt/dψ = d sin γ / sin²(ψ + γ) = √3 = r² / h (h = d sin γ),
// and a central difference of t(ψ) agrees.
TEST(SpotRectification, LawOfSinesAtAHandPickedTriangle) {
  const float d = 2.0f, psi = float(M_PI / 6), gamma = float(M_PI / 3);
  const glm::vec2 tr = msm::msm_spot_ray_distances(d, psi, gamma);
  EXPECT_NEAR(tr.x, 1.0f, 1e-6f);
  EXPECT_NEAR(tr.y, std::sqrt(3.0f), 1e-6f);
  const float h = d * std::sin(gamma);
  EXPECT_NEAR(msm::msm_spot_dt_dpsi(d, psi, gamma), std::sqrt(3.0f), 1e-6f);
  EXPECT_NEAR(msm::msm_spot_dt_dpsi(d, psi, gamma), tr.y * tr.y / h, 1e-6f);
  const float e = 1e-3f;
  const float central =
      (msm::msm_spot_ray_distances(d, psi + e, gamma).x - msm::msm_spot_ray_distances(d, psi - e, gamma).x) /
      (2.0f * e);
  EXPECT_NEAR(central, std::sqrt(3.0f), 1e-3f);
  // Diverging rays never meet.
  EXPECT_LT(msm::msm_spot_ray_distances(d, 2.0f, 1.2f).x, 0.0f);
}

// A hand-placed point: camera at the origin, the light at (0, 2, 0), the point q = (1, 2, 0). Seen
// from the light q lies at 90° from the direction to the camera (ψ = π/2); seen from the camera at
// γ = atan(1/2) from the light (the view's inclination θ = π − γ); t = |q| = √5, r = 1.
TEST(SpotRectification, PsiAndGammaOfAHandPlacedPoint) {
  const glm::vec3 camera(0.0f), light(0.0f, 2.0f, 0.0f), q(1.0f, 2.0f, 0.0f);
  const msm::RectificationFrame f = msm::msm_spot_rectification_frame(camera, light);
  const glm::vec3 p = msm::msm_to_rectification_space(f, q);
  const float d = 2.0f;
  EXPECT_NEAR(msm::msm_spot_psi(p, d), float(M_PI / 2), 1e-6f);
  const float gamma = std::atan(0.5f);
  EXPECT_NEAR(msm::msm_rectified_spherical(p).z, float(M_PI) - gamma, 1e-6f);
  const glm::vec2 tr = msm::msm_spot_ray_distances(d, float(M_PI / 2), gamma);
  EXPECT_NEAR(tr.x, std::sqrt(5.0f), 1e-5f);
  EXPECT_NEAR(tr.y, 1.0f, 1e-5f);
  // The light itself is at ψ = 0 from every point of the line behind it, and the camera at ψ = 0.
  EXPECT_NEAR(msm::msm_spot_psi(msm::msm_to_rectification_space(f, glm::vec3(0.0f, 3.0f, 0.0f)), d), float(M_PI),
              1e-6f);
  EXPECT_NEAR(msm::msm_spot_psi(glm::vec3(0.0f), d), 0.0f, 1e-6f);
}

// Texels to light rays and back: the light ray of texel uv (from the light) has ψ = u ψ_max and
// the slice of v; a point at distance ρ on it has the rectified depth msm_spot_rectified_signed_depth
// says, which grows with ρ (γ grows along every light ray); the view lookup of that point reads
// its own row and depth, at u half a texel before its ψ.
TEST(SpotRectification, TexelsMapToLightRaysThroughTheLight) {
  const glm::vec3 camera(0.0f, 1.0f, 4.5f), light(0.0f, 2.0f, 0.0f), axis(0.0f, -1.0f, 0.0f);
  const msm::RectificationFrame f = msm::msm_spot_rectification_frame(camera, light);
  View v{glm::dvec3(camera),
         glm::normalize(glm::dvec3(0, -0.1, -4.5)),
         {},
         {},
         std::tan(0.4),
         4.0 / 3.0,
         12.0,
         glm::normalize(glm::dvec3(light - camera))};
  v.right = glm::normalize(glm::cross(v.forward, glm::dvec3(0, 1, 0)));
  v.up = glm::cross(v.right, v.forward);
  msm::RectifiedBounds b = msm::msm_rectification_bounds(f, v.far_corners());
  const glm::vec3 axis_f =
      msm::msm_to_rectification_space(msm::RectificationFrame{glm::vec3(0.0f), f.x_axis, f.y_axis, f.z_axis}, axis);
  b = msm::msm_spot_rectified_bounds(b, axis_f, float(M_PI / 6));
  const float d = glm::length(light - camera);
  // The cone's widest ray makes β + 30° with +z, β the axis's angle from the light → camera direction.
  const float beta = std::acos(glm::dot(axis, glm::normalize(camera - light)));
  EXPECT_NEAR(b.r_max, std::min(beta + float(M_PI / 6), float(M_PI)) * (1.0f + msm::MSM_RECT_R_PAD), 1e-5f);
  const float width = 256.0f;
  for (glm::vec2 uv : {glm::vec2(0.3f, 0.5f), glm::vec2(0.7f, 0.2f), glm::vec2(0.55f, 0.9f)}) {
    const glm::vec3 dir = msm::msm_spot_light_ray_direction(f, b, uv);
    EXPECT_NEAR(glm::length(dir), 1.0f, 1e-5f);
    const float psi = uv.x * b.r_max;
    float previous = -2.0f;
    for (float rho : {0.5f, 1.0f, 2.0f, 4.0f}) {
      const glm::vec3 q = light + rho * dir;
      const glm::vec3 p = msm::msm_to_rectification_space(f, q);
      EXPECT_NEAR(msm::msm_spot_psi(p, d), psi, 2e-5f) << uv.x << " " << rho;
      const float depth = msm::msm_spot_rectified_signed_depth(b, psi, d, rho);
      const glm::vec3 c = msm::msm_rectified_coordinates(b, p);
      EXPECT_NEAR(depth, 2.0f * std::clamp(c.z, 0.0f, 1.0f) - 1.0f, 2e-5f);
      EXPECT_GE(depth, previous);
      previous = depth;
      const glm::vec3 lookup = msm::msm_spot_view_lookup(f, b, d, q, width);
      EXPECT_NEAR(lookup.x, uv.x - 0.5f / width, 2e-5f);
      EXPECT_NEAR(lookup.y, uv.y, 2e-5f);
      EXPECT_NEAR(lookup.z, c.z, 1e-6f);
    }
  }
}

// The spot's unshadowed in-scattering by 32 midpoints in ψ against 200000 midpoints in t of the
// same integrand (msm_local_light_inscattering, the ray tracer's): rays inside the cone, across its
// edges, just below the light (h = 0.1 m) and cut by the range. Largest relative error measured 1.9e-3
// (the cone's edges, where the integrand has kinks).
TEST(SpotRectification, UnshadowedInScatteringByPsiMatchesAFineIntegralInT) {
  const glm::vec3 light(0.0f, 2.0f, 0.0f), axis(0.0f, -1.0f, 0.0f), intensity(4.0f);
  const float cos_outer = std::cos(float(M_PI / 6)), cos_inner = std::cos(25.0f * float(M_PI / 180));
  const float extinction = 0.2f, albedo = 1.0f, g = 0.3f;
  struct Ray {
    glm::vec3 camera, target;
    float s, range;
  };
  const Ray rays[] = {{{0.0f, 1.0f, 4.5f}, {0.0f, 0.9f, 0.0f}, 7.0f, 6.0f},
                      {{0.0f, 1.0f, 4.5f}, {0.6f, 0.3f, 0.0f}, 7.5f, 6.0f},
                      {{0.0f, 1.0f, 4.5f}, {0.05f, 1.9f, 0.0f}, 8.0f, 6.0f},
                      {{-3.0f, 0.5f, 0.0f}, {0.0f, 0.4f, 0.1f}, 6.0f, 2.0f},
                      {{2.0f, 0.2f, 3.0f}, {-0.3f, 1.0f, -0.2f}, 9.0f, 10.0f}};
  for (const Ray& ray : rays) {
    const glm::vec3 dir = glm::normalize(ray.target - ray.camera);
    const glm::vec3 got =
        msm::msm_spot_unshadowed_inscattering(ray.camera, dir, ray.s, light, axis, intensity, ray.range, cos_outer,
                                              cos_inner, extinction, albedo, g, msm::MSM_SPOT_INSCATTERING_SAMPLES);
    const int n = 200000;
    double want = 0.0;
    for (int i = 0; i < n; ++i) {
      const double t = (i + 0.5) * ray.s / n;
      const glm::vec3 fe = msm::msm_local_light_inscattering(ray.camera + float(t) * dir, dir, light, axis, intensity,
                                                             ray.range, cos_outer, cos_inner, extinction, albedo, g);
      want += std::exp(-extinction * t) * fe.x * ray.s / n;
    }
    std::printf("spot in-scattering: by psi %.6g, by t %.6g, relative %.2e\n", got.x, want,
                std::abs(got.x / want - 1.0));
    EXPECT_GT(want, 0.0);
    EXPECT_NEAR(got.x, want, 3e-3 * want);
  }
  // A ray of no length or straight through the light: nothing, never NaN.
  EXPECT_EQ(msm::msm_spot_unshadowed_inscattering({0, 1, 4.5f}, {0, 0, -1}, 0.0f, light, axis, intensity, 6.0f,
                                                  cos_outer, cos_inner, extinction, albedo, g, 32)
                .x,
            0.0f);
  const glm::vec3 through = msm::msm_spot_unshadowed_inscattering(
      {0, 0, 0}, {0, 1, 0}, 5.0f, light, axis, intensity, 6.0f, cos_outer, cos_inner, extinction, albedo, g, 32);
  EXPECT_TRUE(std::isfinite(through.x));
}

// The one approximation of the spot's prefix sums: a row weighs its light rays at the slice's mean
// γ (msm_spot_row_gamma) where each view ray has its own. On the view of the render test's beam (a
// spot 2 m up, cone 30°, the camera 4.5 m away, σt 0.2) and a shaft cut out of the cone's middle
// (light rays within 10° of the axis shadowed), the visible fraction with the row's weights against
// the ray's own, over the rays that cross the cone: isotropic (the transmittance alone depends on
// γ) and Henyey–Greenstein g = 0.5 (the phase too). Measured mean / largest difference: 0.0002 /
// 0.0025 (g = 0) and 0.0005 / 0.0043 (g = 0.5); weighed by the cone alone (no phase, no
// transmittance) the mean is 0.0002 and 0.0074: the phase is what the row's γ must carry.
TEST(SpotRectification, RowWeightsAtTheSlicesMeanGammaApproachTheRaysOwn) {
  const glm::vec3 camera(0.0f, 1.0f, 4.5f), light(0.0f, 2.0f, 0.0f), axis(0.0f, -1.0f, 0.0f);
  const float outer = float(M_PI / 6), cos_outer = std::cos(outer), cos_inner = std::cos(25.0f * float(M_PI / 180));
  View v{glm::dvec3(camera),
         glm::normalize(glm::dvec3(0, -0.1, -4.5)),
         {},
         {},
         std::tan(glm::radians(25.0)),
         4.0 / 3.0,
         20.0,
         glm::normalize(glm::dvec3(light - camera))};
  v.right = glm::normalize(glm::cross(v.forward, glm::dvec3(0, 1, 0)));
  v.up = glm::cross(v.right, v.forward);
  const msm::RectificationFrame f = msm::msm_spot_rectification_frame(camera, light);
  msm::RectifiedBounds b = msm::msm_rectification_bounds(f, v.far_corners());
  b = msm::msm_spot_rectified_bounds(
      b, glm::vec3(glm::dot(f.x_axis, axis), glm::dot(f.y_axis, axis), glm::dot(f.z_axis, axis)), outer);
  const float d = glm::length(light - camera), extinction = 0.2f, s = 8.0f;
  const float shaft = std::cos(float(M_PI / 18));
  for (float g : {0.0f, 0.5f}) {
    double sum = 0.0, largest = 0.0, sum_cone_only = 0.0;
    int rays = 0;
    for (int y = 0; y < 24; ++y)
      for (int x = 0; x < 32; ++x) {
        const glm::vec3 dir = glm::normalize(glm::vec3(v.direction((x + 0.5) / 16.0 - 1.0, (y + 0.5) / 12.0 - 1.0)));
        const glm::vec3 end = msm::msm_to_rectification_space(f, camera + s * dir);
        const float gamma = msm::msm_angle_between(dir, light - camera);
        const float row_v = msm::msm_rectified_coordinates(b, end).y;
        const float row_gamma = msm::msm_spot_row_gamma(b, row_v);
        const float psi_end = std::min(msm::msm_spot_psi(end, d), b.r_max);
        double own[2] = {0.0, 0.0}, row[2] = {0.0, 0.0}, cone_only[2] = {0.0, 0.0}; // Σ w V, Σ w
        const int n = 512;
        for (int i = 0; i < n; ++i) {
          const float psi = (float(i) + 0.5f) * psi_end / float(n);
          const glm::vec3 ray = msm::msm_spot_light_ray_direction(f, b, glm::vec2(psi / b.r_max, row_v));
          const float cone = msm::msm_spot_cone(glm::dot(ray, axis), cos_outer, cos_inner);
          const double visible = glm::dot(ray, axis) > shaft ? 0.0 : 1.0;
          const double w_own = msm::msm_spot_prefix_sum_weight(d, psi, gamma, extinction, g, cone);
          const double w_row = msm::msm_spot_prefix_sum_weight(d, psi, row_gamma, extinction, g, cone);
          own[0] += w_own * visible;
          own[1] += w_own;
          row[0] += w_row * visible;
          row[1] += w_row;
          cone_only[0] += cone * visible;
          cone_only[1] += cone;
        }
        if (!(own[1] > 0.0) || !(row[1] > 0.0)) continue;
        const double difference = std::abs(own[0] / own[1] - row[0] / row[1]);
        sum += difference;
        largest = std::max(largest, difference);
        sum_cone_only += std::abs(own[0] / own[1] - cone_only[0] / cone_only[1]);
        ++rays;
      }
    std::printf("spot rows at the slice's mean gamma, g = %.1f: %d rays, visible fraction difference mean %.4f, "
                "largest %.4f; weighed by the cone alone: mean %.4f\n",
                g, rays, sum / rays, largest, sum_cone_only / rays);
    EXPECT_GT(rays, 100);
    EXPECT_LT(sum / rays, 0.001);
    EXPECT_LT(largest, 0.01);
    if (g > 0.0f) { EXPECT_LT(sum, 0.25 * sum_cone_only); }
  }
}

// The slices of the cone: by hand, an axis across the line light–camera (β = 90°) and a 30° cone
// span asin(sin 30° / sin 90°) = 30° on each side of the axis's azimuth; a cone that holds the
// line spans the full circle. For random cones, every direction inside maps into the wedge.
TEST(SpotRectification, ConeSlicesHoldEveryDirectionOfTheCone) {
  const float pad = msm::MSM_RECT_PHI_PAD;
  const glm::vec2 across = msm::msm_spot_cone_phi_range(glm::vec3(0.0f, 1.0f, 0.0f), float(M_PI / 6));
  EXPECT_NEAR(across.x, float(M_PI / 2 - M_PI / 6) - pad, 1e-6f);
  EXPECT_NEAR(across.y, float(M_PI / 3) + 2.0f * pad, 1e-6f);
  EXPECT_EQ(msm::msm_spot_cone_phi_range(glm::normalize(glm::vec3(0.1f, 0.0f, 1.0f)), 0.3f).y, float(2 * M_PI));
  EXPECT_EQ(msm::msm_spot_cone_phi_range(glm::normalize(glm::vec3(0.1f, 0.0f, -1.0f)), 0.3f).y, float(2 * M_PI));
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  int narrower = 0;
  for (int cone = 0; cone < 200; ++cone) {
    const glm::vec3 axis = glm::vec3(random_unit(rng));
    const float outer = float(0.05 + 1.2 * u(rng));
    msm::RectifiedBounds view{};
    view.phi_min = 0.0f;
    view.phi_span = float(2 * M_PI);
    const msm::RectifiedBounds b = msm::msm_spot_rectified_bounds(view, axis, outer);
    narrower += b.phi_span < float(2 * M_PI);
    for (int i = 0; i < 200; ++i) {
      // A direction within the cone: the axis turned by up to `outer` about a random perpendicular.
      const glm::dvec3 p = glm::normalize(glm::cross(glm::dvec3(axis), random_unit(rng)));
      const double a = outer * std::sqrt(u(rng));
      const glm::vec3 d = glm::vec3(std::cos(a) * glm::dvec3(axis) + std::sin(a) * p);
      const float v = msm::msm_rectified_coordinates(b, d).y;
      EXPECT_GE(v, 0.0f);
      EXPECT_LE(v, 1.0f) << "cone " << cone << " axis " << axis.x << " " << axis.y << " " << axis.z << " outer "
                         << outer;
    }
  }
  EXPECT_GT(narrower, 100);
}
