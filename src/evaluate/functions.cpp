// The 37 candidate functions (see functions.h for why these).
#include "msm/evaluate/functions.h"

#include <array>
#include <cmath>
#include <numbers>

namespace msm::evaluate {
namespace {

constexpr double kPi = std::numbers::pi;

// The families the 2015 paper names: powers, trigonometric (the 2015 Eq. (1) frequencies 2 pi and
// 4 pi, their m = 6 extension 6 pi and the half periods pi, 3 pi), exponentials of both signs at
// rates from the gentle to the ESM-like, logarithms and rational functions with poles at various
// distances from [0, 1], and four other elementary shapes (root, arctangent, sigmoid, bump).
const std::array<CandidateFunction, kFunctionCount> kFunctions{{
    {"z", "z", "power", [](double z) { return z; }},
    {"z2", "z^2", "power", [](double z) { return z * z; }},
    {"z3", "z^3", "power", [](double z) { return z * z * z; }},
    {"z4", "z^4", "power", [](double z) { return (z * z) * (z * z); }},
    {"z5", "z^5", "power", [](double z) { return (z * z) * (z * z) * z; }},
    {"z6", "z^6", "power", [](double z) { return (z * z * z) * (z * z * z); }},
    {"sin1pi", "sin(pi z)", "trigonometric", [](double z) { return std::sin(kPi * z); }},
    {"cos1pi", "cos(pi z)", "trigonometric", [](double z) { return std::cos(kPi * z); }},
    {"sin2pi", "sin(2 pi z)", "trigonometric", [](double z) { return std::sin(2 * kPi * z); }},
    {"cos2pi", "cos(2 pi z)", "trigonometric", [](double z) { return std::cos(2 * kPi * z); }},
    {"sin3pi", "sin(3 pi z)", "trigonometric", [](double z) { return std::sin(3 * kPi * z); }},
    {"cos3pi", "cos(3 pi z)", "trigonometric", [](double z) { return std::cos(3 * kPi * z); }},
    {"sin4pi", "sin(4 pi z)", "trigonometric", [](double z) { return std::sin(4 * kPi * z); }},
    {"cos4pi", "cos(4 pi z)", "trigonometric", [](double z) { return std::cos(4 * kPi * z); }},
    {"sin6pi", "sin(6 pi z)", "trigonometric", [](double z) { return std::sin(6 * kPi * z); }},
    {"cos6pi", "cos(6 pi z)", "trigonometric", [](double z) { return std::cos(6 * kPi * z); }},
    {"exp2", "exp(2 z)", "exponential", [](double z) { return std::exp(2 * z); }},
    {"expm2", "exp(-2 z)", "exponential", [](double z) { return std::exp(-2 * z); }},
    {"exp5", "exp(5 z)", "exponential", [](double z) { return std::exp(5 * z); }},
    {"expm5", "exp(-5 z)", "exponential", [](double z) { return std::exp(-5 * z); }},
    {"exp10", "exp(10 z)", "exponential", [](double z) { return std::exp(10 * z); }},
    {"expm10", "exp(-10 z)", "exponential", [](double z) { return std::exp(-10 * z); }},
    {"exp20", "exp(20 z)", "exponential", [](double z) { return std::exp(20 * z); }},
    {"expm20", "exp(-20 z)", "exponential", [](double z) { return std::exp(-20 * z); }},
    {"log1", "log(1 + z)", "logarithmic", [](double z) { return std::log1p(z); }},
    {"log4", "log(1 + 4 z)", "logarithmic", [](double z) { return std::log1p(4 * z); }},
    {"log16", "log(1 + 16 z)", "logarithmic", [](double z) { return std::log1p(16 * z); }},
    {"log64", "log(1 + 64 z)", "logarithmic", [](double z) { return std::log1p(64 * z); }},
    {"rat1", "1 / (1 + z)", "rational", [](double z) { return 1 / (1 + z); }},
    {"rat1sq", "1 / (1 + z)^2", "rational", [](double z) { return 1 / ((1 + z) * (1 + z)); }},
    {"rat4", "1 / (1 + 4 z)", "rational", [](double z) { return 1 / (1 + 4 * z); }},
    {"rat16", "1 / (1 + 16 z)", "rational", [](double z) { return 1 / (1 + 16 * z); }},
    {"rat2m", "1 / (2 - z)", "rational", [](double z) { return 1 / (2 - z); }},
    {"sqrt1", "sqrt(1 + z)", "other", [](double z) { return std::sqrt(1 + z); }},
    {"atan4", "atan(4 z)", "other", [](double z) { return std::atan(4 * z); }},
    {"tanh8", "tanh(8 z - 4)", "other", [](double z) { return std::tanh(8 * z - 4); }},
    {"bump", "exp(-8 (z - 1/2)^2)", "other", [](double z) { return std::exp(-8 * (z - 0.5) * (z - 0.5)); }},
}};

} // namespace

std::span<const CandidateFunction> candidate_functions() { return kFunctions; }

std::optional<int> find_function(std::string_view name) {
  for (int i = 0; i < kFunctionCount; ++i)
    if (kFunctions[i].name == name) return i;
  return std::nullopt;
}

} // namespace msm::evaluate
