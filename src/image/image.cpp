#include "msm/image/image.h"

#include "msm/shading.h"

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <limits>
#include <set>

#include <fmt/core.h>

namespace msm::image {

namespace {
std::string describe(const std::filesystem::path& path, const std::string& reason) {
  return path.empty() ? reason : path.string() + ": " + reason;
}

void check_size(int width, int height) {
  if (width < 1 || height < 1 || width > max_side || height > max_side)
    throw ImageError({}, fmt::format("image size {}x{} is outside 1..{} per side", width, height, max_side));
}

void check_names(const std::vector<std::string>& names) {
  if (names.empty() || names.size() > std::size_t(max_channels))
    throw ImageError({}, fmt::format("{} channels: an image has 1..{}", names.size(), max_channels));
  std::set<std::string> seen;
  for (const std::string& n : names) {
    if (n.empty()) throw ImageError({}, "empty channel name");
    if (!seen.insert(n).second) throw ImageError({}, fmt::format("duplicate channel name '{}'", n));
  }
}
} // namespace

ImageError::ImageError(std::filesystem::path path, std::string reason)
    : std::runtime_error(describe(path, reason)), path_(std::move(path)), reason_(std::move(reason)) {}

std::vector<std::string> default_channel_names(int channels) {
  switch (channels) {
  case 1: return {"Y"};
  case 2: return {"Y", "A"};
  case 3: return {"R", "G", "B"};
  case 4: return {"R", "G", "B", "A"};
  default: throw ImageError({}, fmt::format("{} channels: an image has 1..{}", channels, max_channels));
  }
}

Image::Image(int width, int height, int channels, float fill)
    : Image(width, height, default_channel_names(channels), fill) {}

Image::Image(int width, int height, std::vector<std::string> channel_names, float fill) {
  check_size(width, height);
  check_names(channel_names);
  width_ = width;
  height_ = height;
  names_ = std::move(channel_names);
  pixels_.assign(pixel_count() * names_.size(), fill);
}

void Image::set_channel_names(std::vector<std::string> names) {
  check_names(names);
  if (names.size() != names_.size())
    throw ImageError({}, fmt::format("{} channel names for {} channels", names.size(), names_.size()));
  names_ = std::move(names);
}

int Image::find_channel(std::string_view name) const noexcept {
  for (std::size_t i = 0; i < names_.size(); ++i)
    if (names_[i] == name) return static_cast<int>(i);
  return -1;
}

float& Image::at(int x, int y, int c) {
  if (x < 0 || y < 0 || c < 0 || x >= width_ || y >= height_ || c >= channels())
    throw std::out_of_range(fmt::format("pixel ({}, {}) channel {} outside a {}x{} image of {} channels", x, y, c,
                                        width_, height_, channels()));
  return pixels_[(std::size_t(y) * std::size_t(width_) + std::size_t(x)) * names_.size() + std::size_t(c)];
}

float Image::at(int x, int y, int c) const { return const_cast<Image*>(this)->at(x, y, c); }

Image Image::channel(int c) const {
  if (c < 0 || c >= channels())
    throw std::out_of_range(fmt::format("channel {} of an image of {} channels", c, channels()));
  Image out(width_, height_, 1);
  const std::size_t n = names_.size();
  for (std::size_t i = 0; i < pixel_count(); ++i) out.pixels_[i] = pixels_[i * n + std::size_t(c)];
  return out;
}

Image Image::channel(std::string_view name) const {
  int c = find_channel(name);
  if (c < 0) {
    std::string have;
    for (const std::string& n : names_) have += (have.empty() ? "" : ", ") + n;
    throw ImageError({}, fmt::format("no channel '{}' (channels: {})", name, have));
  }
  return channel(c);
}

// ---- Colour ----------------------------------------------------------------------------------

float linear_to_srgb(float x) {
  if (!(x > 0.0f)) return 0.0f; // also NaN
  if (x >= 1.0f) return 1.0f;
  double v = x;
  return static_cast<float>(v <= 0.0031308 ? 12.92 * v : 1.055 * std::pow(v, 1.0 / 2.4) - 0.055);
}

float srgb_to_linear(float e) {
  if (!(e > 0.0f)) return 0.0f;
  if (e >= 1.0f) return 1.0f;
  double v = e;
  return static_cast<float>(v <= 0.04045 ? v / 12.92 : std::pow((v + 0.055) / 1.055, 2.4));
}

namespace {

std::uint8_t linear_to_srgb8_formula(float x) {
  return static_cast<std::uint8_t>(std::lround(255.0 * double(linear_to_srgb(x))));
}

// steps[k]: the smallest float x with linear_to_srgb8_formula(x) >= k (k = 1 .. 255), found by
// bisection over the ordered bit patterns of the floats in (0, 1]; steps[0] = -inf, steps[256] =
// +inf. first[b]: the code of b / kBuckets. The steepest part of the curve (12.92 x, 3295 codes per
// unit) stays below one step per bucket, so a value's code is first[b] or the next one.
constexpr int kBuckets = 4096;
struct Srgb8Steps {
  std::array<float, 257> steps{};
  std::array<std::uint8_t, kBuckets> first{};
  Srgb8Steps() {
    steps[0] = -std::numeric_limits<float>::infinity();
    steps[256] = std::numeric_limits<float>::infinity();
    for (int k = 1; k < 256; ++k) {
      auto lo = std::bit_cast<std::uint32_t>(0.0f), hi = std::bit_cast<std::uint32_t>(1.0f); // code(lo) < k <= code(hi)
      while (hi - lo > 1) {
        std::uint32_t mid = lo + (hi - lo) / 2;
        (linear_to_srgb8_formula(std::bit_cast<float>(mid)) >= k ? hi : lo) = mid;
      }
      steps[size_t(k)] = std::bit_cast<float>(hi);
    }
    for (int b = 0; b < kBuckets; ++b) first[size_t(b)] = linear_to_srgb8_formula(float(b) / float(kBuckets));
  }
};
const Srgb8Steps& srgb8_steps() {
  static const Srgb8Steps table;
  return table;
}

} // namespace

std::uint8_t linear_to_srgb8(float x) {
  const Srgb8Steps& t = srgb8_steps();
  if (!(x > 0.0f)) return 0; // also NaN
  if (x >= 1.0f) return 255;
  unsigned k = t.first[size_t(x * float(kBuckets))]; // x * 4096 is exact: the bucket of x
  return static_cast<std::uint8_t>(k + (t.steps[k + 1] <= x ? 1 : 0));
}

const std::array<float, 256>& srgb8_to_linear_table() {
  static const std::array<float, 256> table = [] {
    std::array<float, 256> t{};
    for (int i = 0; i < 256; ++i) t[size_t(i)] = srgb_to_linear(float(i) / 255.0f);
    return t;
  }();
  return table;
}

float srgb8_to_linear(std::uint8_t code) { return srgb8_to_linear_table()[code]; }

float luminance(float r, float g, float b) { return msm::msm_luminance(glm::vec3(r, g, b)); }

Image tone_map(const Image& image, const ToneMap& tone) {
  Image out = image;
  const int alpha = image.find_channel("A");
  const float scale = std::exp2(tone.exposure_stops);
  const int n = image.channels();
  auto px = out.pixels();
  for (std::size_t i = 0; i < px.size(); ++i) {
    if (int(i % std::size_t(n)) == alpha) continue;
    float x = px[i] * scale;
    if (!(x > 0.0f)) {
      px[i] = 0.0f;
      continue;
    } // negative, NaN
    switch (tone.curve) {
    case ToneCurve::clamp: break;
    case ToneCurve::reinhard: x = std::isinf(x) ? 1.0f : x / (1.0f + x); break;
    case ToneCurve::aces: x = std::isinf(x) ? 1.0f : msm_aces(x); break;
    }
    px[i] = x;
  }
  return out;
}

std::vector<std::uint8_t> to_srgb8(const Image& image) { return to_srgb8(image, image.find_channel("A")); }

std::vector<std::uint8_t> to_srgb8(const Image& image, int alpha) {
  const int n = image.channels();
  auto px = image.pixels();
  std::vector<std::uint8_t> out(px.size());
  for (std::size_t i = 0; i < px.size(); ++i) {
    if (int(i % std::size_t(n)) == alpha) {
      float a = px[i];
      out[i] = static_cast<std::uint8_t>(std::lround(255.0 * (a > 0.0f ? (a < 1.0f ? a : 1.0f) : 0.0f)));
    } else {
      out[i] = linear_to_srgb8(px[i]);
    }
  }
  return out;
}

} // namespace msm::image
