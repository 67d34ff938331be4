// The image-test helper of the tests (in the manner of Filament's and Mitsuba's image tests):
// compare an image against a reference with tolerances; on failure dump the images. Test support
// (msm_image_testing), not installed.
//
//   auto r = msm::image::compare(actual, reference, {.max_mae = 0.005, .max_share_above_3pct = 0.01},
//                                {.failure_dir = "build/test-failures/" + test_name});
//   EXPECT_TRUE(r.passed) << r.report;
#pragma once

#include "msm/image/metrics.h"

#include <filesystem>
#include <limits>
#include <string>

namespace msm::image {

// Each metric must be <= its tolerance (inclusive). Defaults: strict on MAE and share > 3%,
// no NaN/inf allowed, everything else unbounded.
struct Tolerances {
  static constexpr double none = std::numeric_limits<double>::infinity();
  double max_mae = 0.01;
  double max_rmse = none;
  double max_error = none;
  double max_share_above_1pct = none;
  double max_share_above_3pct = 0.01;
  double max_share_above_10pct = none;
  double max_light_leaking = none;
  double max_over_darkening = none;
  std::size_t max_non_finite = 0;
};

struct CompareOptions {
  MetricOptions metrics{};             // signal, channel, mask
  std::filesystem::path failure_dir{}; // where to dump on failure (created); empty: no dump
  double error_range = 0.1;            // scale of the false-colour error image
};

struct CompareResult {
  bool passed = false;
  Metrics metrics;    // zero if the images could not be compared (size mismatch, bad channel)
  std::string report; // one line "PASS ..." / "FAIL ..." then the metrics and any violations,
                      // and on failure the files written (or why they could not be)
  explicit operator bool() const noexcept { return passed; }
};

// Never throws for bad images: a size mismatch or an unknown channel is a failed comparison.
// On failure with failure_dir set, writes there (atomically, replacing older dumps):
// actual.exr, reference.exr (the full images, exact float), actual.png, reference.png (the
// compared signal as grey sRGB, clamped to [0,1]; left out if the channel is unknown) and
// error.png (error_image with error_range; only when the sizes match).
CompareResult compare(const Image& actual, const Image& reference, const Tolerances& tolerances = {},
                      const CompareOptions& options = {});

} // namespace msm::image
