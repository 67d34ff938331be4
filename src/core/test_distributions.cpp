#include "test_distributions.h"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace msm::test {

Distribution random_diracs(std::mt19937_64& rng, int count, double lo, double hi) {
  std::uniform_real_distribution<double> depth(lo, hi), weight(0.01, 1.0);
  Distribution d;
  double sum = 0.0;
  for (int i = 0; i < count; ++i) {
    d.z.push_back(depth(rng));
    d.w.push_back(weight(rng));
    sum += d.w.back();
  }
  for (double& w : d.w) w /= sum;
  return d;
}

Distribution random_continuous(std::mt19937_64& rng, double lo, double hi) {
  constexpr int atoms = 512;
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  int bumps = 1 + int(unit(rng) * 3.0) % 3;
  std::vector<double> center(bumps), width(bumps), mass(bumps);
  std::vector<bool> gaussian(bumps);
  for (int k = 0; k < bumps; ++k) {
    center[k] = lo + (hi - lo) * unit(rng);
    width[k] = (hi - lo) * (0.005 + 0.2 * unit(rng));
    mass[k] = 0.1 + unit(rng);
    gaussian[k] = unit(rng) < 0.5;
  }
  Distribution d;
  double sum = 0.0;
  for (int i = 0; i < atoms; ++i) {
    double z = lo + (hi - lo) * (i + 0.5) / atoms, density = 0.0;
    for (int k = 0; k < bumps; ++k) {
      double t = (z - center[k]) / width[k];
      density += mass[k] * (gaussian[k] ? std::exp(-0.5 * t * t) : (std::abs(t) <= 1.0 ? 1.0 : 0.0)) / width[k];
    }
    if (density > 0.0) {
      d.z.push_back(z);
      d.w.push_back(density);
      sum += density;
    }
  }
  if (d.z.empty()) return random_diracs(rng, 1, lo, hi); // a bump narrower than the quadrature
  for (double& w : d.w) w /= sum;
  return d;
}

Distribution random_distribution(std::mt19937_64& rng, double lo, double hi) {
  std::uniform_int_distribution<int> coin(0, 1), count(1, 8);
  return coin(rng) ? random_continuous(rng, lo, hi) : random_diracs(rng, count(rng), lo, hi);
}

double cdf_less(const Distribution& d, double zf) {
  double sum = 0.0;
  for (size_t i = 0; i < d.z.size(); ++i)
    if (d.z[i] < zf) sum += d.w[i];
  return sum;
}

double cdf_less_equal(const Distribution& d, double zf) {
  double sum = 0.0;
  for (size_t i = 0; i < d.z.size(); ++i)
    if (d.z[i] <= zf) sum += d.w[i];
  return sum;
}

std::vector<double> power_moments(const Distribution& d, int m) {
  std::vector<double> b(m + 1, 0.0);
  for (size_t i = 0; i < d.z.size(); ++i) {
    double p = d.w[i];
    for (int j = 0; j <= m; ++j, p *= d.z[i]) b[j] += p;
  }
  return b;
}

std::vector<double> trig_moments(const Distribution& d) {
  std::vector<double> b(4, 0.0);
  for (size_t i = 0; i < d.z.size(); ++i) {
    double a = 2.0 * std::numbers::pi * d.z[i];
    b[0] += d.w[i] * std::sin(a);
    b[1] += d.w[i] * std::cos(a);
    b[2] += d.w[i] * std::sin(2.0 * a);
    b[3] += d.w[i] * std::cos(2.0 * a);
  }
  return b;
}

glm::vec4 moments4f(const Distribution& d) {
  std::vector<double> b = power_moments(d, 4);
  return glm::vec4(float(b[1]), float(b[2]), float(b[3]), float(b[4]));
}

} // namespace msm::test
