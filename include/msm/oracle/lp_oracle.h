// Reference solution of the general moment problem (2015 paper, Problem 1) on a finite depth grid
// by linear programming (its Algorithm 1), solved with GLPK: the sharp bounds on Z(z < zf) and
// Z(z <= zf) over all distributions on the grid with prescribed expectations of any basis b(z).
// Double precision, C++ only, independent of include/msm/*.h.
#ifndef MSM_ORACLE_LP_ORACLE_H
#define MSM_ORACLE_LP_ORACLE_H

#include "msm/oracle/distribution.h"

#include <cstddef>
#include <functional>
#include <span>
#include <string>
#include <vector>

namespace msm::oracle {

// b: depth -> R^size, without the constant b_0 = 1 (the LP adds that row itself).
struct Basis {
  std::string name;
  std::size_t size = 0;
  BasisFunction eval; // eval(z, out) with out.size() == size
  std::vector<double> operator()(double z) const;
};

// (z, z^2, .., z^m): Hamburger/Hausdorff MSM (2015 Eq. 1 for m = 4). Precondition: m >= 1.
Basis power_basis(int m);
// (sin 2 pi z, cos 2 pi z, sin 4 pi z, cos 4 pi z, .., sin 2k pi z, cos 2k pi z): `pairs` = k,
// 2015 TMSM for k = 2 in this order. Precondition: pairs >= 1.
Basis trigonometric_basis(int pairs);
// (exp(c_1 z), .., exp(c_m z)) for the given exponents (ESM: {c}). Precondition: non-empty.
Basis exponential_basis(std::vector<double> exponents);
// (exp(c z), exp(2 c z), .., exp(m c z)). Precondition: m >= 1.
Basis exponential_basis(double c, int m);
// Any functions, evaluated in the given order. Precondition: non-empty, none empty.
Basis custom_basis(std::string name, std::vector<std::function<double(double)>> functions);

// E_Z(b) for a test distribution (its quadrature rule, see Mixture::quadrature).
std::vector<double> expectations(const Mixture& distribution, const Basis& basis);

// n >= 2 equally spaced points from a to b inclusive, the ends exact. Precondition: a < b.
std::vector<double> uniform_grid(double a, double b, std::size_t n);
// A finite stand-in for I = R: `inner` equally spaced points on [a, b] (spacing h = (b - a) /
// (inner - 1)), then on each side steps h g, h g^2, h g^3, .. (g = growth) until a point lies at
// or beyond distance `reach` from [a, b]. The step next to [a, b] is thus ~h and it grows by
// the factor g each step: a point at distance d from [a, b] has neighbours ~(g - 1) d + h away.
// With the defaults (inner 1001 on [0, 1], reach 1e3, growth 1.05) that is 1443 points: 1e-3
// spacing inside, 0.05 at distance 1, 5 at distance 100, 48 at the ends (+-1012).
// Precondition: a < b, inner >= 2, reach > 0, growth >= 1.
std::vector<double> wide_grid(double a, double b, std::size_t inner = 1001, double reach = 1e3, double growth = 1.05);
// Sorted union of two grids without exact duplicates (e.g. a grid plus known optimal atoms).
std::vector<double> merge_grids(std::span<const double> a, std::span<const double> b);

// How lp_bounds drives GLPK. lp_bounds first preconditions the LP itself (see lp_bounds), which
// makes GLPK's own presolver and scaling unnecessary, and harmful: measured on the power basis,
// m = 8, on wide_grid(0, 1), with them glp_simplex reports optima that violate the moment rows by
// up to 20 (relative); without them the rows hold to 1e-19 and the bounds match the moment
// oracle to 3e-12 once its atoms are grid points.
struct LpOptions {
  double tolerance = 1e-10;  // glp_smcp tol_bnd and tol_dj (GLPK default 1e-7; 1e-12 can cycle)
  bool presolve = false;     // glp_smcp presolve (which also scales the presolved problem)
  bool glpk_scaling = false; // glp_scale_prob(GLP_SF_AUTO)
  // glp_exact (rational arithmetic on the preconditioned double data) after the simplex, from its
  // basis. Removes the simplex tolerances; measured 0.07-0.5 s per call on 1001-1443 points for
  // m = 4..8, against 1-25 ms without.
  bool exact = false;
  int iteration_limit = 0; // per simplex run, against cycling; 0: 1000 + 2 (rows + columns)
  // Each preconditioned row may deviate from its target by this many times the worst-case effect
  // of rounding b to double (0: equality rows). The moment vectors of Diracs on grid points lie
  // on the boundary of the grid's moment cone; rounded, they can lie just outside.
  double rounding_band = 16;
  // A GLPK optimum is accepted when, re-solved from its basis in long double, the moment rows
  // hold to this (relative to 1 + |b_j|), no weight is below -this and no reduced cost has the
  // wrong sign by more than this (weights and costs in the preconditioned variables, where the
  // columns have norm <= 1). Otherwise lp_bounds tries again with the textbook ratio test
  // instead of Harris', then with tolerance 1e-7, and fails with all the reasons.
  double check_tolerance = 1e-8;
};

struct LpDistribution {
  std::vector<double> support; // grid points with nonzero weight, ascending (a weight may be
  std::vector<double> weights; // negative within LpOptions::check_tolerance)
};

struct LpBounds {
  bool feasible = false; // false also when GLPK fails; see status
  // "optimal"; "infeasible" when no distribution on the grid matches b to GLPK's tolerance (for b
  // on the boundary of the grid's moment cone that can include b that rounding moved just
  // outside, see rounding_band); else what went wrong.
  std::string status;
  double lower = 0;                          // min sum_{z_i < zf} w_i
  double upper = 0;                          // max sum_{z_i <= zf} w_i
  LpDistribution lower_argmin, upper_argmax; // optimal distributions, for debugging
  // The checks of LpOptions::check_tolerance, worst over both optima.
  double residual = 0, dual_violation = 0;
  // Which attempt produced the optima: "Harris ratio test", "textbook ratio test", "tolerance 1e-7".
  std::string solver;
};

// Sharp bounds over all distributions w on the grid with sum w_i = 1, sum_i w_i basis(z_i) = b,
// w >= 0 (2015 Algorithm 1, and its maximizing twin for the upper bound). zf is added to the
// grid if it is not a grid point. Restricting the support to the grid can only shrink the set of
// distributions, so lower >= the bound over the grid's whole hull and upper <= it.
//
// Before GLPK sees it, the LP is preconditioned in long double: column i is scaled by
// 1 / |(1, b(z_i))| and the rows are orthonormalized (QR); neither changes the feasible set. The
// optimum GLPK returns is re-solved from its basis in long double and checked (see LpOptions).
//
// Preconditions (else std::invalid_argument): grid non-empty and finite, b.size() == basis.size,
// b and zf finite, basis values finite on the grid. Each call creates and deletes its own GLPK
// problem, and GLPK keeps its environment per thread, so concurrent calls from different threads
// share nothing; GLPK's terminal output is off for the calling thread during the call, and a GLPK
// environment that the call had to create, it frees (no GLPK memory outlives the call). Cost
// (two simplex runs, the second warm-started): ~10-25 ms for m <= 8 on the default wide_grid,
// ~1-10 ms on 1001 points of [0, 1]. The rounding band (LpOptions) relaxes the rows by a few ulps
// of b, which can only lower `lower` and raise `upper`.
LpBounds lp_bounds(std::span<const double> grid, const Basis& basis, std::span<const double> b, double zf,
                   const LpOptions& options = {});

} // namespace msm::oracle

#endif // MSM_ORACLE_LP_ORACLE_H
