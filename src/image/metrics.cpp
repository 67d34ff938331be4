#include "msm/image/metrics.h"
#include "msm/image/io.h"

#include <algorithm>
#include <cmath>

#include <fmt/core.h>
#include <nlohmann/json.hpp>

namespace msm::image {

Image select_signal(const Image& image, const std::string& channel) {
  if (image.empty()) throw ImageError({}, "empty image");
  if (!channel.empty()) return image.channel(std::string_view(channel));
  const auto& names = image.channel_names();
  if (image.channels() == 1) return image.channel(0);
  if (image.channels() == 2 && names[1] == "A") return image.channel(0);
  const int r = image.find_channel("R"), g = image.find_channel("G"), b = image.find_channel("B");
  if (r < 0 || g < 0 || b < 0) {
    std::string have;
    for (const std::string& n : names) have += (have.empty() ? "" : ", ") + n;
    throw ImageError({}, fmt::format("several channels ({}) and no R,G,B: choose one", have));
  }
  Image out(image.width(), image.height(), 1);
  const std::size_t n = std::size_t(image.channels());
  auto in = image.pixels();
  auto px = out.pixels();
  for (std::size_t i = 0; i < px.size(); ++i)
    px[i] = luminance(in[i * n + std::size_t(r)], in[i * n + std::size_t(g)], in[i * n + std::size_t(b)]);
  return out;
}

namespace {

void check_same_size(const Image& a, const Image& b, const char* what) {
  if (a.width() != b.width() || a.height() != b.height())
    throw ImageError({}, fmt::format("size mismatch: {} is {}x{}, reference is {}x{}", what, a.width(), a.height(),
                                     b.width(), b.height()));
}

// What a pixel is to the metrics.
enum class Pixel { counted, masked, non_finite, non_finite_in_test };

// Visits every pixel: f(index, kind, brightness difference b; NaN unless counted).
template <class F>
void for_each_difference(const Image& test, const Image& reference, const MetricOptions& options, F&& f) {
  check_same_size(test, reference, "test");
  if (options.mask) check_same_size(*options.mask, reference, "mask");
  const Image t = select_signal(test, options.channel);
  const Image r = select_signal(reference, options.channel);
  const std::size_t mask_stride = options.mask ? std::size_t(options.mask->channels()) : 0;
  const double sign = options.signal == Signal::visibility ? 1.0 : -1.0;
  auto tp = t.pixels();
  auto rp = r.pixels();
  for (std::size_t i = 0; i < tp.size(); ++i) {
    const bool masked = options.mask && options.mask->pixels()[i * mask_stride] > 0.5f;
    const bool test_finite = std::isfinite(tp[i]), reference_finite = std::isfinite(rp[i]);
    if (masked)
      f(i, Pixel::masked, std::nan(""));
    else if (test_finite && reference_finite)
      f(i, Pixel::counted, sign * (double(tp[i]) - double(rp[i])));
    else
      f(i, reference_finite ? Pixel::non_finite_in_test : Pixel::non_finite, std::nan(""));
  }
}

} // namespace

Metrics compute_metrics(const Image& test, const Image& reference, const MetricOptions& options) {
  Metrics m;
  m.width = reference.width();
  m.height = reference.height();
  double sum_abs = 0, sum_sq = 0, sum_leak = 0, sum_dark = 0, sum_signed = 0;
  std::size_t above1 = 0, above3 = 0, above10 = 0;
  const std::size_t width = std::size_t(reference.width());
  for_each_difference(test, reference, options, [&](std::size_t i, Pixel kind, double b) {
    if (kind == Pixel::masked) {
      ++m.masked;
      return;
    }
    if (kind != Pixel::counted) {
      ++m.non_finite;
      m.non_finite_in_test += kind == Pixel::non_finite_in_test;
      return;
    }
    const double a = std::abs(b);
    ++m.pixels;
    sum_abs += a;
    sum_sq += a * a;
    sum_signed += b;
    if (b > 0)
      sum_leak += b;
    else
      sum_dark -= b;
    if (a > m.max_error || m.max_error_x < 0) {
      m.max_error = a;
      m.max_error_x = int(i % width);
      m.max_error_y = int(i / width);
    }
    above1 += a > 0.01;
    above3 += a > 0.03;
    above10 += a > 0.10;
  });
  if (m.pixels == 0) return m;
  const double n = double(m.pixels);
  m.mae = sum_abs / n;
  m.rmse = std::sqrt(sum_sq / n);
  m.share_above_1pct = double(above1) / n;
  m.share_above_3pct = double(above3) / n;
  m.share_above_10pct = double(above10) / n;
  m.light_leaking = sum_leak / n;
  m.over_darkening = sum_dark / n;
  m.mean_error = sum_signed / n;
  return m;
}

std::string format_metrics(const Metrics& m) {
  std::string s;
  s += fmt::format("{:<20} {}x{}\n", "size", m.width, m.height);
  s += fmt::format("{:<20} {}\n", "pixels", m.pixels);
  s += fmt::format("{:<20} {}\n", "masked", m.masked);
  s += fmt::format("{:<20} {}\n", "non_finite", m.non_finite);
  s += fmt::format("{:<20} {}\n", "non_finite_in_test", m.non_finite_in_test);
  s += fmt::format("{:<20} {:.6g}\n", "mae", m.mae);
  s += fmt::format("{:<20} {:.6g}\n", "rmse", m.rmse);
  s += fmt::format("{:<20} {:.6g} at ({}, {})\n", "max_error", m.max_error, m.max_error_x, m.max_error_y);
  s += fmt::format("{:<20} {:.4f}%\n", "share > 1%", 100 * m.share_above_1pct);
  s += fmt::format("{:<20} {:.4f}%\n", "share > 3%", 100 * m.share_above_3pct);
  s += fmt::format("{:<20} {:.4f}%\n", "share > 10%", 100 * m.share_above_10pct);
  s += fmt::format("{:<20} {:.6g}\n", "light_leaking", m.light_leaking);
  s += fmt::format("{:<20} {:.6g}\n", "over_darkening", m.over_darkening);
  s += fmt::format("{:<20} {:.6g}\n", "mean_error", m.mean_error);
  return s;
}

std::string metrics_json(const Metrics& m, int indent) {
  nlohmann::ordered_json j;
  j["width"] = m.width;
  j["height"] = m.height;
  j["pixels"] = m.pixels;
  j["masked"] = m.masked;
  j["non_finite"] = m.non_finite;
  j["non_finite_in_test"] = m.non_finite_in_test;
  j["mae"] = m.mae;
  j["rmse"] = m.rmse;
  j["max_error"] = m.max_error;
  j["max_error_x"] = m.max_error_x;
  j["max_error_y"] = m.max_error_y;
  j["share_above_1pct"] = m.share_above_1pct;
  j["share_above_3pct"] = m.share_above_3pct;
  j["share_above_10pct"] = m.share_above_10pct;
  j["light_leaking"] = m.light_leaking;
  j["over_darkening"] = m.over_darkening;
  j["mean_error"] = m.mean_error;
  return j.dump(indent);
}

Image error_image(const Image& test, const Image& reference, double range, const MetricOptions& options) {
  if (!(range > 0) || !std::isfinite(range)) throw ImageError({}, fmt::format("error range {} is not > 0", range));
  Image out(reference.width(), reference.height(), 3);
  auto px = out.pixels();
  auto set = [&](std::size_t i, float r, float g, float b) {
    px[3 * i] = srgb_to_linear(r);
    px[3 * i + 1] = srgb_to_linear(g);
    px[3 * i + 2] = srgb_to_linear(b);
  };
  for_each_difference(test, reference, options, [&](std::size_t i, Pixel kind, double b) {
    if (kind == Pixel::masked) return set(i, 0.5f, 0.5f, 0.5f);
    if (kind != Pixel::counted) return set(i, 0.0f, 1.0f, 0.0f);
    const float t = float(std::clamp(b / range, -1.0, 1.0));
    if (t >= 0)
      set(i, 1.0f, 1.0f - t, 1.0f - t);
    else
      set(i, 1.0f + t, 1.0f + t, 1.0f);
  });
  return out;
}

void write_error_png(const std::filesystem::path& path, const Image& test, const Image& reference, double range,
                     const MetricOptions& options) {
  write_png(path, error_image(test, reference, range, options));
}

} // namespace msm::image
