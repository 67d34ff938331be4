// Test distributions: exact CDFs and quadrature rules (Golub-Welsch) for their expectations.
#include "msm/oracle/distribution.h"

#include <Eigen/Dense>

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace msm::oracle {
namespace {

using Real = long double;

void require(bool condition, const char* message) {
  if (!condition) throw std::invalid_argument(message);
}

void check_discrete(std::span<const double> depths, std::span<const double> weights) {
  require(!depths.empty() && depths.size() == weights.size(),
          "discrete: depths and weights must have the same size >= 1");
  Real total = 0;
  for (std::size_t i = 0; i < depths.size(); ++i) {
    require(std::isfinite(depths[i]) && std::isfinite(weights[i]) && weights[i] >= 0,
            "discrete: finite depths, weights >= 0");
    total += weights[i];
  }
  require(total > 0, "discrete: weights must have a positive sum");
}

// Nodes and weights on [-1, 1] for the weight (1 - t)^a (1 + t)^b (a, b > -1), from the eigen-
// decomposition of the Jacobi matrix of the monic Jacobi recurrence (Golub & Welsch 1969). The
// weights are normalized to sum 1: every caller renormalizes anyway, so mu_0 is irrelevant.
Discrete gauss_jacobi(int n, Real a, Real b) {
  Eigen::Matrix<Real, Eigen::Dynamic, 1> diag(n), sub(std::max(n - 1, 1));
  for (int k = 0; k < n; ++k) {
    const Real s = 2 * k + a + b;
    diag[k] = k == 0 ? (b - a) / (a + b + 2) : (b * b - a * a) / (s * (s + 2));
    if (k == 0) continue;
    // beta_k; for k = 1 the factor (s - 1) = (1 + a + b) cancels, which matters when a + b = -1.
    const Real beta = k == 1 ? 4 * (1 + a) * (1 + b) / ((2 + a + b) * (2 + a + b) * (3 + a + b))
                             : 4 * k * (k + a) * (k + b) * (k + a + b) / (s * s * (s + 1) * (s - 1));
    sub[k - 1] = std::sqrt(beta);
  }
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix<Real, Eigen::Dynamic, Eigen::Dynamic>> solver;
  solver.computeFromTridiagonal(diag, sub.head(n - 1), Eigen::ComputeEigenvectors);
  Discrete rule;
  Real total = 0;
  for (int i = 0; i < n; ++i) total += solver.eigenvectors()(0, i) * solver.eigenvectors()(0, i);
  for (int i = 0; i < n; ++i) {
    rule.depths.push_back(double(solver.eigenvalues()[i]));
    rule.weights.push_back(double(solver.eigenvectors()(0, i) * solver.eigenvectors()(0, i) / total));
  }
  return rule;
}

const Discrete& gauss_legendre20() {
  static const Discrete rule = gauss_jacobi(20, 0, 0); // thread-safe static initialization
  return rule;
}

// Appends `panels` equal panels of 20-point Gauss-Legendre on [lo, hi], node weights times
// density(z) and times `scale`.
template <class Density>
void add_panels(Discrete& out, double lo, double hi, int panels, double scale, Density density) {
  const Discrete& gl = gauss_legendre20();
  const double h = (hi - lo) / panels;
  for (int p = 0; p < panels; ++p)
    for (std::size_t i = 0; i < gl.depths.size(); ++i) {
      const double z = lo + h * (p + 0.5 * (gl.depths[i] + 1));
      out.depths.push_back(z);
      out.weights.push_back(scale * gl.weights[i] * density(z));
    }
}

// Standard normal tails, accurate far out because erfc is.
double upper_tail(double t) { return 0.5 * std::erfc(t / std::sqrt(2.0)); }
double lower_tail(double t) { return 0.5 * std::erfc(-t / std::sqrt(2.0)); }

// Continued fraction of the incomplete beta function (modified Lentz; Numerical Recipes 6.4).
double beta_continued_fraction(double a, double b, double x) {
  const double tiny = 1e-300;
  double c = 1, d = 1 - (a + b) * x / (a + 1);
  d = 1 / (std::fabs(d) < tiny ? tiny : d);
  double h = d;
  for (int k = 1; k <= 1000; ++k) {
    for (int odd = 0; odd < 2; ++odd) {
      const double coefficient = odd ? -(a + k) * (a + b + k) * x / ((a + 2 * k) * (a + 2 * k + 1))
                                     : k * (b - k) * x / ((a + 2 * k - 1) * (a + 2 * k));
      d = 1 + coefficient * d;
      d = 1 / (std::fabs(d) < tiny ? tiny : d);
      c = 1 + coefficient / c;
      if (std::fabs(c) < tiny) c = tiny;
      h *= c * d;
      if (odd && std::fabs(c * d - 1) < 1e-16) return h;
    }
  }
  return h;
}

// Regularized incomplete beta I_x(a, b), the Beta(a, b) CDF.
double regularized_incomplete_beta(double a, double b, double x) {
  if (x <= 0) return 0;
  if (x >= 1) return 1;
  const double front =
      std::exp(std::lgamma(a + b) - std::lgamma(a) - std::lgamma(b) + a * std::log(x) + b * std::log1p(-x));
  // The fraction converges fast on the side of the mean; use the symmetry I_x(a,b) = 1 - I_{1-x}(b,a).
  if (x < (a + 1) / (a + b + 2)) return front * beta_continued_fraction(a, b, x) / a;
  return 1 - front * beta_continued_fraction(b, a, 1 - x) / b;
}

} // namespace

std::vector<double> power_moments(std::span<const double> depths, std::span<const double> weights, int m) {
  check_discrete(depths, weights);
  require(m >= 0, "power_moments: m >= 0");
  std::vector<Real> sums(m + 1, 0);
  for (std::size_t i = 0; i < depths.size(); ++i) {
    Real power = weights[i];
    for (int j = 0; j <= m; ++j, power *= depths[i]) sums[j] += power;
  }
  std::vector<double> b(m + 1);
  for (int j = 0; j <= m; ++j) b[j] = double(sums[j] / sums[0]);
  b[0] = 1;
  return b;
}

double cdf_below(std::span<const double> depths, std::span<const double> weights, double zf) {
  check_discrete(depths, weights);
  Real below = 0, total = 0;
  for (std::size_t i = 0; i < depths.size(); ++i) (depths[i] < zf ? below : total) += weights[i];
  return double(below / (below + total));
}

double cdf_at_or_below(std::span<const double> depths, std::span<const double> weights, double zf) {
  check_discrete(depths, weights);
  Real below = 0, total = 0;
  for (std::size_t i = 0; i < depths.size(); ++i) (depths[i] <= zf ? below : total) += weights[i];
  return double(below / (below + total));
}

Mixture& Mixture::dirac(double z, double weight) {
  require(std::isfinite(z) && weight > 0, "Mixture::dirac: finite z, weight > 0");
  return add({Kind::dirac, weight, z, z, 0, 0, {}});
}

Mixture& Mixture::uniform(double a, double b, double weight) {
  require(std::isfinite(a) && std::isfinite(b) && a < b && weight > 0, "Mixture::uniform: a < b, weight > 0");
  return add({Kind::uniform, weight, a, b, 0, 0, {}});
}

Mixture& Mixture::truncated_gaussian(double mean, double sigma, double a, double b, double weight) {
  require(std::isfinite(a) && std::isfinite(b) && a < b && sigma > 0 && weight > 0,
          "Mixture::truncated_gaussian: a < b, sigma > 0");
  const double nearest = std::clamp(mean, a, b);
  require(std::fabs(nearest - mean) <= 30 * sigma, "Mixture::truncated_gaussian: [a, b] within 30 sigma of the mean");
  return add({Kind::gaussian, weight, a, b, mean, sigma, {}});
}

Mixture& Mixture::beta(double alpha, double beta, double a, double b, double weight) {
  require(std::isfinite(a) && std::isfinite(b) && a < b && alpha > 0 && beta > 0 && weight > 0,
          "Mixture::beta: alpha, beta > 0, a < b");
  return add({Kind::beta, weight, a, b, alpha, beta, {}});
}

// Builds the component's quadrature once: the Gauss-Jacobi eigen-decomposition costs milliseconds.
Mixture& Mixture::add(Component c) {
  Discrete& part = c.rule;
  switch (c.kind) {
  case Kind::dirac: part = {{c.a}, {1.0}}; break;
  case Kind::uniform: add_panels(part, c.a, c.b, 16, 1.0, [](double) { return 1.0; }); break;
  case Kind::gaussian: {
    // Integrate within 12 sigma of the interval point nearest the mean: beyond it the density is
    // below e^-72 of its largest value on [a, b]. Density relative to that point, so that an
    // interval far in the tail does not underflow.
    const double nearest = std::clamp(c.p, c.a, c.b);
    const double lo = std::max(c.a, nearest - 12 * c.q), hi = std::min(c.b, nearest + 12 * c.q);
    const int panels = std::max(1, int(std::ceil((hi - lo) / (0.25 * c.q))));
    const double d0 = (nearest - c.p) / c.q;
    add_panels(part, lo, hi, panels, 1.0, [&](double z) {
      const double t = (z - c.p) / c.q;
      return std::exp(-0.5 * (t - d0) * (t + d0));
    });
    break;
  }
  case Kind::beta: {
    // Beta density on [0, 1] is x^(alpha-1) (1-x)^(beta-1); with x = (1 + t)/2 that is the
    // Jacobi weight (1 - t)^(beta-1) (1 + t)^(alpha-1).
    part = gauss_jacobi(64, c.q - 1, c.p - 1);
    for (double& t : part.depths) t = c.a + (c.b - c.a) * 0.5 * (1 + t);
    break;
  }
  }
  Real total = 0;
  for (double w : part.weights) total += w;
  for (double& w : part.weights) w = double(w / total);
  components_.push_back(std::move(c));
  return *this;
}

double Mixture::cdf(double zf, bool inclusive) const {
  require(!components_.empty(), "Mixture: empty");
  Real total = 0, below = 0;
  for (const Component& c : components_) {
    total += c.weight;
    double f = 0;
    switch (c.kind) {
    case Kind::dirac: f = inclusive ? c.a <= zf : c.a < zf; break;
    case Kind::uniform: f = std::clamp((zf - c.a) / (c.b - c.a), 0.0, 1.0); break;
    case Kind::gaussian: {
      if (zf <= c.a) break;
      if (zf >= c.b) {
        f = 1;
        break;
      }
      const double lo = (c.a - c.p) / c.q, hi = (c.b - c.p) / c.q, t = (zf - c.p) / c.q;
      // Difference the tail on the interval's side: both terms are then not close to 1.
      f = lo > 0 ? (upper_tail(lo) - upper_tail(t)) / (upper_tail(lo) - upper_tail(hi))
                 : (lower_tail(t) - lower_tail(lo)) / (lower_tail(hi) - lower_tail(lo));
      break;
    }
    case Kind::beta: f = regularized_incomplete_beta(c.p, c.q, (zf - c.a) / (c.b - c.a)); break;
    }
    below += c.weight * f;
  }
  return double(below / total);
}

double Mixture::cdf_below(double zf) const { return cdf(zf, false); }
double Mixture::cdf_at_or_below(double zf) const { return cdf(zf, true); }

Discrete Mixture::quadrature() const {
  require(!components_.empty(), "Mixture: empty");
  Real total = 0;
  for (const Component& c : components_) total += c.weight;
  Discrete out;
  for (const Component& c : components_) {
    const double share = double(c.weight / total);
    for (std::size_t i = 0; i < c.rule.depths.size(); ++i) {
      out.depths.push_back(c.rule.depths[i]);
      out.weights.push_back(share * c.rule.weights[i]);
    }
  }
  return out;
}

std::vector<double> Mixture::power_moments(int m) const {
  const Discrete q = quadrature();
  return oracle::power_moments(q.depths, q.weights, m);
}

std::vector<double> Mixture::expectations(const BasisFunction& f, std::size_t count) const {
  const Discrete q = quadrature();
  std::vector<Real> sums(count, 0);
  std::vector<double> values(count);
  Real total = 0;
  for (std::size_t i = 0; i < q.depths.size(); ++i) {
    f(q.depths[i], values);
    for (std::size_t j = 0; j < count; ++j) sums[j] += Real(q.weights[i]) * values[j];
    total += q.weights[i];
  }
  std::vector<double> result(count);
  for (std::size_t j = 0; j < count; ++j) result[j] = double(sums[j] / total);
  return result;
}

double Mixture::mean() const { return power_moments(1)[1]; }

double Mixture::variance() const {
  // Central second moment directly, not b2 - b1^2, which cancels for narrow distributions.
  const Discrete q = quadrature();
  const double mu = mean();
  Real sum = 0, total = 0;
  for (std::size_t i = 0; i < q.depths.size(); ++i) {
    sum += Real(q.weights[i]) * (q.depths[i] - mu) * (q.depths[i] - mu);
    total += q.weights[i];
  }
  return double(sum / total);
}

} // namespace msm::oracle
