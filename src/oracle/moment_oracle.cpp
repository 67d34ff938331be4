// JCGT 2017 Algorithm 1 by plain linear algebra in long double, for any even m.
#include "msm/oracle/moment_oracle.h"

#include <Eigen/Dense>
#include <Eigen/Eigenvalues>

#include <algorithm>
#include <cmath>
#include <complex>
#include <limits>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

namespace msm::oracle {
namespace {

using Real = long double;
using Matrix = Eigen::Matrix<Real, Eigen::Dynamic, Eigen::Dynamic>;
using Vector = Eigen::Matrix<Real, Eigen::Dynamic, 1>;

// Relative rounding of one double: the inputs b_j carry at least this error.
constexpr Real double_epsilon = 0x1p-53L;

// sum_j c_j x^j and its derivative (Horner; coefficients ascending).
std::pair<Real, Real> evaluate(const std::vector<Real>& c, Real x) {
  Real p = 0, dp = 0;
  for (std::size_t j = c.size(); j-- > 0;) {
    dp = dp * x + p;
    p = p * x + c[j];
  }
  return {p, dp};
}

Real magnitude(const std::vector<Real>& c, Real x) {
  Real sum = 0, power = 1;
  for (Real cj : c) sum += std::fabs(cj) * power, power *= std::fabs(x);
  return sum;
}

// Real roots of sum_j c_j x^j in ascending order: companion-matrix eigenvalues, polished by Newton.
// A leading coefficient below 1e-12 of the largest lowers the degree (a root beyond ~1e12 sigma is
// taken to be at infinity). Returns false and says why when a root is not real (to polishing
// accuracy) or two roots coincide.
bool real_roots(std::vector<Real> c, std::vector<Real>& roots, std::string& why) {
  Real largest = 0;
  for (Real cj : c) largest = std::max(largest, std::fabs(cj));
  while (c.size() > 1 && std::fabs(c.back()) <= 1e-12L * largest) c.pop_back();
  const int degree = int(c.size()) - 1;
  roots.clear();
  if (degree <= 0) return true;
  std::vector<Real> guesses;
  if (degree == 1) {
    guesses.push_back(-c[0] / c[1]);
  } else {
    Matrix companion = Matrix::Zero(degree, degree);
    for (int i = 1; i < degree; ++i) companion(i, i - 1) = 1;
    for (int i = 0; i < degree; ++i) companion(i, degree - 1) = -c[i] / c[degree];
    Eigen::EigenSolver<Matrix> solver(companion, false);
    if (solver.info() != Eigen::Success) return why = "companion-matrix eigenvalues did not converge", false;
    for (int i = 0; i < degree; ++i) {
      const std::complex<Real> z = solver.eigenvalues()[i];
      // Distinct real roots come out with rounding-size imaginary parts; allow near-double roots,
      // whose eigenvalues split by ~sqrt(epsilon), and let the residual check below decide.
      if (std::fabs(z.imag()) > 1e-6L * (1 + std::fabs(z.real())))
        return why = "root of the kernel polynomial is not real", false;
      guesses.push_back(z.real());
    }
  }
  std::sort(guesses.begin(), guesses.end());
  // Newton in long double; a step may not leave the root's neighbourhood (a quarter of the gap to
  // the nearest other root), so that polishing cannot make two roots collide.
  for (int i = 0; i < degree; ++i) {
    Real gap = std::numeric_limits<Real>::infinity();
    if (i > 0) gap = std::min(gap, guesses[i] - guesses[i - 1]);
    if (i + 1 < degree) gap = std::min(gap, guesses[i + 1] - guesses[i]);
    Real x = guesses[i];
    for (int iteration = 0; iteration < 60; ++iteration) {
      const auto [p, dp] = evaluate(c, x);
      if (dp == 0) break;
      const Real step = p / dp, next = x - step;
      if (std::fabs(next - guesses[i]) > 0.25L * gap || std::fabs(evaluate(c, next).first) > std::fabs(p)) break;
      x = next;
      if (std::fabs(step) <= 4 * std::numeric_limits<Real>::epsilon() * (1 + std::fabs(x))) break;
    }
    if (std::fabs(evaluate(c, x).first) > 1e-10L * magnitude(c, x))
      return why = "root of the kernel polynomial is not real (Newton does not reach a real root)", false;
    roots.push_back(x);
  }
  std::sort(roots.begin(), roots.end());
  for (int i = 1; i < degree; ++i)
    if (roots[i] - roots[i - 1] <= 1e-14L * (1 + std::fabs(roots[i])))
      return why = "roots of the kernel polynomial coincide", false;
  return true;
}

// Weights of atoms at `nodes` from the Christoffel function of the k x k Hankel matrix H:
// w_l = 1 / (p(u_l)^T H^-1 p(u_l)), p(u) = (1, u, .., u^(k-1)). Equal to the Vandermonde solve of
// Algorithm 1 step 5 whenever k atoms reproduce s_0..s_{2k-2} (H = V^T W V gives
// p(u_k)^T H^-1 p(u_l) = delta_kl / w_l; the errata for HPG Algorithm 3 uses the same identity),
// but stays accurate when a root is huge and the Vandermonde matrix is not. With fewer than k
// nodes (a root lost to infinity) it is the limit of the weights of the finite ones.
Vector christoffel_weights(const std::vector<Real>& nodes, const Eigen::LLT<Matrix>& hankel) {
  const int k = int(hankel.matrixLLT().rows());
  Vector w(nodes.size()), p(k);
  for (std::size_t l = 0; l < nodes.size(); ++l) {
    Real power = 1;
    for (int j = 0; j < k; ++j, power *= nodes[l]) p[j] = power;
    w[l] = 1 / hankel.matrixL().solve(p).squaredNorm();
  }
  return w;
}

// max_j (|sum_l w_l u_l^j - s_j| - noise_j)^+ / sum_l |w_l| |u_l|^j over j < count: the moment
// error relative to the size of the terms, beyond what rounding of b explains (noise may be empty).
Real moment_residual(const std::vector<Real>& nodes, const Vector& w, const std::vector<Real>& s, std::size_t count,
                     const std::vector<Real>& noise = {}) {
  Real worst = 0;
  for (std::size_t j = 0; j < count; ++j) {
    Real sum = 0, scale = 0;
    for (std::size_t l = 0; l < nodes.size(); ++l) {
      const Real term = w[l] * std::pow(nodes[l], Real(j));
      sum += term, scale += std::fabs(term);
    }
    const Real error = std::max<Real>(0, std::fabs(sum - s[j]) - (noise.empty() ? 0 : noise[j]));
    worst = std::max(worst, error / std::max(scale, std::numeric_limits<Real>::min()));
  }
  return worst;
}

MomentBounds failure(std::string reason) {
  MomentBounds result;
  result.reason = std::move(reason);
  return result;
}

// The moments in standardized depth u = (z - mu) / sigma, mu = b1, sigma^2 = b2 - b1^2, and the
// worst-case error that rounding each b_k to double (|delta b_k| <= eps |b_k|) puts into them.
struct Standardized {
  Real mu = 0, sigma = 0, variance = 0, variance_noise = 0;
  std::vector<Real> central, central_noise; // E (z - mu)^j and its rounding error
  std::vector<Real> s, noise;               // E u^j and its rounding error (sigma > 0 only)
};

Standardized standardize(std::span<const double> b) {
  const int m = int(b.size()) - 1;
  Standardized st;
  st.mu = b[1];
  st.central.assign(m + 1, 0), st.central_noise.assign(m + 1, 0);
  for (int j = 0; j <= m; ++j) {
    Real binomial = 1; // C(j, k)
    for (int k = 0; k <= j; ++k) {
      const Real term = binomial * std::pow(-st.mu, Real(j - k)) * Real(b[k]);
      st.central[j] += term;
      st.central_noise[j] += double_epsilon * std::fabs(term);
      binomial = binomial * (j - k) / (k + 1);
    }
  }
  st.central[0] = 1, st.central[1] = 0;
  st.variance = st.central[2], st.variance_noise = st.central_noise[2];
  if (st.variance > 0) {
    st.sigma = std::sqrt(st.variance);
    for (int j = 0; j <= m; ++j) {
      const Real scale = std::pow(st.sigma, Real(j));
      st.s.push_back(st.central[j] / scale);
      st.noise.push_back(st.central_noise[j] / scale);
    }
    st.s[2] = 1;
  }
  return st;
}

// The unique distribution of a singular B (2015 Proposition 4): r = rank(B) atoms at the roots of
// the monic degree-r polynomial orthogonal to 1, u, .., u^(r-1), i.e. leading r x r Hankel block
// times its coefficients = -(s_r .. s_{2r-1}) (Prony). r is where the leading blocks stop being
// positive definite beyond rounding: they hold the low moments, which carry less rounding than B.
// Returns "" or why b is not the moment vector of such a distribution.
std::string singular_distribution(const Matrix& hankel, const Matrix& noise_b, const Standardized& st, Real tolerance,
                                  std::vector<Real>& atoms, Vector& w) {
  const int n = int(hankel.rows()), m = int(st.s.size()) - 1;
  auto positive_definite = [&](int k) {
    Eigen::SelfAdjointEigenSolver<Matrix> block(hankel.topLeftCorner(k, k), Eigen::EigenvaluesOnly);
    return block.eigenvalues()[0] > tolerance * noise_b.topLeftCorner(k, k).norm();
  };
  int r = 1;
  while (r < n && positive_definite(r + 1)) ++r;
  if (r == n) return "B is not singular";
  const Eigen::LLT<Matrix> leading(hankel.topLeftCorner(r, r));
  Vector rhs(r);
  for (int j = 0; j < r; ++j) rhs[j] = -st.s[r + j];
  const Vector c = leading.solve(rhs);
  std::vector<Real> coefficients(c.data(), c.data() + r);
  coefficients.push_back(1);
  std::string why;
  if (!real_roots(coefficients, atoms, why)) return "B is singular and the " + why;
  if (int(atoms.size()) != r) return "B is singular, but b is no finite distribution's moments";
  w = christoffel_weights(atoms, leading);
  // The atoms must reproduce all moments to the rounding that b carries; else the mass that makes
  // B singular sits at infinity, e.g. b = (1, 0, 1, 0, 2).
  for (int j = 0; j <= m; ++j) {
    Real sum = 0, scale = 0;
    for (int l = 0; l < r; ++l) {
      const Real term = w[l] * std::pow(atoms[l], Real(j));
      sum += term, scale += std::fabs(term);
    }
    if (std::fabs(sum - st.s[j]) > 1e-9L * scale + tolerance * st.noise[j])
      return "B is singular, but b is not the moment vector of a " + std::to_string(r) + "-atomic distribution";
  }
  return "";
}

} // namespace

MomentBounds moment_bounds(std::span<const double> b, double zf, const MomentOptions& options) {
  const int m = int(b.size()) - 1;
  if (m < 2 || m % 2 != 0) throw std::invalid_argument("moment_bounds: b must hold b_0..b_m for even m >= 2");
  if (std::fabs(b[0] - 1) > 1e-12) throw std::invalid_argument("moment_bounds: b_0 must be 1");
  if (!std::isfinite(zf) || !std::all_of(b.begin(), b.end(), [](double x) { return std::isfinite(x); }))
    throw std::invalid_argument("moment_bounds: b and zf must be finite");
  const int n = m / 2 + 1;
  const Real tolerance = options.singular_tolerance;
  const Standardized st = standardize(b);
  if (st.variance < -std::max<Real>(tolerance, 1) * st.variance_noise)
    return failure("B is not positive semi-definite: b2 - b1^2 < 0");

  MomentBounds result;
  std::vector<Real> atoms; // the unique distribution when B is singular, standardized
  Vector w;
  Real sigma = st.sigma;
  if (st.variance <= tolerance * st.variance_noise) {
    // One Dirac at mu, to rounding. Zero variance forces c_3 = 0 for B >= 0 but leaves c_4, c_6,
    // .. free: those belong to mass escaping to infinity, not to a Dirac.
    if (tolerance == 0) return failure("B is singular (zero variance)");
    for (int j = 3; j <= m; ++j)
      if (std::fabs(st.central[j]) > tolerance * st.central_noise[j])
        return failure("B is singular, but b is no finite distribution's moments (zero variance but not higher "
                       "moments: mass at infinity)");
    sigma = 1, atoms = {0}, w = Vector::Ones(1);
  } else {
    Matrix hankel(n, n), noise_b(n, n);
    for (int j = 0; j < n; ++j)
      for (int k = 0; k < n; ++k) hankel(j, k) = st.s[j + k], noise_b(j, k) = st.noise[j + k];
    // The Frobenius norm bounds the spectral norm of the perturbation, hence the eigenvalue shift.
    const Real threshold = tolerance * noise_b.norm();
    const Real smallest = Eigen::SelfAdjointEigenSolver<Matrix>(hankel, Eigen::EigenvaluesOnly).eigenvalues()[0];
    if (tolerance > 0 && smallest < -threshold)
      return failure("B is not positive semi-definite (smallest eigenvalue " + std::to_string(double(smallest)) + ")");
    const Eigen::LLT<Matrix> cholesky(hankel);
    if (tolerance > 0 && smallest <= threshold) {
      // Singular to rounding. When no atomic distribution explains b, but B is positive definite
      // as given, fall through to Algorithm 1: it answers exactly for the b given.
      const std::string why = singular_distribution(hankel, noise_b, st, tolerance, atoms, w);
      if (!why.empty() && (smallest <= 0 || cholesky.info() != Eigen::Success)) return failure(why);
      if (!why.empty()) atoms.clear(), result.ill_conditioned = true;
    }
    if (atoms.empty()) {
      // Algorithm 1: B q = (1, uf, .., uf^(m/2)); the other atoms are the roots of sum q_j u^j.
      if (cholesky.info() != Eigen::Success) return failure("B is not positive definite");
      const Real uf = (Real(zf) - st.mu) / sigma;
      Vector rhs(n);
      Real power = 1;
      for (int j = 0; j < n; ++j, power *= uf) rhs[j] = power;
      const Vector q = cholesky.solve(rhs);
      std::vector<Real> nodes;
      if (!real_roots(std::vector<Real>(q.data(), q.data() + n), nodes, result.reason)) return failure(result.reason);
      nodes.insert(nodes.begin(), uf);
      const Vector all = christoffel_weights(nodes, cholesky);
      if (all.minCoeff() < -1e-9L) return failure("negative weight: B is numerically indefinite");
      // A root lost to infinity (fewer nodes) took weight -> 0 but a finite share of s_m along.
      result.residual = double(moment_residual(nodes, all, st.s, int(nodes.size()) == n ? m + 1 : m));
      result.support.push_back(zf);
      result.weights.push_back(double(all[0]));
      Real lower = 0;
      for (std::size_t l = 1; l < nodes.size(); ++l) {
        result.support.push_back(double(st.mu + sigma * nodes[l]));
        result.weights.push_back(double(all[l]));
        if (nodes[l] < uf) lower += all[l];
      }
      result.lower = double(lower);
      result.upper = double(lower + all[0]);
      result.ok = true;
      return result;
    }
  }

  // Degenerate: the distribution is known; zf is a support point only if an atom sits there.
  result.degenerate = true;
  result.residual =
      st.s.empty() || st.sigma == 0 || atoms.size() == 1 ? 0 : double(moment_residual(atoms, w, st.s, m + 1, st.noise));
  const Real uf = (Real(zf) - st.mu) / sigma;
  Real lower = 0, at = 0;
  result.support.push_back(zf);
  result.weights.push_back(0);
  for (std::size_t l = 0; l < atoms.size(); ++l) {
    if (std::fabs(atoms[l] - uf) <= options.coincidence_tolerance) {
      at += w[l];
      continue;
    }
    result.support.push_back(double(st.mu + sigma * atoms[l]));
    result.weights.push_back(double(w[l]));
    if (atoms[l] < uf) lower += w[l];
  }
  result.weights[0] = double(at);
  result.lower = double(lower);
  result.upper = double(lower + at);
  result.ok = true;
  return result;
}

CantelliBounds cantelli_bounds(double mean, double variance, double zf) {
  const double d = zf - mean, tail = variance / (variance + d * d);
  return d > 0 ? CantelliBounds{1 - tail, 1} : CantelliBounds{0, d < 0 ? tail : 1};
}

} // namespace msm::oracle
