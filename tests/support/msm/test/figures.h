// The figures a test asserts, written where `msm report` gathers them (test support, not installed).
//
//   EXPECT_LT(err.max(), 1e-5);
//   msm::test::record_figure("hamburger4.unit.lower_range_distance_max", err.max(),
//                            {.below = 1e-5, .meaning = "lower bound's distance to Alg. 1's range, max"});
//
// A test records the value its assertion checks (the same variable) and the assertion's bound, beside
// the assertion. Recording is off unless the environment variable MSM_TEST_FIGURES names a file: then
// each figure is appended to it as one line of JSON (JSON Lines; one append per line, so that the
// processes of a parallel run do not interleave within a line):
//   {"key", "value", "unit", "relation" ("<" or ">"), "bound", "holds", "meaning", "test"}
// "holds" is whether value relation bound; a NaN or infinite value is written as null and never holds.
#pragma once

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <optional>
#include <string>
#include <string_view>

namespace msm::test {

constexpr const char* kFiguresVariable = "MSM_TEST_FIGURES";

// What the assertion beside the record checks: value < below, or value > above (one of the two).
struct FigureBound {
  // (Every member has its initializer, so that a designated initializer may leave any out.)
  std::optional<double> below = {};
  std::optional<double> above = {};
  std::string_view unit = {};    // "" for a plain number (errors of visibility, probabilities)
  std::string_view meaning = {}; // what the figure is, in a few words
};

namespace figures_detail {

inline std::string json_string(std::string_view s) {
  std::string out = "\"";
  for (const char c : s) {
    if (c == '"' || c == '\\') {
      out += '\\';
      out += c;
    } else if (static_cast<unsigned char>(c) < 0x20) {
      char escaped[8];
      std::snprintf(escaped, sizeof escaped, "\\u%04x", c);
      out += escaped;
    } else {
      out += c;
    }
  }
  return out + "\"";
}

inline std::string json_number(double v) {
  if (!std::isfinite(v)) return "null";
  char text[32];
  std::snprintf(text, sizeof text, "%.17g", v);
  return text;
}

} // namespace figures_detail

// Appends the figure to the file MSM_TEST_FIGURES names; nothing when it is unset or empty. A
// record without a bound, or with both, is a mistake of the test: it fails.
inline void record_figure(std::string_view key, double value, const FigureBound& bound) {
  using namespace figures_detail;
  if (bound.below.has_value() == bound.above.has_value()) {
    ADD_FAILURE() << "record_figure(" << key << "): give exactly one of .below and .above";
    return;
  }
  const char* path = std::getenv(kFiguresVariable);
  if (!path || !*path) return;
  const bool below = bound.below.has_value();
  const double limit = below ? *bound.below : *bound.above;
  const bool holds = std::isfinite(value) && (below ? value < limit : value > limit);
  const ::testing::TestInfo* info = ::testing::UnitTest::GetInstance()->current_test_info();
  const std::string test = info ? std::string(info->test_suite_name()) + "." + info->name() : "";
  const std::string line = "{\"key\": " + json_string(key) + ", \"value\": " + json_number(value) +
                           ", \"unit\": " + json_string(bound.unit) + ", \"relation\": \"" + (below ? "<" : ">") +
                           "\", \"bound\": " + json_number(limit) + ", \"holds\": " + (holds ? "true" : "false") +
                           ", \"meaning\": " + json_string(bound.meaning) + ", \"test\": " + json_string(test) + "}\n";
  FILE* file = std::fopen(path, "a");
  if (!file) {
    ADD_FAILURE() << kFiguresVariable << "=" << path << ": cannot open the file to append figure " << key;
    return;
  }
  std::fwrite(line.data(), 1, line.size(), file);
  if (std::fclose(file) != 0) ADD_FAILURE() << kFiguresVariable << "=" << path << ": cannot write figure " << key;
}

} // namespace msm::test
