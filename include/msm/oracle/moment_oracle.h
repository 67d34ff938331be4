// Double-precision reference for moment shadow mapping: the sharp bounds on Z(z < zf) given the
// power moments b_0..b_m of Z on the real line (the Hamburger moment problem), computed by direct
// linear algebra (JCGT 2017 Algorithm 1 = 2015 Algorithm 2) in long double for any even m.
// Independent of include/msm/*.h on purpose: it is what that single-precision code is tested
// against. C++ only.
#ifndef MSM_ORACLE_MOMENT_ORACLE_H
#define MSM_ORACLE_MOMENT_ORACLE_H

#include <span>
#include <string>
#include <vector>

namespace msm::oracle {

struct MomentBounds {
  bool ok = false;
  std::string reason; // why !ok, empty when ok
  // B was singular (to the rounding of b, see MomentOptions): by 2015 Proposition 4 b then has a
  // unique representing distribution with at most m/2 atoms, which is what support/weights hold.
  // Also when rounding hides the higher moments and fewer atoms explain b to within its rounding
  // (e.g. depths in [100, 100.01] with m = 4).
  bool degenerate = false;
  // B is singular to within what rounding b to double can do, yet no atomic distribution explains
  // b: the bounds are Algorithm 1's for b exactly as given, and b's rounding alone could change
  // them a lot (e.g. uniform on [0.3, 0.35] with m = 8: (mean / sigma)^8 = 7e10 times the
  // rounding of b_8 reaches the smallest eigenvalue of the standardized B).
  bool ill_conditioned = false;
  // The optimal distribution: support[0] = zf with weights[0] = w0, then the other atoms in
  // ascending order. For ok && !degenerate there are 1 + m/2 points (fewer only when q's leading
  // coefficient vanishes, 2015 Proposition 3: an atom escaped to infinity with weight -> 0).
  std::vector<double> support;
  std::vector<double> weights;
  double lower = 0; // sum of weights[l] with support[l] < zf, l >= 1: the sharp lower bound
  double upper = 0; // lower + weights[0]: the sharp upper bound on Z(z <= zf)
  // Largest error of the optimal distribution's moments b_0..b_m (all of them, not only the
  // m/2 + 1 that determine the weights), in standardized depth u = (z - b1)/sigma and relative to
  // sum_l |w_l| |u_l|^j. A self-check: ~1e-18 for well-conditioned inputs (long double). Leaves
  // out b_m when an atom escaped to infinity (it took part of b_m along); when degenerate, counts
  // only the error beyond the worst-case rounding of b (one atom: 0).
  double residual = 0;
};

struct MomentOptions {
  // B (standardized, see moment_bounds) counts as singular when its smallest eigenvalue is below
  // singular_tolerance times the worst-case perturbation of B that rounding b to double can
  // cause. 0 never takes the degenerate branch: then a singular B fails (ok = false), as
  // Algorithm 1 does.
  double singular_tolerance = 100;
  // In the degenerate branch an atom within coincidence_tolerance standard deviations of Z
  // (sigma^2 = b2 - b1^2) of zf is taken to be at zf: it counts in upper, not in lower. The atoms
  // recovered from double moments carry errors of ~1e-8 sigma for 4 atoms 0.05 apart in [0, 1]
  // at m = 8.
  double coincidence_tolerance = 1e-6;
};

// The sharp lower bound inf Z(z < zf) and upper bound sup Z(z <= zf) over all distributions Z on
// the real line with power moments b = (b_0, ..., b_m), and the distributions that attain them.
//
// Steps (JCGT 2017 Algorithm 1): Hankel B = (b_{j+k}), j, k = 0..m/2; B q = (1, zf, .., zf^(m/2));
// the roots z_1..z_{m/2} of sum q_j z^j (companion-matrix eigenvalues, Newton-polished); the
// weights of z_0 = zf, z_1, .., z_{m/2} that step 5 gets from a Vandermonde solve, computed as the
// equal Christoffel weights 1 / (p(z_l)^T B^-1 p(z_l)), p(z) = (1, z, .., z^(m/2)), which stay
// accurate when a root is huge. All in long double, on standardized moments (depth
// u = (z - b1) / sigma, an affine map under which the problem is invariant), so the conditioning
// does not depend on where the depths lie. When B is singular to within the rounding of b, the
// unique distribution of Proposition 4 instead (Prony: roots of the kernel polynomial of the
// leading rank(B) x rank(B) block), see `degenerate`.
//
// Preconditions (else std::invalid_argument): b.size() = m + 1 with m >= 2 even, b[0] = 1 (to
// 1e-12), all finite, zf finite. Returns ok = false with a reason when B is not positive
// semi-definite (b is the moment vector of no distribution), when B is singular but b is no
// finite distribution's (mass escaped to infinity), or when the computed roots are not real.
MomentBounds moment_bounds(std::span<const double> b, double zf, const MomentOptions& options = {});

// Cantelli's inequality, i.e. moment_bounds for m = 2 (VSM) in closed form, for a distribution
// with this mean and variance > 0: the lower bound is (zf - mean)^2 / (variance + (zf - mean)^2)
// for zf > mean and 0 otherwise; the upper bound 1 - (the lower bound mirrored at the mean).
struct CantelliBounds {
  double lower, upper;
};
CantelliBounds cantelli_bounds(double mean, double variance, double zf);

} // namespace msm::oracle

#endif // MSM_ORACLE_MOMENT_ORACLE_H
