// Progress as lines, for a log rather than a terminal (stderr redirected, CI): a line at every
// tenth of the work, but only once the work has run `quiet_seconds` (a short run prints nothing),
// and the last line at the end when any was printed. Pure: the caller prints what next() returns.
// Progress as a bar, for a terminal: progress_bar, rewritten in place.
#pragma once

#include <fmt/format.h>

#include <cmath>
#include <cstddef>
#include <optional>
#include <string>
#include <string_view>
#include <utility>

namespace msm::util {

class ProgressLines {
 public:
  // A line: "<prefix> 40% (216 of 540<unit>), 4.1 s, 6.2 s left".
  explicit ProgressLines(std::string prefix, std::string unit = "", double quiet_seconds = 2.0, int steps = 10)
      : prefix_(std::move(prefix)), unit_(std::move(unit)), quiet_seconds_(quiet_seconds), steps_(steps) {}

  // The line to print for `done` of `total` after `seconds`, if one is due.
  std::optional<std::string> next(std::size_t done, std::size_t total, double seconds) {
    if (total == 0) return std::nullopt;
    const int step = int(double(done) / double(total) * steps_); // tenths completed
    const bool finished = done >= total;
    if (finished ? !printed_ : (step <= last_step_ || seconds < quiet_seconds_)) return std::nullopt;
    if (finished && printed_ && last_step_ >= steps_) return std::nullopt;
    last_step_ = step;
    printed_ = true;
    const double fraction = double(done) / double(total);
    const double left = fraction > 0.0 ? seconds * (1.0 - fraction) / fraction : 0.0;
    return fmt::format("{}{:3.0f}% ({} of {}{}), {:.1f} s, {:.1f} s left", prefix_, 100.0 * fraction, done, total,
                       unit_, seconds, left);
  }

 private:
  std::string prefix_, unit_;
  double quiet_seconds_;
  int steps_;
  int last_step_ = 0;
  bool printed_ = false;
};

// A bar for a terminal, to print after a carriage return:
// "<label> [############                  ]  40%  <detail>4.1 s, 6.2 s left " (no work: full).
inline std::string progress_bar(std::string_view label, std::size_t done, std::size_t total, double seconds, int width,
                                std::string_view detail = "") {
  const double fraction = total ? double(done) / double(total) : 1.0;
  const int filled = int(std::lround(fraction * width));
  const double left = fraction > 0.0 ? seconds * (1.0 - fraction) / fraction : 0.0;
  return fmt::format("{} [{}{}] {:3.0f}%  {}{:.1f} s, {:.1f} s left ", label, std::string(filled, '#'),
                     std::string(width - filled, ' '), 100.0 * fraction, detail, seconds, left);
}

} // namespace msm::util
