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

} // namespace

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
  const float sigma = 0.3f, s = 7.0f, f = msm::msm_scattering_phase_term(sigma, 0.8f, 0.2f, 0.5f);
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
