// The 2015 error term (§3.2) of one candidate on one stack: the mean over the counted fragments of
// |shadow - PCF|, with shadow the candidate's reconstruction at the fragment's receiver depth from
// the moments of its kernel distribution (stack.h).
//
// Reconstructions:
//  - lp (a set of candidate functions): the sharp lower bound of 2015 Problem 1 on the depth grid,
//    GridLp. Since the kernel distribution Z itself lies on the grid and has the moments, the bound
//    lies in [0, PCF]: where PCF = 0 (fully lit) it is exactly 0, and by default those fragments
//    are not sent through the LP (EvaluateOptions::solve_lit sends them, for checking this).
//    Fragments of one texel share the moments; the LP of each layer warm-starts from the basis of
//    the same layer at the previous texel (scan order). An LP that GridLp cannot solve goes to GLPK
//    (EvaluateOptions::glpk_fallback).
//  - the closed forms of include/msm, in float as the renderer evaluates them, from the kernel's
//    moments accumulated in double and rounded once to float (the best a float map could hold):
//      pcf         PCF itself (error 0 by definition)
//      vsm         msm_vsm_shadow, (z, z^2), [0,1] depth, the float minimum variance
//      esm         msm_esm_shadow, exp(80 z) (MSM_ESM_C_DEFAULT)
//      evsm2       msm_evsm2_shadow, [-1,1] depth, c+ = 40 (32-bit float channels), float minimum variance
//      evsm4       msm_evsm4_shadow, c+ = 40, c- = 5.54 (128 bits)
//      hamburger4  msm_hamburger4_lower, [0,1] power moments biased for float (MSM_REP_UNIT_FLOAT)
//      hausdorff4  msm_hausdorff4_lower on [0,1], same moments and bias
//      tmsm        msm_trig_lower of msm_trig_bias(b), the 2015 trigonometric moments
#pragma once

#include <cstdint>
#include <vector>

#include "msm/evaluate/candidates.h"
#include "msm/evaluate/grid_lp.h"
#include "msm/evaluate/stack.h"

namespace msm::evaluate {

// Sums over one stack. Every field is a deterministic function of the stack and the candidate
// (no timings), so that results compare bit for bit across thread and rank counts.
struct SceneSums {
  double error_sum = 0.0; // sum of |shadow - PCF| over the counted fragments
  double max_error = 0.0;
  std::int64_t fragments = 0;  // counted fragments
  std::int64_t lps = 0;        // linear programs solved
  std::int64_t fallbacks = 0;  // LPs that GridLp could not solve, solved by GLPK (EvaluateOptions)
  std::int64_t failures = 0;   // LPs neither solved (counted with shadow 0, the most leaking)
  std::int64_t iterations = 0; // simplex pivots
  std::int64_t cold = 0;       // LPs without a usable warm start
  double error() const { return fragments > 0 ? error_sum / double(fragments) : 0.0; }
};

struct EvaluateOptions {
  bool solve_lit = false; // also solve the LPs of fully lit fragments (their bound is 0)
  // Where GridLp gives up (bases too ill-conditioned for long double, seen with m = 6 power
  // moments: 0.7% of the LPs), ask GLPK (msm::oracle::lp_bounds, ~5 ms an LP).
  bool glpk_fallback = true;
};

// The uniform depth grid of n points (stack.h): z_i = i / (n - 1).
std::vector<double> unit_grid(int n);

// The LP candidate's basis on the stack's grid. Throws SingularBasis.
GridBasis prepare_basis(const Candidate& candidate, int grid_points);

// One candidate on one stack. `basis` is required for lp candidates (prepare_basis with the stack's
// grid) and ignored otherwise.
SceneSums evaluate(const Stack& stack, const Candidate& candidate, const GridBasis* basis,
                   const EvaluateOptions& options = {});

// The closed form's shadow for one kernel distribution at receiver depth zf (the `shadow` above);
// Technique::lp is not a closed form (std::invalid_argument).
double closed_form_shadow(Technique technique, std::span<const GridAtom> kernel, double zf, int grid_points);

} // namespace msm::evaluate
