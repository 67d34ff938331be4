// msm_surface_footprint against ray casting in double precision: the surface points seen through
// screen positions a small step away, found by unprojecting the screen position and intersecting
// the ray with the plane (no Jacobian, no code shared with the header).
#include <glm/gtc/matrix_transform.hpp>
#include <gtest/gtest.h>

#include "msm/footprint.h"
#include "msm/util/random.h"

namespace {

// The point of the plane (p0, n) seen at screen position `screen` (pixels, y down).
glm::dvec3 cast(const glm::dmat4& inverse_vp, glm::dvec2 viewport, glm::dvec2 screen, glm::dvec3 p0, glm::dvec3 n) {
  const glm::dvec2 ndc = screen / viewport * 2.0 - 1.0;
  glm::dvec4 a = inverse_vp * glm::dvec4(ndc, 0.0, 1.0), b = inverse_vp * glm::dvec4(ndc, 1.0, 1.0);
  const glm::dvec3 o = glm::dvec3(a) / a.w, d = glm::dvec3(b) / b.w - o;
  return o + d * (glm::dot(p0 - o, n) / glm::dot(d, n));
}

glm::dvec2 screen_of(const glm::dmat4& vp, glm::dvec2 viewport, glm::dvec3 p) {
  const glm::dvec4 c = vp * glm::dvec4(p, 1.0);
  return (glm::dvec2(c) / c.w + 1.0) * 0.5 * viewport;
}

struct Rng {
  msm::util::SplitMix64 generator;
  double uniform(double lo, double hi) { return lo + (hi - lo) * generator.uniform(); }
};

} // namespace

TEST(Footprint, MatchesRayCastingForPerspectiveAndOrthographicCameras) {
  Rng rng{msm::util::SplitMix64(7)};
  int checked = 0;
  for (int i = 0; i < 400; ++i) {
    const glm::vec3 eye(rng.uniform(-5, 5), rng.uniform(0.5, 6), rng.uniform(3, 9));
    const glm::vec3 target(rng.uniform(-1, 1), 0.0f, rng.uniform(-1, 1));
    const glm::vec2 viewport(float(rng.uniform(64, 2048)), float(rng.uniform(64, 2048)));
    const glm::mat4 view = glm::lookAtRH(eye, target, glm::vec3(0, 1, 0));
    const glm::mat4 projection =
        i % 2 ? glm::perspectiveRH_ZO(glm::radians(float(rng.uniform(20, 90))), viewport.x / viewport.y, 0.1f, 100.0f)
              : glm::orthoRH_ZO(-4.0f, 4.0f, -3.0f, 3.0f, 0.1f, 100.0f);
    const glm::mat4 vp = projection * view;
    // A plane through the target with a random normal that faces the camera.
    glm::vec3 n = glm::normalize(glm::vec3(rng.uniform(-1, 1), rng.uniform(0.2, 1), rng.uniform(-1, 1)));
    if (glm::dot(n, eye - target) < 0.0f) n = -n;
    const msm::MsmFootprint f = msm::msm_surface_footprint(vp, viewport, target, n);
    const glm::dmat4 dvp(vp), inv = glm::inverse(dvp);
    const glm::dvec2 s0 = screen_of(dvp, viewport, target);
    const glm::dvec3 p0(target), dn(n);
    const double h = 1e-3; // pixels: central differences, exact to O(h²) for the smooth cast
    for (int axis = 0; axis < 2; ++axis) {
      const glm::dvec2 step = axis == 0 ? glm::dvec2(h, 0) : glm::dvec2(0, h);
      const glm::dvec3 expected =
          (cast(inv, viewport, s0 + step, p0, dn) - cast(inv, viewport, s0 - step, p0, dn)) / (2 * h);
      const glm::dvec3 got(axis == 0 ? f.dp_dx : f.dp_dy);
      EXPECT_LT(glm::length(got - expected), 2e-3 * glm::length(expected) + 1e-7)
          << "case " << i << " axis " << axis << " expected length " << glm::length(expected);
      // The offset stays in the plane.
      EXPECT_LT(std::abs(glm::dot(got, dn)), 1e-4 * glm::length(expected) + 1e-7);
    }
    ++checked;
  }
  EXPECT_EQ(checked, 400);
}

TEST(Footprint, GrazingViewStaysFinite) {
  const glm::mat4 vp = glm::perspectiveRH_ZO(glm::radians(45.0f), 1.0f, 0.1f, 100.0f) *
                       glm::lookAtRH(glm::vec3(0, 0, 5), glm::vec3(0), glm::vec3(0, 1, 0));
  // The plane contains the view ray: the footprint is unbounded, the function stays finite.
  const msm::MsmFootprint f = msm::msm_surface_footprint(vp, glm::vec2(512), glm::vec3(0), glm::vec3(1, 0, 0));
  for (int k = 0; k < 3; ++k) { EXPECT_TRUE(std::isfinite(f.dp_dx[k]) && std::isfinite(f.dp_dy[k])); }
  EXPECT_GT(glm::length(f.dp_dx) + glm::length(f.dp_dy), 1e3f);
}
