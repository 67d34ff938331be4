// Depth distributions with exactly known CDF and (to rounding) known expectations, so that tests
// can feed the moment and LP oracles with "continuous" depth distributions and compare the bounds
// with the truth. Double precision, C++ only; shares no code with the GLSL/C++ headers.
#ifndef MSM_ORACLE_DISTRIBUTION_H
#define MSM_ORACLE_DISTRIBUTION_H

#include <cstddef>
#include <functional>
#include <span>
#include <vector>

namespace msm::oracle {

// Evaluates `out.size()` real functions at depth z (a shadow map's b(z), without b_0 = 1).
using BasisFunction = std::function<void(double z, std::span<double> out)>;

// A finite distribution sum_i weights[i] delta(depths[i]). Weights need not be normalized.
struct Discrete {
  std::vector<double> depths;
  std::vector<double> weights;
};

// Power moments b_j = sum_i w_i z_i^j / sum_i w_i for j = 0..m, so b_0 = 1; sums in long double,
// rounded once to double. Preconditions: depths.size() == weights.size() >= 1, weights >= 0 with
// a positive sum, m >= 0; throws std::invalid_argument otherwise.
std::vector<double> power_moments(std::span<const double> depths, std::span<const double> weights, int m);

// Z(z < zf) and Z(z <= zf) of a finite distribution (weights normalized by their sum).
// Same preconditions as power_moments.
double cdf_below(std::span<const double> depths, std::span<const double> weights, double zf);
double cdf_at_or_below(std::span<const double> depths, std::span<const double> weights, double zf);

// A mixture of Diracs, uniforms, truncated Gaussians and Beta distributions on intervals. The
// component weights are normalized on use, so they need only be positive.
//
// The CDF is exact (closed forms; the Beta CDF by the incomplete-beta continued fraction, ~1e-15).
// Expectations use a quadrature rule per component (see quadrature()), which is exact for
// polynomials of the stated degree and accurate to rounding for smooth functions such as
// sin(2 pi k z) (k <= 16) or exp(c z) (|c| (b - a) <= 200) on the component's interval.
class Mixture {
 public:
  // delta(z). Precondition: z finite, weight > 0.
  Mixture& dirac(double z, double weight = 1.0);
  // Uniform on [a, b]. Precondition: a < b finite, weight > 0.
  Mixture& uniform(double a, double b, double weight = 1.0);
  // Gaussian N(mean, sigma^2) restricted to [a, b] and renormalized. Precondition: a < b,
  // sigma > 0, and [a, b] not further than 30 sigma from the mean (else it has no mass in double).
  Mixture& truncated_gaussian(double mean, double sigma, double a, double b, double weight = 1.0);
  // Beta(alpha, beta) mapped affinely from [0, 1] onto [a, b]. Precondition: alpha, beta > 0,
  // a < b. alpha or beta < 1 gives an unbounded density; the quadrature handles it (Gauss-Jacobi).
  Mixture& beta(double alpha, double beta, double a, double b, double weight = 1.0);

  bool empty() const { return components_.empty(); }

  // Z(z < zf) and Z(z <= zf); they differ only at the Diracs. Precondition: !empty().
  double cdf_below(double zf) const;
  double cdf_at_or_below(double zf) const;

  // A finite distribution with the mixture's expectations: Diracs as themselves, a uniform as
  // 16 panels of 20-point Gauss-Legendre (exact for polynomials of degree <= 39), a truncated
  // Gaussian as Gauss-Legendre panels no wider than sigma/4 over [a, b] cut to mean +- 12 sigma
  // (what is cut weighs < 1e-32), a Beta as 64-point Gauss-Jacobi (exact for the Beta density
  // times polynomials of degree <= 127). Weights sum to 1. Precondition: !empty().
  Discrete quadrature() const;

  // b_0..b_m (b_0 = 1) through quadrature(). Precondition: !empty(), m >= 0.
  std::vector<double> power_moments(int m) const;
  // E(f(z)) for the `count` functions that f evaluates, through quadrature(). Precondition: !empty().
  std::vector<double> expectations(const BasisFunction& f, std::size_t count) const;
  // Mean and variance through quadrature().
  double mean() const;
  double variance() const;

 private:
  enum class Kind { dirac, uniform, gaussian, beta };
  struct Component {
    Kind kind;
    double weight, a, b, p, q; // p, q: Gaussian mean and sigma, or Beta alpha and beta
    Discrete rule;             // the component's quadrature, weights summing to 1
  };
  std::vector<Component> components_;
  Mixture& add(Component component);
  double cdf(double zf, bool inclusive) const;
};

} // namespace msm::oracle

#endif // MSM_ORACLE_DISTRIBUTION_H
