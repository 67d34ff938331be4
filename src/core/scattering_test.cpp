// The single-scattering building blocks of include/msm/scattering.h against double-precision
// quadrature and closed forms computed here independently (std::expm1, Simpson's rule).
#include <cmath>

#include <gtest/gtest.h>

#include "msm/scattering.h"

namespace {

// ∫ p dω over the sphere = 2π ∫_{-1}^{1} p(μ) dμ, Simpson's rule on 20000 intervals.
double phase_integral(float g) {
  const int n = 20000;
  double sum = 0.0;
  for (int i = 0; i <= n; ++i) {
    const double mu = -1.0 + 2.0 * i / n;
    const double w = (i == 0 || i == n) ? 1.0 : (i % 2 ? 4.0 : 2.0);
    sum += w * msm::msm_phase_henyey_greenstein(float(mu), g);
  }
  return 2.0 * M_PI * sum * (2.0 / n) / 3.0;
}

// The Henyey–Greenstein phase function in its textbook form, in long double: independent of the
// header's form. Its own cancellation (terms of 1 in 1 + g² − 2g cos θ, a result of at least
// (1 − |g|)² = 1e-8 at |g| = 0.9999) costs it 1e-19 / 1e-8 = 1e-11 relative there.
long double phase_exact(long double cos_theta, long double g) {
  const long double pi = 3.141592653589793238462643383279502884L;
  return (1.0L - g * g) / (4.0L * pi * std::pow(1.0L + g * g - 2.0L * g * cos_theta, 1.5L));
}

// Asymmetries up to what the scene loader accepts (the largest float below 1) and angles from the
// forward to the backward direction, where the phase function peaks as |g| → 1.
const float kLargestBelowOne = std::nextafter(1.0f, 0.0f);
const float kAsymmetries[] = {0.0f,   0.5f,    0.9f,     0.99f,
                              0.999f, 0.9999f, 0.99999f, kLargestBelowOne}; // and their negatives
const double kAngles[] = {
    0.0, 1e-6, 1e-5,        1e-4,        3e-4,        1e-3, 1e-2, 0.1, 0.5, 1.0, 1.5707963267948966,
    2.0, 3.0,  M_PI - 1e-3, M_PI - 1e-4, M_PI - 1e-6, M_PI};

} // namespace

TEST(Scattering, PhaseFunctionIsAccurateAsGApproachesOne) {
  // At the float cos θ and g it is given, within 16 ulp of the exact value, for every asymmetry
  // the scene loader accepts: no cancellation in 1 + g² − 2g cos θ (as small as (1 − |g|)² where
  // the function peaks) nor in 1 − g².
  for (float magnitude : kAsymmetries)
    for (float g : {magnitude, -magnitude})
      for (double theta : kAngles) {
        const float cos_theta = float(std::cos(theta));
        const long double exact = phase_exact(cos_theta, g);
        const float got = msm::msm_phase_henyey_greenstein(cos_theta, g);
        EXPECT_NEAR(double(got / exact), 1.0, 16 * 6e-8)
            << "g " << g << " theta " << theta << ": " << got << " vs " << double(exact);
      }
}

TEST(Scattering, PhaseTermOfDirectionsIsAccurateNearThePeak) {
  // The renderer's and the ray tracer's phase term of a light direction and a view direction, as
  // float unit vectors at angles from the forward direction (looking into the light) to the
  // backward one: within 1e-5 of the exact value for the angle between those very vectors, for
  // |g| up to 0.9999. Float's dot(u, v) is 1 below 3e-4 rad, so 1 − dot(u, v) would be off by
  // orders of magnitude there. The bound: the vectors' lengths (1 ± 1.2e-7 each) bound what any
  // form can know, (2.4e-7)² / 2 = 3e-14 in 1 − cos θ against (1 − |g|)² = 1e-8 at the peak, 4e-6
  // after the power 3/2 (measured: 3e-7).
  const float sigma = 0.3f, albedo = 0.8f;
  for (glm::dvec3 light : {glm::dvec3(0.3, 0.5, 0.8), glm::dvec3(0.0, 0.0, 1.0), glm::dvec3(-0.7, 0.1, 0.2)})
    for (float magnitude : kAsymmetries)
      for (float g : {magnitude, -magnitude}) {
        if (magnitude > 0.9999f) continue;
        const glm::dvec3 towards_light = glm::normalize(light);
        const glm::dvec3 across = glm::normalize(glm::cross(towards_light, glm::dvec3(1.0, 0.0, 0.0)));
        for (double theta : kAngles) {
          const glm::vec3 u(towards_light), v(std::cos(theta) * towards_light + std::sin(theta) * across);
          // The exact angle between the float vectors: 1 − cos θ as ½|û − v̂|² in long double.
          long double norm_u = 0.0L, norm_v = 0.0L, half_chord = 0.0L;
          for (int i = 0; i < 3; ++i) norm_u += (long double)u[i] * u[i], norm_v += (long double)v[i] * v[i];
          for (int i = 0; i < 3; ++i) {
            const long double d = u[i] / std::sqrt(norm_u) - v[i] / std::sqrt(norm_v);
            half_chord += 0.5L * d * d;
          }
          const long double exact = (long double)albedo * sigma * phase_exact(1.0L - half_chord, g);
          const float got = msm::msm_scattering_phase_term(sigma, albedo, g, u, v);
          EXPECT_NEAR(double(got / exact), 1.0, 1e-5)
              << "g " << g << " theta " << theta << ": " << got << " vs " << double(exact);
        }
      }
}

TEST(Scattering, PhaseFunctionIsNormalized) {
  for (float g : {0.0f, 0.3f, -0.5f, 0.8f}) EXPECT_NEAR(phase_integral(g), 1.0, 2e-4) << "g = " << g;
  EXPECT_FLOAT_EQ(msm::msm_phase_henyey_greenstein(0.3f, 0.0f), float(1.0 / (4.0 * M_PI)));
}

TEST(Scattering, ForwardScatteringPeaksTowardsTheLight) {
  // g > 0: brightest where the view direction points at the light (cos θ = 1).
  EXPECT_GT(msm::msm_phase_henyey_greenstein(1.0f, 0.6f), msm::msm_phase_henyey_greenstein(0.0f, 0.6f));
  EXPECT_GT(msm::msm_phase_henyey_greenstein(0.0f, 0.6f), msm::msm_phase_henyey_greenstein(-1.0f, 0.6f));
  // Mean cosine of HG is g: 2π ∫ μ p(μ) dμ.
  const int n = 20000;
  double mean = 0.0;
  for (int i = 0; i < n; ++i) {
    const double mu = -1.0 + (i + 0.5) * 2.0 / n;
    mean += mu * msm::msm_phase_henyey_greenstein(float(mu), 0.6f) * 2.0 / n;
  }
  EXPECT_NEAR(2.0 * M_PI * mean, 0.6, 1e-3);
}

TEST(Scattering, TransmittanceIntegralIsAccurateAtEveryScale) {
  // Relative error against the double closed form exp(−σ a) (−expm1(−σ (b − a))) / σ, including
  // optical depths where 1 − exp(−x) in float would lose every digit.
  for (double sigma : {1e-7, 1e-4, 1e-2, 0.5, 3.0, 50.0})
    for (double a : {0.0, 0.1, 2.0})
      for (double len : {1e-3, 0.5, 10.0}) {
        if (sigma * a > 60.0) continue; // exp(−σ a) below float's normal range: no digits to keep
        // The exact value for the float inputs the function sees (b − a of floats is exact here).
        const float fs = float(sigma), fa = float(a), fb = float(a + len);
        const double exact = std::exp(-double(fs) * fa) * -std::expm1(-double(fs) * (double(fb) - fa)) / fs;
        const float got = msm::msm_transmittance_integral(fs, fa, fb);
        EXPECT_NEAR(got / exact, 1.0, 2e-6 + 1e-6 * sigma * (a + len))
            << "sigma " << sigma << " a " << a << " len " << len;
      }
  EXPECT_EQ(msm::msm_transmittance_integral(1.0f, 2.0f, 1.0f), 0.0f); // empty segment
}

TEST(Scattering, RadianceOfAClearRayIsTheClosedForm) {
  // No occluder: exp(−σt s) L_s + f E (1 − exp(−σt s)) / σt (the analytic check).
  const float sigma = 0.3f, s = 7.0f;
  const float f = msm::msm_scattering_phase_term(sigma, 0.8f, 0.2f, glm::vec3(0.0f, 0.0f, 1.0f),
                                                 glm::vec3(std::sqrt(0.75f), 0.0f, 0.5f));
  const glm::vec3 ls(0.2f, 0.4f, 0.6f), e(3.0f, 2.0f, 1.0f);
  const glm::vec3 got = msm::msm_scattered_radiance(ls, e, sigma, f, s, 1.0f);
  for (int c = 0; c < 3; ++c) {
    const double exact =
        std::exp(-double(sigma) * s) * ls[c] + double(f) * e[c] * -std::expm1(-double(sigma) * s) / sigma;
    EXPECT_NEAR(got[c], exact, 1e-6 * exact);
  }
  // Fully shadowed: only the attenuated surface remains.
  EXPECT_NEAR(msm::msm_scattered_radiance(ls, e, sigma, f, s, 0.0f).x, std::exp(-0.3 * 7.0) * 0.2, 1e-7);
}
