// Tests of msm::image: PNG/EXR round trips, atomic writes, read errors, metrics with known
// answers, the false-colour error image and the failure-dump helper.
#include "msm/image/io.h"
#include "msm/image/metrics.h"
#include "msm/test/image_compare.h"

#include <gtest/gtest.h>

#include <OpenEXR/ImfChannelList.h>
#include <OpenEXR/ImfFrameBuffer.h>
#include <OpenEXR/ImfHeader.h>
#include <OpenEXR/ImfInputFile.h>
#include <OpenEXR/ImfTiledOutputFile.h>

#include <bit>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <iterator>
#include <limits>

#include <unistd.h>

namespace fs = std::filesystem;
using namespace msm::image;

namespace {

// A fresh directory per test under the system temp dir (removed afterwards).
class ImageTest : public ::testing::Test {
 protected:
  void SetUp() override {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    dir = fs::temp_directory_path() / ("msm_image_test_" + std::to_string(::getpid()) + "_" + info->name());
    fs::remove_all(dir);
    fs::create_directories(dir);
  }
  void TearDown() override { fs::remove_all(dir); }

  // Files in dir other than the listed ones (temporary leftovers).
  std::vector<std::string> entries() const {
    std::vector<std::string> out;
    for (const auto& e : fs::directory_iterator(dir)) out.push_back(e.path().filename().string());
    std::sort(out.begin(), out.end());
    return out;
  }
  static std::string slurp(const fs::path& p) {
    std::ifstream in(p, std::ios::binary);
    return {std::istreambuf_iterator<char>(in), {}};
  }
  static void spit(const fs::path& p, const std::string& bytes) {
    std::ofstream out(p, std::ios::binary);
    out << bytes;
  }
  fs::path dir;
};

Image ramp(int w, int h, std::vector<std::string> names) {
  Image im(w, h, std::move(names));
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x)
      for (int c = 0; c < im.channels(); ++c)
        im.at(x, y, c) = std::fmod(0.37f * float(x) + 0.11f * float(y) + 0.23f * float(c), 1.0f);
  return im;
}

Image step(int w, int h, int edge) { // 0 left of the edge, 1 from it on
  Image im(w, h, 1);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) im.at(x, y) = x >= edge ? 1.0f : 0.0f;
  return im;
}

} // namespace

// ---- Image and colour ------------------------------------------------------------------------

TEST(Image, LayoutNamesAndBoundsChecks) {
  Image im(3, 2, 4, 0.5f);
  EXPECT_EQ(im.channel_names(), (std::vector<std::string>{"R", "G", "B", "A"}));
  EXPECT_EQ(Image(1, 1, 1).channel_names(), std::vector<std::string>{"Y"});
  im.at(2, 1, 3) = 7.0f;
  EXPECT_EQ(im.pixels()[(1 * 3 + 2) * 4 + 3], 7.0f);
  EXPECT_THROW(im.at(3, 0), std::out_of_range);
  EXPECT_THROW(im.at(0, 2), std::out_of_range);
  EXPECT_THROW(im.at(-1, 0), std::out_of_range);
  EXPECT_THROW(im.at(0, 0, 4), std::out_of_range);
  EXPECT_EQ(im.channel("A").at(2, 1), 7.0f);
  EXPECT_THROW(im.channel("visibility"), ImageError);
  EXPECT_THROW(Image(0, 4, 1), ImageError);
  EXPECT_THROW(Image(4, max_side + 1, 1), ImageError);
  EXPECT_THROW(Image(4, 4, 5), ImageError);
  EXPECT_THROW(Image(4, 4, 0), ImageError);
  EXPECT_THROW(Image(4, 4, std::vector<std::string>{"a", "a"}), ImageError);
  EXPECT_THROW(Image(4, 4, std::vector<std::string>{""}), ImageError);
}

TEST(Colour, ExactSrgbTransfer) {
  EXPECT_EQ(linear_to_srgb(0.0f), 0.0f);
  EXPECT_EQ(linear_to_srgb(1.0f), 1.0f);
  EXPECT_FLOAT_EQ(linear_to_srgb(0.002f), 12.92f * 0.002f); // linear segment
  EXPECT_NEAR(linear_to_srgb(0.5f), 0.735356983, 1e-6);     // 1.055 * 0.5^(1/2.4) - 0.055
  EXPECT_NEAR(linear_to_srgb(0.214041144f), 0.5, 1e-6);
  EXPECT_EQ(linear_to_srgb8(0.5f), 188);
  EXPECT_EQ(linear_to_srgb8(-1.0f), 0);
  EXPECT_EQ(linear_to_srgb8(std::nanf("")), 0);
  EXPECT_EQ(linear_to_srgb8(5.0f), 255);
  for (int i = 0; i <= 255; ++i) // decode then encode is the identity on 8-bit codes
    EXPECT_EQ(linear_to_srgb8(srgb_to_linear(float(i) / 255.0f)), i) << i;
}

// The table-driven paths give the formula's result: round(255 linear_to_srgb(x)) for floats on
// both sides of every step (where an off-by-one would show) and spread over [0, 1], and the
// formula's decode of every 8-bit code.
TEST(Colour, TablesEqualTheFormula) {
  auto formula = [](float x) { return int(std::lround(255.0 * double(linear_to_srgb(x)))); };
  int checked = 0;
  for (int code = 1; code <= 255; ++code) {
    // The step between code - 1 and code, from the formula's inverse, then 200 floats either side.
    float edge = srgb_to_linear((float(code) - 0.5f) / 255.0f);
    float x = edge;
    for (int i = 0; i < 200; ++i) x = std::nextafter(x, 0.0f);
    for (int i = 0; i < 400; ++i, x = std::nextafter(x, 2.0f), ++checked)
      ASSERT_EQ(int(linear_to_srgb8(x)), formula(x)) << x;
  }
  for (std::uint32_t bits = 0; bits <= std::bit_cast<std::uint32_t>(1.0f); bits += 997, ++checked) {
    float x = std::bit_cast<float>(bits);
    ASSERT_EQ(int(linear_to_srgb8(x)), formula(x)) << x;
  }
  EXPECT_GT(checked, 1000000);
  EXPECT_EQ(linear_to_srgb8(std::numeric_limits<float>::infinity()), 255);
  EXPECT_EQ(linear_to_srgb8(-std::numeric_limits<float>::infinity()), 0);
  for (int i = 0; i <= 255; ++i) EXPECT_EQ(srgb8_to_linear(std::uint8_t(i)), srgb_to_linear(float(i) / 255.0f)) << i;
}

TEST(Colour, ToneMapping) {
  Image im(3, 1, 4, 1.0f);
  im.at(0, 0, 0) = 1.0f;
  im.at(1, 0, 0) = 3.0f;
  im.at(2, 0, 0) = -2.0f;
  im.at(0, 0, 3) = 0.25f;
  Image r = tone_map(im, {.exposure_stops = 1.0f, .curve = ToneCurve::reinhard});
  EXPECT_FLOAT_EQ(r.at(0, 0, 0), 2.0f / 3.0f);
  EXPECT_FLOAT_EQ(r.at(1, 0, 0), 6.0f / 7.0f);
  EXPECT_EQ(r.at(2, 0, 0), 0.0f);
  EXPECT_EQ(r.at(0, 0, 3), 0.25f); // alpha untouched
  Image a = tone_map(im, {.curve = ToneCurve::aces});
  EXPECT_NEAR(a.at(0, 0, 0), 2.54f / 3.16f, 1e-6);
  EXPECT_GT(a.at(1, 0, 0), a.at(0, 0, 0));
  EXPECT_LE(a.at(1, 0, 0), 1.0f);
}

// ---- I/O -------------------------------------------------------------------------------------

TEST_F(ImageTest, ExrRoundTripIsExact) {
  for (int n = 1; n <= 4; ++n) {
    Image im = ramp(37, 11, default_channel_names(n));
    im.at(0, 0, 0) = -3.5f; // out of [0,1] and special values survive
    im.at(1, 0, 0) = 1e30f;
    im.at(2, 0, 0) = std::nanf("");
    im.at(3, 0, 0) = 1e-40f; // denormal
    const fs::path p = dir / ("im" + std::to_string(n) + ".exr");
    write_exr(p, im);
    Image back = read_exr(p);
    ASSERT_EQ(back.channel_names(), im.channel_names());
    ASSERT_EQ(back.width(), 37);
    ASSERT_EQ(back.height(), 11);
    EXPECT_TRUE(std::isnan(back.at(2, 0, 0)));
    back.at(2, 0, 0) = im.at(2, 0, 0) = 0.0f; // NaN != NaN
    EXPECT_TRUE(back == im) << n;
    Image again = read_image(p); // by content, same result
    again.at(2, 0, 0) = 0.0f;
    EXPECT_TRUE(again == im);
  }
}

// A channel whose every value is a half (masks, 8-bit values) is stored as HALF, in half the
// bytes; one value that is not keeps its channel FLOAT. Either way the round trip is exact.
TEST_F(ImageTest, ExrStoresExactHalfChannelsAsHalfLosslessly) {
  const float halfs[] = {0.0f,
                         -0.0f,
                         1.0f,
                         65504.0f,
                         -65504.0f,
                         std::ldexp(1.0f, -24),
                         std::ldexp(3.0f, -24),
                         std::ldexp(1.5f, -15),
                         std::ldexp(1.0f, -14),
                         0.5f + std::ldexp(1.0f, -11)};
  const float not_halfs[] = {1.0f + std::ldexp(1.0f, -11),
                             65520.0f,
                             std::ldexp(1.0f, -25),
                             std::ldexp(1.5f, -24),
                             std::ldexp(1.0f + std::ldexp(1.0f, -10), -15),
                             0.1f,
                             std::numeric_limits<float>::infinity()};
  const int w = int(std::size(not_halfs)) + 1;
  Image im(w, 2, {"mask", "halfs", "mixed"});
  for (int x = 0; x < w; ++x) {
    im.at(x, 0, 0) = float(x % 2);
    im.at(x, 1, 0) = 1.0f - float(x % 2);
    im.at(x, 0, 1) = halfs[std::size_t(x) % std::size(halfs)];
    im.at(x, 1, 1) = -halfs[std::size_t(x + 3) % std::size(halfs)];
    im.at(x, 0, 2) = 0.25f;
    im.at(x, 1, 2) = x + 1 < w ? not_halfs[std::size_t(x)] : 0.75f;
  }
  const fs::path p = dir / "halfs.exr";
  write_exr(p, im);
  const Image back = read_exr(p);
  ASSERT_EQ(back.channel_names(), im.channel_names());
  for (std::size_t i = 0; i < im.pixels().size(); ++i) {
    EXPECT_EQ(std::bit_cast<std::uint32_t>(back.pixels()[i]), std::bit_cast<std::uint32_t>(im.pixels()[i]))
        << "value " << i << ": " << im.pixels()[i];
  }
  Imf::InputFile file(p.c_str());
  EXPECT_EQ(file.header().channels().findChannel("mask")->type, Imf::HALF);
  EXPECT_EQ(file.header().channels().findChannel("halfs")->type, Imf::HALF);
  EXPECT_EQ(file.header().channels().findChannel("mixed")->type, Imf::FLOAT);
  // Each value that is not a half alone keeps a channel FLOAT.
  for (float v : not_halfs) {
    Image one(1, 1, {"Y"});
    one.at(0, 0, 0) = v;
    write_exr(p, one);
    EXPECT_EQ(Imf::InputFile(p.c_str()).header().channels().findChannel("Y")->type, Imf::FLOAT) << v;
    EXPECT_EQ(std::bit_cast<std::uint32_t>(read_exr(p).at(0, 0, 0)), std::bit_cast<std::uint32_t>(v)) << v;
  }
}

// The writer makes OpenEXR's ZIP chunks itself (exr_encode.cpp): chunks of 16 lines and a last
// partial one, chunks that deflate and chunks of noise that are stored as they are, HALF and FLOAT
// channels interleaved line by line in the header's sorted order. OpenEXR's reader gets every bit.
TEST_F(ImageTest, ExrZipChunksRoundTripBitExactly) {
  std::uint32_t state = 12345u;
  auto next = [&] { // xorshift32
    state ^= state << 13, state ^= state >> 17, state ^= state << 5;
    return state;
  };
  auto noise_float = [&] { // any finite float: bits that deflate cannot shrink
    std::uint32_t bits;
    do bits = next();
    while ((bits & 0x7f800000u) == 0x7f800000u);
    return std::bit_cast<float>(bits);
  };
  auto noise_half = [&] { // any finite half, as a float: the channel stays HALF
    float v;
    do v = std::ldexp(float(next() % 2048u), int(next() % 41u) - 34) * (next() % 2 ? -1.0f : 1.0f);
    while (std::fabs(v) > 65504.0f || (v != 0.0f && std::fabs(v) < std::ldexp(1.0f, -14) &&
                                       std::fmod(std::fabs(v), std::ldexp(1.0f, -24)) != 0.0f));
    return v;
  };
  for (const bool noise : {false, true}) {
    const int w = 1921, h = 35;
    Image im(w, h, {"z_float", "a_mask", "m_float"});
    for (int y = 0; y < h; ++y)
      for (int x = 0; x < w; ++x) {
        im.at(x, y, 0) = noise ? noise_float() : std::sin(0.01f * float(x + 3 * y));
        im.at(x, y, 1) = noise ? noise_half() : float((x / 7 + y) % 2);
        im.at(x, y, 2) = noise ? noise_float() : float(x) / float(w) + 1e-7f * float(y);
      }
    const fs::path p = dir / (noise ? "noise.exr" : "smooth.exr");
    write_exr(p, im);
    const Image back = read_exr(p);
    ASSERT_EQ(back.channel_names(), im.channel_names());
    for (std::size_t i = 0; i < im.pixels().size(); ++i)
      ASSERT_EQ(std::bit_cast<std::uint32_t>(back.pixels()[i]), std::bit_cast<std::uint32_t>(im.pixels()[i]))
          << (noise ? "noise" : "smooth") << ", value " << i;
    Imf::InputFile file(p.c_str());
    EXPECT_EQ(file.header().compression(), Imf::ZIP_COMPRESSION);
    EXPECT_EQ(file.header().channels().findChannel("a_mask")->type, Imf::HALF);
    const auto raw_bytes = std::uintmax_t(w) * std::uintmax_t(h) * (4 + 2 + 4);
    if (noise)
      EXPECT_GT(fs::file_size(p), raw_bytes); // stored, plus the header and the chunk table
    else
      EXPECT_LT(fs::file_size(p), raw_bytes / 2);
  }
}

TEST_F(ImageTest, ExrNamedChannelsKeepTheirOrder) {
  Image im = ramp(5, 4, {"visibility", "sample_count", "std_error"});
  write_image(dir / "gt.EXR", im);
  Image back = read_exr(dir / "gt.EXR");
  EXPECT_EQ(back.channel_names(), (std::vector<std::string>{"visibility", "sample_count", "std_error"}));
  EXPECT_TRUE(back == im);
  EXPECT_EQ(back.channel("std_error").at(4, 3), im.at(4, 3, 2));
}

TEST_F(ImageTest, PngRoundTripWithinOneCode) {
  for (int n : {1, 2, 3, 4}) {
    Image im = ramp(19, 7, default_channel_names(n));
    const fs::path p = dir / ("im" + std::to_string(n) + ".png");
    write_png(p, im);
    Image back = read_png(p);
    ASSERT_EQ(back.channels(), n);
    ASSERT_EQ(back.width(), 19);
    for (int y = 0; y < 7; ++y)
      for (int x = 0; x < 19; ++x)
        for (int c = 0; c < n; ++c) {
          const bool alpha = (n == 2 || n == 4) && c == n - 1;
          const float v = im.at(x, y, c), w = back.at(x, y, c);
          if (alpha)
            EXPECT_NEAR(w, v, 0.5f / 255.0f + 1e-6f);
          else // within half a code after sRGB encoding, so within 1/255 in sRGB terms
            EXPECT_NEAR(linear_to_srgb(w), linear_to_srgb(v), 0.5f / 255.0f + 1e-6f);
        }
    // Re-encoding the decoded image gives the same bytes.
    write_png(dir / "again.png", back);
    EXPECT_EQ(slurp(dir / "again.png"), slurp(p));
  }
}

// A PNG of 8-bit values as read back from an sRGB target (encode_png8) is the PNG of the float
// path (the values decoded with srgb8_to_linear, then encode_png): the same file, for all 256
// levels in every colour channel, and reading it gives the levels back exactly.
TEST_F(ImageTest, Png8FromSrgbBytesEqualsTheFloatPath) {
  for (int n : {1, 2, 3, 4}) {
    const int w = 256, h = 3; // row y: level (x + 85 y) mod 256 in channel c shifted by 37 c
    const bool has_alpha = n == 2 || n == 4;
    std::vector<std::uint8_t> bytes(std::size_t(w) * h * n);
    Image decoded(w, h, n);
    for (int y = 0; y < h; ++y)
      for (int x = 0; x < w; ++x)
        for (int c = 0; c < n; ++c) {
          const auto v = std::uint8_t((x + 85 * y + 37 * c) % 256);
          bytes[(std::size_t(y) * w + std::size_t(x)) * n + std::size_t(c)] = v;
          decoded.at(x, y, c) = has_alpha && c == n - 1 ? float(v) / 255.0f : srgb8_to_linear(v);
        }
    const std::vector<std::uint8_t> png8 = encode_png8(dir / "a.png", w, h, n, bytes);
    EXPECT_EQ(png8, encode_png(dir / "a.png", decoded)) << n;
    write_file_atomic(dir / "a.png", png8);
    const Image back = read_png(dir / "a.png");
    ASSERT_EQ(back.channels(), n);
    for (int y = 0; y < h; ++y)
      for (int x = 0; x < w; ++x)
        for (int c = 0; c < n; ++c) {
          const std::uint8_t v = bytes[(std::size_t(y) * w + std::size_t(x)) * n + std::size_t(c)];
          if (has_alpha && c == n - 1)
            ASSERT_EQ(std::lround(255.0f * back.at(x, y, c)), v) << n;
          else
            ASSERT_EQ(linear_to_srgb8(back.at(x, y, c)), v) << n;
        }
  }
  // Each level's decode encodes back to it with the shared sRGB function itself.
  for (int i = 0; i <= 255; ++i)
    EXPECT_EQ(std::lround(255.0 * double(linear_to_srgb(srgb8_to_linear(std::uint8_t(i))))), i) << i;
}

TEST_F(ImageTest, Png8RejectsBadSizes) {
  const std::vector<std::uint8_t> six(6, 100);
  EXPECT_NO_THROW(encode_png8(dir / "ok.png", 2, 1, 3, six));
  EXPECT_THROW(encode_png8(dir / "short.png", 2, 2, 3, six), ImageError); // 12 bytes needed
  EXPECT_THROW(encode_png8(dir / "long.png", 1, 1, 3, six), ImageError);
  EXPECT_THROW(encode_png8(dir / "zero.png", 0, 1, 3, {}), ImageError);
  EXPECT_THROW(encode_png8(dir / "channels.png", 1, 1, 6, six), ImageError);
  EXPECT_THROW(encode_png8(dir / "huge.png", max_side + 1, 1, 1, six), ImageError);
  try {
    encode_png8(dir / "short.png", 2, 2, 3, six);
  } catch (const ImageError& e) {
    EXPECT_EQ(e.path(), dir / "short.png");
    EXPECT_NE(e.reason().find("6 bytes for a 2x2 image of 3 channels"), std::string::npos) << e.reason();
  }
  EXPECT_TRUE(entries().empty()); // encoding writes nothing
}

TEST_F(ImageTest, AtomicWriteFailureLeavesNoTraceAndKeepsTheOldFile) {
  // Tests may run as root, where permissions do not stop writes: the parent is a regular file.
  spit(dir / "blocker", "not a directory");
  EXPECT_THROW(write_exr(dir / "blocker" / "out.exr", Image(2, 2, 1)), ImageError);
  EXPECT_THROW(write_png(dir / "blocker" / "out.png", Image(2, 2, 1)), ImageError);
  try {
    write_png(dir / "blocker" / "out.png", Image(2, 2, 1));
  } catch (const ImageError& e) {
    EXPECT_EQ(e.path(), dir / "blocker" / "out.png");
    EXPECT_NE(std::string(e.what()).find("out.png"), std::string::npos);
    EXPECT_NE(e.reason().find("Not a directory"), std::string::npos) << e.reason();
  }
  EXPECT_THROW(write_exr(dir / "missing_dir" / "out.exr", Image(2, 2, 1)), ImageError);

  // A failure at the rename (the target is a non-empty directory): the temporary file is
  // removed. And an old target is replaced only by a complete file.
  fs::create_directories(dir / "target.exr" / "inside");
  EXPECT_THROW(write_exr(dir / "target.exr", Image(2, 2, 1)), ImageError);
  EXPECT_EQ(entries(), (std::vector<std::string>{"blocker", "target.exr"}));
  EXPECT_EQ(slurp(dir / "blocker"), "not a directory");

  const Image old_image = ramp(4, 4, {"Y"});
  write_exr(dir / "old.exr", old_image);
  const std::string old_bytes = slurp(dir / "old.exr");
  EXPECT_THROW(write_exr(dir / "old.exr", Image()), ImageError); // nothing to write
  EXPECT_EQ(slurp(dir / "old.exr"), old_bytes);
  write_exr(dir / "old.exr", ramp(8, 8, {"Y"})); // a successful overwrite
  EXPECT_TRUE(read_exr(dir / "old.exr") == ramp(8, 8, {"Y"}));
  EXPECT_EQ(entries(), (std::vector<std::string>{"blocker", "old.exr", "target.exr"}));
  EXPECT_THROW(write_image(dir / "x.tiff", old_image), ImageError);
}

TEST_F(ImageTest, ReadErrors) {
  EXPECT_THROW(read_image(dir / "missing.exr"), ImageError);
  EXPECT_THROW(read_png(dir / "missing.png"), ImageError);
  EXPECT_THROW(read_image(dir), ImageError);
  spit(dir / "empty.exr", "");
  EXPECT_THROW(read_image(dir / "empty.exr"), ImageError);
  spit(dir / "garbage.exr", std::string(1000, 'x'));
  EXPECT_THROW(read_exr(dir / "garbage.exr"), ImageError);
  EXPECT_THROW(read_image(dir / "garbage.exr"), ImageError);

  write_exr(dir / "good.exr", ramp(64, 64, {"R", "G", "B"}));
  write_png(dir / "good.png", ramp(64, 64, {"R", "G", "B"}));
  EXPECT_THROW(read_png(dir / "good.exr"), ImageError); // wrong format for the reader
  EXPECT_THROW(read_exr(dir / "good.png"), ImageError);
  for (const char* name : {"good.exr", "good.png"}) {
    const std::string bytes = slurp(dir / name);
    for (std::size_t keep : {std::size_t(6), std::size_t(40), bytes.size() / 2, bytes.size() - 20}) {
      spit(dir / "cut", bytes.substr(0, keep));
      EXPECT_THROW(read_image(dir / "cut"), ImageError) << name << " cut to " << keep;
    }
    std::string corrupt = bytes; // header intact, payload garbage
    for (std::size_t i = corrupt.size() / 2; i < corrupt.size(); ++i) corrupt[i] = char(i * 7);
    spit(dir / "corrupt", corrupt);
    EXPECT_THROW(read_image(dir / "corrupt"), ImageError) << name;
  }
}

TEST_F(ImageTest, AbsurdSizesAreRejected) {
  // A PNG header claiming 70000 x 1: rejected before decoding.
  write_png(dir / "one.png", Image(1, 1, 1));
  std::string png = slurp(dir / "one.png");
  auto put32 = [&](std::size_t at, std::uint32_t v) {
    for (int i = 0; i < 4; ++i) png[at + std::size_t(i)] = char((v >> (24 - 8 * i)) & 0xff);
  };
  put32(16, 70000); // IHDR width (stb ignores the chunk CRC)
  spit(dir / "huge.png", png);
  try {
    read_image(dir / "huge.png");
    ADD_FAILURE() << "no error";
  } catch (const ImageError& e) { EXPECT_NE(e.reason().find("70000"), std::string::npos) << e.reason(); }
  EXPECT_THROW(Image(max_side + 1, 1, 1), ImageError);
  EXPECT_NO_THROW(Image(max_side, 1, 1));
}

// Issue 19: a small file that claims a large image is refused against the memory limit
// (MSM_MAX_MEMORY_MB, msm/util/limits.h) before the image is allocated, naming the limit.
TEST_F(ImageTest, ClaimedSizeCheckedAgainstTheMemoryLimit) {
  write_png(dir / "one.png", Image(1, 1, 4));
  std::string png = slurp(dir / "one.png");
  // IHDR width and height 16000 (stb itself refuses more than 2^30 bytes of 8-bit texels).
  for (std::size_t at : {std::size_t(16), std::size_t(20)})
    for (int i = 0; i < 4; ++i) png[at + std::size_t(i)] = char((16000u >> (24 - 8 * i)) & 0xff);
  spit(dir / "claims.png", png);
  ::setenv("MSM_MAX_MEMORY_MB", "1024", 1);
  try {
    read_image(dir / "claims.png");
    ADD_FAILURE() << "no error";
  } catch (const ImageError& e) {
    EXPECT_NE(e.reason().find("16000x16000 image of 4 channels needs about 3.8 GiB; the limit is 1.0 GiB"),
              std::string::npos)
        << e.reason();
  }
  ::unsetenv("MSM_MAX_MEMORY_MB");
  // Within the limit the same claim fails as truncated, not as too large.
  png = slurp(dir / "one.png");
  png[19] = char(200); // width 200
  spit(dir / "small_claim.png", png);
  try {
    read_image(dir / "small_claim.png");
    ADD_FAILURE() << "no error";
  } catch (const ImageError& e) { EXPECT_EQ(e.reason().find("limit"), std::string::npos) << e.reason(); }
}

// Found by the compare fuzzer (tests/fuzz/crashes/compare): an EXR header attribute whose size
// field claims 1.9 GB made OpenEXR allocate that before failing; the header is walked first.
TEST_F(ImageTest, ExrAttributeSizeBeyondTheFileIsRefusedFirst) {
  write_exr(dir / "good.exr", ramp(4, 3, {"Y"}));
  std::string exr = slurp(dir / "good.exr");
  const std::size_t at = exr.find("compression");
  ASSERT_NE(at, std::string::npos);
  const std::size_t size_field = at + std::string("compression").size() * 2 + 2; // name, type, NULs
  ASSERT_EQ(exr[size_field], 1);                                                 // compression: one byte
  exr[size_field + 3] = 0x72;                                                    // 1912602625 bytes claimed
  spit(dir / "claims.exr", exr);
  try {
    read_image(dir / "claims.exr");
    ADD_FAILURE() << "no error";
  } catch (const ImageError& e) {
    EXPECT_NE(e.reason().find("attribute 'compression' claims 1912602625 bytes"), std::string::npos) << e.reason();
  }
  EXPECT_EQ(read_image(dir / "good.exr"), ramp(4, 3, {"Y"}));
}

// A header of a few hundred bytes may claim a 16384² mip-mapped image of 1x1 tiles: 358 million
// chunks, whose offsets alone would fill 2.9 GB (io.cpp, check_exr_header). A real tiled file (here one of 1x1 tiles, 341 chunks over its five levels) holds that table and
// reads as before; the same header with a larger data window is refused, naming the chunks.
TEST_F(ImageTest, ExrHeaderImplyingMoreChunksThanTheFileHoldsIsRefused) {
  const Image image = ramp(16, 16, {"Y"});
  {
    Imf::Header header(16, 16);
    header.channels().insert("Y", Imf::Channel(Imf::FLOAT));
    header.setTileDescription(Imf::TileDescription(1, 1, Imf::MIPMAP_LEVELS));
    Imf::TiledOutputFile file((dir / "tiled.exr").c_str(), header);
    for (int level = 0; level < file.numLevels(); ++level) {
      const int w = file.levelWidth(level), h = file.levelHeight(level);
      Imf::FrameBuffer fb;
      fb.insert("Y", Imf::Slice(Imf::FLOAT, (char*)image.pixels().data(), sizeof(float), sizeof(float) * 16));
      file.setFrameBuffer(fb);
      file.writeTiles(0, file.numXTiles(level) - 1, 0, file.numYTiles(level) - 1, level);
      EXPECT_LE(w, 16);
      EXPECT_LE(h, 16);
    }
  }
  EXPECT_EQ(read_image(dir / "tiled.exr"), image);
  std::string exr = slurp(dir / "tiled.exr");
  const std::size_t at = exr.find("dataWindow");
  ASSERT_NE(at, std::string::npos);
  const std::size_t value = at + std::string("dataWindow").size() + std::string("box2i").size() + 2 + 4;
  for (std::size_t corner : {value + 8, value + 12}) { // xMax, yMax: 15 -> 16383
    exr[corner] = char(0xff);
    exr[corner + 1] = char(0x3f);
  }
  spit(dir / "claims.exr", exr);
  try {
    read_image(dir / "claims.exr");
    ADD_FAILURE() << "no error";
  } catch (const ImageError& e) {
    EXPECT_NE(e.reason().find("header implies 357913941 chunks"), std::string::npos) << e.reason();
  }
  // A side beyond max_side is refused from the header too (OpenEXR would size a line of it).
  exr[value + 8] = char(0x6f), exr[value + 9] = char(0x11), exr[value + 10] = char(0x01); // xMax 69999
  exr[value + 12] = char(15), exr[value + 13] = char(0);                                  // yMax 15
  spit(dir / "wide.exr", exr);
  try {
    read_image(dir / "wide.exr");
    ADD_FAILURE() << "no error";
  } catch (const ImageError& e) {
    EXPECT_NE(e.reason().find("image size 70000x16 is outside"), std::string::npos) << e.reason();
  }
}

// Found by the image fuzzer (tests/fuzz/crashes/image): stb copies an empty IDAT chunk before
// the image data from a null buffer (undefined behaviour; UBSan reports it under
// `make sanitize-cpu`). Empty IDAT chunks are dropped first: the file reads as without them.
TEST_F(ImageTest, EmptyIdatChunksReadAsWithoutThem) {
  const Image image = ramp(5, 3, {"R", "G", "B", "A"});
  write_png(dir / "plain.png", image);
  std::string png = slurp(dir / "plain.png");
  const std::size_t idat = png.find("IDAT");
  ASSERT_NE(idat, std::string::npos);
  const std::string empty("\0\0\0\0IDAT\x35\xaf\x06\x1e", 12); // length 0, type, CRC
  spit(dir / "empty_idat.png", png.substr(0, idat - 4) + empty + empty + png.substr(idat - 4));
  EXPECT_EQ(read_image(dir / "empty_idat.png"), read_image(dir / "plain.png"));
}

// ---- Metrics ---------------------------------------------------------------------------------

TEST(Metrics, ShiftedStepHasExactErrors) {
  // Reference edge at x = 8, test edge at x = 7 in a 16 x 8 image: one column of 8 pixels is 1
  // instead of 0 (test brighter): MAE = 8/128, RMSE = sqrt(8/128), max 1, all light leaking.
  const Image ref = step(16, 8, 8), test = step(16, 8, 7);
  const Metrics m = compute_metrics(test, ref);
  EXPECT_EQ(m.pixels, 128u);
  EXPECT_EQ(m.mae, 0.0625);
  EXPECT_EQ(m.rmse, 0.25);
  EXPECT_EQ(m.max_error, 1.0);
  EXPECT_EQ(m.max_error_x, 7);
  EXPECT_EQ(m.max_error_y, 0);
  EXPECT_EQ(m.share_above_1pct, 0.0625);
  EXPECT_EQ(m.share_above_3pct, 0.0625);
  EXPECT_EQ(m.share_above_10pct, 0.0625);
  EXPECT_EQ(m.light_leaking, 0.0625);
  EXPECT_EQ(m.over_darkening, 0.0);
  EXPECT_EQ(m.mean_error, 0.0625);

  // The other way round the test is darker: over-darkening.
  const Metrics d = compute_metrics(ref, test);
  EXPECT_EQ(d.light_leaking, 0.0);
  EXPECT_EQ(d.over_darkening, 0.0625);
  EXPECT_EQ(d.mean_error, -0.0625);

  // As shadow intensity (larger = darker), a larger test value is over-darkening.
  const Metrics s = compute_metrics(test, ref, {.signal = Signal::shadow_intensity});
  EXPECT_EQ(s.light_leaking, 0.0);
  EXPECT_EQ(s.over_darkening, 0.0625);
  EXPECT_EQ(s.mae, 0.0625);

  const Metrics same = compute_metrics(ref, ref);
  EXPECT_EQ(same.mae, 0.0);
  EXPECT_EQ(same.rmse, 0.0);
  EXPECT_EQ(same.max_error, 0.0);
  EXPECT_EQ(same.share_above_1pct, 0.0);
}

TEST(Metrics, ThresholdsAreStrictAndShareIsAFraction) {
  // Differences 0.005, 0.02, 0.05, 0.2 (exactly representable offsets from 0.5 are not all
  // possible in float, so use values well away from the thresholds).
  Image ref(4, 1, 1, 0.5f), test(4, 1, 1, 0.5f);
  const float d[4] = {0.005f, -0.02f, 0.05f, -0.2f};
  for (int x = 0; x < 4; ++x) test.at(x, 0) += d[x];
  const Metrics m = compute_metrics(test, ref);
  EXPECT_EQ(m.share_above_1pct, 0.75);
  EXPECT_EQ(m.share_above_3pct, 0.5);
  EXPECT_EQ(m.share_above_10pct, 0.25);
  EXPECT_NEAR(m.mae, (0.005 + 0.02 + 0.05 + 0.2) / 4, 1e-7);
  EXPECT_NEAR(m.light_leaking, (0.005 + 0.05) / 4, 1e-7);
  EXPECT_NEAR(m.over_darkening, (0.02 + 0.2) / 4, 1e-7);
  EXPECT_NEAR(m.light_leaking + m.over_darkening, m.mae, 1e-12);
  EXPECT_NEAR(m.rmse, std::sqrt((0.005 * 0.005 + 0.02 * 0.02 + 0.05 * 0.05 + 0.2 * 0.2) / 4), 1e-7);
  EXPECT_EQ(m.max_error_x, 3);
}

TEST(Metrics, MaskNonFiniteChannelsAndLuminance) {
  const Image ref = step(16, 8, 8), test = step(16, 8, 7);
  Image mask(16, 8, 1, 0.0f);
  for (int y = 0; y < 8; ++y) mask.at(7, y) = 1.0f; // ignore the differing column
  const Metrics m = compute_metrics(test, ref, {.mask = &mask});
  EXPECT_EQ(m.masked, 8u);
  EXPECT_EQ(m.pixels, 120u);
  EXPECT_EQ(m.mae, 0.0);

  Image nan_test = test;
  nan_test.at(0, 0) = std::nanf("");
  nan_test.at(1, 0) = INFINITY;
  const Metrics n = compute_metrics(nan_test, ref);
  EXPECT_EQ(n.non_finite, 2u);
  EXPECT_EQ(n.pixels, 126u);
  EXPECT_EQ(n.mae, 8.0 / 126.0);
  EXPECT_EQ(n.non_finite_in_test, 2u); // the reference is finite there

  // Non-finite in the reference (or both) is not the test's failure; masked pixels are not counted.
  Image nan_ref = ref;
  nan_ref.at(0, 0) = std::nanf("");
  nan_ref.at(2, 0) = -INFINITY;
  Image nan_mask(16, 8, 1, 0.0f);
  nan_mask.at(1, 0) = 1.0f;
  const Metrics r = compute_metrics(nan_test, nan_ref, {.mask = &nan_mask});
  EXPECT_EQ(r.masked, 1u);
  EXPECT_EQ(r.non_finite, 2u);
  EXPECT_EQ(r.non_finite_in_test, 0u);
  const Metrics all_nan = compute_metrics(Image(16, 8, 1, std::nanf("")), ref);
  EXPECT_EQ(all_nan.pixels, 0u);
  EXPECT_EQ(all_nan.non_finite_in_test, 128u);

  // RGB: compared as Rec. 709 luminance; a named channel on request.
  Image rgb_ref(2, 1, 3, 0.0f), rgb_test(2, 1, 3, 0.0f);
  rgb_test.at(0, 0, 1) = 1.0f; // green +1 -> luminance +0.7152
  const Metrics l = compute_metrics(rgb_test, rgb_ref);
  EXPECT_NEAR(l.mae, 0.7152 / 2, 1e-6);
  EXPECT_NEAR(compute_metrics(rgb_test, rgb_ref, {.channel = "G"}).mae, 0.5, 0);
  EXPECT_EQ(compute_metrics(rgb_test, rgb_ref, {.channel = "B"}).mae, 0.0);
  EXPECT_THROW(compute_metrics(rgb_test, rgb_ref, {.channel = "visibility"}), ImageError);

  Image gt = ramp(4, 4, {"visibility", "sample_count", "std_error"});
  EXPECT_THROW(compute_metrics(gt, gt), ImageError); // several channels, none chosen
  EXPECT_EQ(compute_metrics(gt, gt, {.channel = "visibility"}).mae, 0.0);

  EXPECT_THROW(compute_metrics(step(16, 8, 8), step(15, 8, 8)), ImageError);
  Image small_mask(2, 2, 1);
  EXPECT_THROW(compute_metrics(test, ref, {.mask = &small_mask}), ImageError);
}

TEST_F(ImageTest, ErrorImageColours) {
  Image ref(5, 1, 1, 0.5f), test(5, 1, 1, 0.5f);
  test.at(0, 0) = 0.6f;   // brighter by the full range: red
  test.at(1, 0) = 0.4f;   // darker by the full range: blue
  test.at(2, 0) = 0.525f; // a quarter of the range brighter: light red (1, 0.75, 0.75)
  test.at(4, 0) = std::nanf("");
  Image mask(5, 1, 1, 0.0f);
  mask.at(3, 0) = 1.0f;
  const MetricOptions options{.mask = &mask};
  write_error_png(dir / "err.png", test, ref, 0.1, options);
  const std::vector<std::uint8_t> bytes = to_srgb8(read_png(dir / "err.png"));
  const std::vector<std::uint8_t> expected = {255, 0, 0, 0, 0, 255, 255, 191, 191, 128, 128, 128, 0, 255, 0};
  EXPECT_EQ(bytes, expected);
  EXPECT_THROW(error_image(test, ref, 0.0), ImageError);
  // For shadow intensity the colours swap: a larger test value is darker (blue).
  const Image s = error_image(test, ref, 0.1, {.signal = Signal::shadow_intensity});
  EXPECT_EQ(linear_to_srgb8(s.at(0, 0, 2)), 255);
  EXPECT_EQ(linear_to_srgb8(s.at(0, 0, 0)), 0);
}

// ---- The image-test helper -------------------------------------------------------------------

TEST_F(ImageTest, CompareDumpsActualReferenceAndErrorOnFailure) {
  const Image ref = step(16, 8, 8), test = step(16, 8, 7);
  const fs::path out = dir / "test-failures" / "Shadow.Step";

  CompareResult ok = compare(ref, ref, {}, {.failure_dir = out});
  EXPECT_TRUE(ok.passed) << ok.report;
  EXPECT_TRUE(ok);
  EXPECT_EQ(ok.report.rfind("PASS", 0), 0u) << ok.report;
  EXPECT_FALSE(fs::exists(out));

  // MAE 0.0625 is within 0.1, but 6.25% of the pixels are off by more than 3% (> 1%).
  CompareResult bad = compare(test, ref, {.max_mae = 0.1, .max_share_above_3pct = 0.01}, {.failure_dir = out});
  EXPECT_FALSE(bad.passed);
  EXPECT_EQ(bad.report.rfind("FAIL", 0), 0u) << bad.report;
  EXPECT_NE(bad.report.find("share_above_3pct = 0.0625 > tolerance 0.01"), std::string::npos) << bad.report;
  EXPECT_EQ(bad.report.find("mae = "), std::string::npos) << bad.report; // within tolerance
  EXPECT_NE(bad.report.find(out.string()), std::string::npos) << bad.report;
  EXPECT_TRUE(read_exr(out / "actual.exr") == test);
  EXPECT_TRUE(read_exr(out / "reference.exr") == ref);
  EXPECT_EQ(read_png(out / "actual.png").width(), 16);
  EXPECT_EQ(read_png(out / "reference.png").width(), 16);
  const Image err = read_png(out / "error.png");
  EXPECT_EQ(err.channels(), 3);
  EXPECT_EQ(to_srgb8(err)[3 * 7], 255); // the leaking column is red
  EXPECT_EQ(to_srgb8(err)[3 * 7 + 1], 0);

  // Tolerances loose enough pass; a size mismatch fails without throwing and dumps no error.png.
  EXPECT_TRUE(compare(test, ref, {.max_mae = 0.07, .max_share_above_3pct = 0.07}).passed);
  const fs::path out2 = dir / "mismatch";
  CompareResult mismatch = compare(step(15, 8, 7), ref, {}, {.failure_dir = out2});
  EXPECT_FALSE(mismatch.passed);
  EXPECT_NE(mismatch.report.find("size mismatch"), std::string::npos) << mismatch.report;
  EXPECT_TRUE(fs::exists(out2 / "actual.exr"));
  EXPECT_TRUE(fs::exists(out2 / "reference.exr"));
  EXPECT_FALSE(fs::exists(out2 / "error.png"));

  Image nan_test = ref;
  nan_test.at(0, 0) = std::nanf("");
  EXPECT_FALSE(compare(nan_test, ref).passed);
}

// A file set appears whole or not at all: a failure at the second rename (its target is a
// non-empty directory) leaves the first target as it was (absent, or its old bytes) and no
// temporary or backup file; a set never committed leaves nothing.
TEST_F(ImageTest, FileSetIsAllOrNothing) {
  const std::string bytes = "{}\n";
  const std::span<const std::uint8_t> json(reinterpret_cast<const std::uint8_t*>(bytes.data()), bytes.size());
  fs::create_directories(dir / "b.png" / "inside");
  {
    FileSet set;
    set.add_exr(dir / "a.exr", ramp(4, 4, {"Y"}));
    set.add_png(dir / "b.png", ramp(4, 4, {"Y"}));
    set.add(dir / "c.json", json);
    EXPECT_THROW(set.commit(), ImageError);
  }
  EXPECT_EQ(entries(), (std::vector<std::string>{"b.png"}));

  write_exr(dir / "a.exr", ramp(2, 2, {"Y"}));
  const std::string old_bytes = slurp(dir / "a.exr");
  {
    FileSet set;
    set.add_exr(dir / "a.exr", ramp(8, 8, {"Y"}));
    set.add_png(dir / "b.png", ramp(8, 8, {"Y"}));
    try {
      set.commit();
      ADD_FAILURE() << "the rename over a directory succeeded";
    } catch (const ImageError& e) {
      EXPECT_EQ(e.path(), dir / "b.png");
      EXPECT_NE(e.reason().find("none of the set's files was written"), std::string::npos) << e.reason();
    }
  }
  EXPECT_EQ(slurp(dir / "a.exr"), old_bytes);
  EXPECT_EQ(entries(), (std::vector<std::string>{"a.exr", "b.png"}));

  {
    FileSet set; // never committed
    set.add(dir / "c.json", json);
  }
  EXPECT_EQ(entries(), (std::vector<std::string>{"a.exr", "b.png"}));

  fs::remove_all(dir / "b.png");
  spit(dir / "stale.exr", "old");
  FileSet set;
  set.add_exr(dir / "a.exr", ramp(8, 8, {"Y"}));
  set.add_png(dir / "b.png", ramp(8, 8, {"Y"}));
  set.remove(dir / "stale.exr");
  set.remove(dir / "never-there.exr");
  set.commit();
  EXPECT_TRUE(read_exr(dir / "a.exr") == ramp(8, 8, {"Y"}));
  EXPECT_EQ(entries(), (std::vector<std::string>{"a.exr", "b.png"}));
}
