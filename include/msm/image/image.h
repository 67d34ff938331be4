// msm::image: float images for the ground truth and the renderer's image tests.
//
// An Image holds width x height pixels of 1..4 float channels, interleaved and row-major:
// the value of channel c of pixel (x, y) is pixels()[(y * width + x) * channels + c], with
// (0, 0) the top-left pixel (the first row of a PNG, the data window's min corner of an EXR).
// Every channel has a name: by default "Y" (1 channel), "Y","A" (2), "R","G","B" (3) and
// "R","G","B","A" (4); any other distinct non-empty names may be given (e.g. "visibility",
// "sample_count", "std_error"), and EXR files keep them.
#pragma once

#include <array>
#include <cstdint>
#include <filesystem>
#include <span>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

namespace msm::image {

// Every failure of this library to read, write or build an image: the path (empty where none is
// involved) and the reason. what() is "<path>: <reason>".
class ImageError : public std::runtime_error {
 public:
  ImageError(std::filesystem::path path, std::string reason);
  const std::filesystem::path& path() const noexcept { return path_; }
  const std::string& reason() const noexcept { return reason_; }

 private:
  std::filesystem::path path_;
  std::string reason_;
};

// Largest width or height accepted anywhere (construction, reading, writing).
inline constexpr int max_side = 65536;
inline constexpr int max_channels = 4;

// The default channel names for a channel count in 1..4 (see above).
std::vector<std::string> default_channel_names(int channels);

class Image {
 public:
  Image() = default; // empty: 0 x 0, no channels; only assignable, readable as empty()
  // Throws ImageError for a side outside 1..max_side or channels outside 1..max_channels.
  Image(int width, int height, int channels, float fill = 0.0f);
  // Channel count = names.size(); names must be distinct and non-empty.
  Image(int width, int height, std::vector<std::string> channel_names, float fill = 0.0f);

  int width() const noexcept { return width_; }
  int height() const noexcept { return height_; }
  int channels() const noexcept { return static_cast<int>(names_.size()); }
  bool empty() const noexcept { return pixels_.empty(); }
  std::size_t pixel_count() const noexcept { return std::size_t(width_) * std::size_t(height_); }

  const std::vector<std::string>& channel_names() const noexcept { return names_; }
  void set_channel_names(std::vector<std::string> names); // same count, distinct, non-empty
  // Index of the channel with that name, or -1.
  int find_channel(std::string_view name) const noexcept;

  // Bounds-checked access: throws std::out_of_range outside the image or the channels.
  float& at(int x, int y, int c = 0);
  float at(int x, int y, int c = 0) const;

  // The raw interleaved row-major values (size width * height * channels).
  std::span<float> pixels() noexcept { return pixels_; }
  std::span<const float> pixels() const noexcept { return pixels_; }

  // One channel as a 1-channel image named "Y" (by index, or by name: ImageError if unknown).
  Image channel(int c) const;
  Image channel(std::string_view name) const;

  bool operator==(const Image&) const = default; // exact: sizes, names and every value

 private:
  int width_ = 0, height_ = 0;
  std::vector<std::string> names_;
  std::vector<float> pixels_;
};

// ---- Colour conversions ----------------------------------------------------------------------

// The exact sRGB transfer functions (IEC 61966-2-1): encode is 12.92 x for x <= 0.0031308, else
// 1.055 x^(1/2.4) - 0.055; decode is its inverse (threshold 0.04045). Input is clamped to [0,1];
// NaN gives 0.
float linear_to_srgb(float linear);
float srgb_to_linear(float encoded);
// round(255 * linear_to_srgb(x)), without a pow per call: the smallest float of each of the 255
// steps is found once (by bisection on linear_to_srgb itself, which is monotone); a value's code
// is its bucket's first code or the next, one comparison with a step. Equal to the formula for
// every float (Colour.TablesEqualTheFormula).
std::uint8_t linear_to_srgb8(float linear);
// srgb_to_linear(code / 255) from a table of the 256 values (the decode of 8-bit images).
float srgb8_to_linear(std::uint8_t code);
// That table: srgb8_to_linear_table()[code] == srgb8_to_linear(code), for decoding many codes.
const std::array<float, 256>& srgb8_to_linear_table();

// Rec. 709 / sRGB relative luminance of linear RGB: 0.2126 R + 0.7152 G + 0.0722 B.
float luminance(float r, float g, float b);

enum class ToneCurve {
  clamp,    // x (clamped to [0,1] only when encoded)
  reinhard, // x / (1 + x)
  aces,     // Narkowicz 2015 fit of the ACES filmic curve:
            //   x (2.51 x + 0.03) / (x (2.43 x + 0.59) + 0.14), clamped to [0,1]
};

struct ToneMap {
  float exposure_stops = 0.0f; // colour channels are scaled by 2^exposure_stops first
  ToneCurve curve = ToneCurve::clamp;
};

// Applies exposure and the curve to every channel except one named "A" (alpha, kept as is).
// Result stays linear; write_png then encodes it to sRGB. Negative and NaN values become 0.
Image tone_map(const Image& image, const ToneMap& tone = {});

// 8-bit interleaved sRGB of the image (colour channels encoded with linear_to_srgb8; a channel
// named "A" is stored linearly: round(255 x)).
std::vector<std::uint8_t> to_srgb8(const Image& image);
// The same with channel `alpha` (-1: none) stored linearly, whatever its name.
std::vector<std::uint8_t> to_srgb8(const Image& image, int alpha);

} // namespace msm::image
