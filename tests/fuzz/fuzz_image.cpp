// Fuzz target: image loading (msm::image::decode_image, what read_image does after reading the
// file: PNG through stb, EXR through OpenEXR, chosen by the signature), then the per-channel
// views that `msm compare` takes.
#include "fuzz_support.h"
#include "msm/image/io.h"
#include "msm/image/metrics.h"

#include <cstring>
#include <span>

extern "C" int LLVMFuzzerInitialize(int*, char***) {
  msm::fuzz::lower_limits();
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace msm::image;
  try {
    const Image image = decode_image(std::span(data, size), "fuzz");
    MSM_FUZZ_CHECK(image.width() >= 1 && image.width() <= max_side);
    MSM_FUZZ_CHECK(image.height() >= 1 && image.height() <= max_side);
    MSM_FUZZ_CHECK(image.channels() >= 1 && image.channels() <= max_channels);
    MSM_FUZZ_CHECK(image.pixels().size() == image.pixel_count() * std::size_t(image.channels()));
    // By name and by index the same values, bit for bit (NaN included).
    for (int c = 0; c < image.channels(); ++c) {
      const Image by_name = image.channel(image.channel_names()[std::size_t(c)]), by_index = image.channel(c);
      MSM_FUZZ_CHECK(std::memcmp(by_name.pixels().data(), by_index.pixels().data(), by_index.pixels().size_bytes()) ==
                     0);
    }
    const Image signal = select_signal(image);
    MSM_FUZZ_CHECK(signal.channels() == 1 && signal.pixel_count() == image.pixel_count());
  } catch (const ImageError& e) { msm::fuzz::rejected(e); }
  return 0;
}
