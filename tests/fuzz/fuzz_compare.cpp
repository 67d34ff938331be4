// Fuzz target: `msm compare`'s inputs: two images (and a mask taken from the reference, as
// --mask does) through decode_image, compute_metrics, error_image and the printed forms.
// Input: 1 byte of options (bit 0: shadow signal, bits 1-3: the channel, bit 4: mask), a 32-bit
// little-endian length n, n bytes of the reference image, the rest the test image.
#include "fuzz_support.h"
#include "msm/image/io.h"
#include "msm/image/metrics.h"

#include <cmath>
#include <optional>
#include <span>

extern "C" int LLVMFuzzerInitialize(int*, char***) {
  msm::fuzz::lower_limits();
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace msm::image;
  if (size < 5) return 0;
  static const char* const kChannels[] = {"", "Y", "R", "A", "visibility", "background", "n_dot_l", "Z"};
  const std::uint8_t flags = data[0];
  std::size_t n =
      std::size_t(data[1]) | std::size_t(data[2]) << 8 | std::size_t(data[3]) << 16 | std::size_t(data[4]) << 24;
  const std::span<const std::uint8_t> rest(data + 5, size - 5);
  n = std::min(n, rest.size());
  try {
    const Image reference = decode_image(rest.first(n), "reference");
    const Image test = decode_image(rest.subspan(n), "test");
    MetricOptions options;
    options.signal = (flags & 1) ? Signal::shadow_intensity : Signal::visibility;
    options.channel = kChannels[(flags >> 1) & 7];
    std::optional<Image> mask;
    if (flags & 16) {
      const Image values = reference.channel(0);
      mask = Image(values.width(), values.height(), 1);
      for (std::size_t i = 0; i < values.pixel_count(); ++i)
        mask->pixels()[i] = values.pixels()[i] > 0.5f ? 1.0f : 0.0f;
      options.mask = &*mask;
    }
    const Metrics m = compute_metrics(test, reference, options);
    MSM_FUZZ_CHECK(m.width == test.width() && m.height == test.height());
    MSM_FUZZ_CHECK(m.pixels + m.masked + m.non_finite == test.pixel_count());
    for (double v : {m.mae, m.rmse, m.max_error, m.light_leaking, m.over_darkening, m.mean_error})
      MSM_FUZZ_CHECK(std::isfinite(v));
    for (double share : {m.share_above_1pct, m.share_above_3pct, m.share_above_10pct})
      MSM_FUZZ_CHECK(share >= 0.0 && share <= 1.0);
    MSM_FUZZ_CHECK(m.mae >= 0.0 && m.max_error >= 0.0 && m.rmse >= 0.0);
    // light_leaking + over_darkening = mae (metrics.h), to the rounding of the sums.
    MSM_FUZZ_CHECK(std::abs(m.light_leaking + m.over_darkening - m.mae) <= 1e-9 * std::max(1.0, m.mae));
    const Image error = error_image(test, reference, 0.1, options);
    MSM_FUZZ_CHECK(error.width() == test.width() && error.height() == test.height() && error.channels() == 3);
    (void)format_metrics(m);
    (void)metrics_json(m);
  } catch (const ImageError& e) { msm::fuzz::rejected(e); }
  return 0;
}
