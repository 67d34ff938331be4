// The 37 candidate functions of the 2015 framework for choosing shadow-map data (2015 §3.2).
//
// The paper evaluated every set of four out of "37 rather elementary, smooth functions ranging
// from rational functions to exponentials and trigonometric functions", listed in its
// supplementary material, which is not available. This set is OURS (docs/techniques.md, "The 37
// candidate functions"): the families the paper names, each function smooth on [0, 1], none an
// affine combination of others (the constant b0 = 1 is always part of the moment vector, so a
// function like z / (1 + z) = 1 - 1 / (1 + z) would duplicate 1 / (1 + z)). It contains the power
// moments z..z^6 and the trigonometric moments of 2015 Eq. (1) and their m = 6 extension.
//
// CPU only, double precision: the functions exist for the evaluation, not for shaders.
#pragma once

#include <optional>
#include <span>
#include <string_view>

namespace msm::evaluate {

struct CandidateFunction {
  std::string_view name;    // identifier used in candidate lists, e.g. "z2", "sin2pi", "expm5"
  std::string_view formula; // human-readable, e.g. "z^2", "sin(2 pi z)", "exp(-5 z)"
  std::string_view family;  // "power", "trigonometric", "exponential", "logarithmic", "rational", "other"
  double (*value)(double z);
};

inline constexpr int kFunctionCount = 37;

// The 37 functions, in a fixed order (their index is their identity in results and checkpoints).
std::span<const CandidateFunction> candidate_functions();
// Index of the function with this name, if any.
std::optional<int> find_function(std::string_view name);

} // namespace msm::evaluate
