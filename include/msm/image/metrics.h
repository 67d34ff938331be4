// Error metrics of a test image against a reference.
//
// Both images must have the same width and height (else ImageError). Each is reduced to one
// scalar signal s per pixel (see select_signal): the named channel if one is given, else the only
// channel, else the first channel of a "Y","A" image, else the Rec. 709 luminance of R,G,B
// (alpha ignored). With d = s_test - s_reference per counted pixel and N counted pixels:
//
//   mae                = sum |d| / N
//   rmse               = sqrt(sum d^2 / N)
//   max_error          = max |d|                  (at max_error_x, max_error_y; -1 if N = 0)
//   share_above_1pct   = #{ |d| > 0.01 } / N        (absolute difference in [0,1] units,
//   share_above_3pct   = #{ |d| > 0.03 } / N         strictly greater; a fraction in [0,1],
//   share_above_10pct  = #{ |d| > 0.10 } / N         not a percentage)
//   light_leaking      = sum max(0, b) / N          where b is the BRIGHTNESS difference:
//   over_darkening     = sum max(0, -b) / N           b = d for Signal::visibility (visibility,
//                                                     intensity, luminance: larger = more light),
//                                                     b = -d for Signal::shadow_intensity
//                                                     (1 - visibility: larger = darker).
//   So light leaking = the test is brighter / less shadowed than the reference, over-darkening =
//   darker / more shadowed; light_leaking + over_darkening = mae.
//   mean_error         = sum b / N  (signed, brightness terms: > 0 leaks on average)
//
// Counted pixels: not masked, and both values finite. A mask (same size, its first channel) marks
// pixels to IGNORE where its value is > 0.5 (e.g. background). Pixels with a NaN or infinite
// value in either image are counted in non_finite and left out of everything else; of those,
// non_finite_in_test counts the ones where only the test is non-finite (the reference is finite):
// values the test failed to produce, which no statistic over the counted pixels shows (an all-NaN
// test has N = 0). With N = 0 every statistic is 0.
#pragma once

#include "msm/image/image.h"

#include <cstddef>
#include <string>

namespace msm::image {

enum class Signal {
  visibility,       // larger = brighter (visibility, light intensity, luminance)
  shadow_intensity, // larger = darker (shadow intensity = 1 - visibility)
};

struct MetricOptions {
  Signal signal = Signal::visibility;
  std::string channel{};       // channel to compare (empty: see select_signal)
  const Image* mask = nullptr; // pixels to ignore where > 0.5
};

struct Metrics {
  int width = 0, height = 0;
  std::size_t pixels = 0;             // counted pixels N
  std::size_t masked = 0;             // ignored by the mask
  std::size_t non_finite = 0;         // NaN/inf in test or reference (not masked)
  std::size_t non_finite_in_test = 0; // of non_finite: NaN/inf in the test, the reference finite
  double mae = 0, rmse = 0, max_error = 0;
  int max_error_x = -1, max_error_y = -1;
  double share_above_1pct = 0, share_above_3pct = 0, share_above_10pct = 0;
  double light_leaking = 0, over_darkening = 0, mean_error = 0;
};

// The scalar signal compared (1 channel, named "Y"); channel empty = automatic (see above).
// Throws ImageError (naming the available channels) for an unknown channel name.
Image select_signal(const Image& image, const std::string& channel = {});

Metrics compute_metrics(const Image& test, const Image& reference, const MetricOptions& options = {});

// The metrics as a table (one "name value" line each) or as a JSON object (keys as in Metrics).
std::string format_metrics(const Metrics& metrics);
std::string metrics_json(const Metrics& metrics, int indent = 2);

// False-colour error image (RGB): b / range clamped to [-1, 1] (b the brightness difference
// above) on a diverging map: white = equal, red = test brighter (light leaking), blue = test
// darker (over-darkening), saturated at |b| >= range. The map is linear in display (sRGB) values:
// t > 0: (1, 1 - t, 1 - t), t < 0: (1 - |t|, 1 - |t|, 1). Masked pixels are mid grey (0.5),
// non-finite ones green (0, 1, 0). Values are stored linear so that write_png yields exactly
// these display colours. range must be > 0 (else ImageError).
Image error_image(const Image& test, const Image& reference, double range = 0.1, const MetricOptions& options = {});
void write_error_png(const std::filesystem::path& path, const Image& test, const Image& reference, double range = 0.1,
                     const MetricOptions& options = {});

} // namespace msm::image
