// `msm compare REFERENCE TEST`: error metrics of a test image (EXR or PNG) against a reference
// (see msm/image/metrics.h for the definitions), as a table or JSON; optionally the false-colour
// error image. Bad input (missing or malformed file, size mismatch, unknown channel) is a
// UsageError: exit status 2.
#include "commands.h"
#include "msm/image/io.h"
#include "msm/image/metrics.h"

#include <fmt/core.h>

#include <map>
#include <optional>

namespace msm::tool {

void add_compare(CLI::App& app) {
  struct Options {
    std::string reference, test, error_image, mask, mask_channel, channel, test_channel;
    std::string signal = "visibility";
    double range = 0.1;
    std::optional<double> mask_above, mask_below;
    bool json = false;
  };
  auto opt = std::make_shared<Options>();
  auto* cmd = app.add_subcommand("compare", "Error metrics of a test image against a reference (EXR or PNG)");
  cmd->add_option("REFERENCE", opt->reference, "Reference image")->required();
  cmd->add_option("TEST", opt->test, "Test image")->required();
  cmd->add_flag("--json", opt->json, "Print JSON");
  cmd->add_option("--error-image", opt->error_image, "Write the false-colour error image (PNG) here");
  cmd->add_option("--range", opt->range, "Difference shown at full colour in the error image (default 0.1)");
  cmd->add_option("--mask", opt->mask,
                  "Image marking pixels to ignore: where its mask channel is > 0.5 (or as --mask-above / "
                  "--mask-below say)");
  cmd->add_option("--mask-channel", opt->mask_channel,
                  "Channel of the mask image (default: the first), e.g. background of visibility.exr, n_dot_l or "
                  "object of surface.exr");
  cmd->add_option("--mask-above", opt->mask_above, "Ignore pixels where the mask channel is above this");
  cmd->add_option("--mask-below", opt->mask_below,
                  "Ignore pixels where the mask channel is below this (e.g. n_dot_l 0.1: the terminator and the "
                  "background)");
  cmd->add_option("--channel", opt->channel,
                  "Channel to compare (default: the only one, Y of Y+A, else the luminance of R,G,B)");
  cmd->add_option("--test-channel", opt->test_channel,
                  "Channel of the test image where its name differs from the reference's (default: --channel), "
                  "e.g. visible_fraction of `msm render`'s <technique>-scattering.exr against visibility of `msm "
                  "reference --effect scattering`'s visibility.exr");
  cmd->add_option("--signal", opt->signal,
                  "visibility (larger = brighter) or shadow (shadow intensity, larger = darker): "
                  "sets which sign is light leaking");
  cmd->callback([opt] {
    using namespace msm::image;
    MetricOptions options;
    if (opt->signal == "visibility")
      options.signal = Signal::visibility;
    else if (opt->signal == "shadow")
      options.signal = Signal::shadow_intensity;
    else
      throw UsageError(fmt::format("--signal {}: expected visibility or shadow", opt->signal));
    if (!(opt->range > 0)) throw UsageError(fmt::format("--range {} is not > 0", opt->range));
    options.channel = opt->channel;
    Metrics metrics;
    try {
      Image reference = read_image(opt->reference);
      Image test = read_image(opt->test);
      if (!opt->test_channel.empty()) { // each image's own channel, then the one signal of both
        reference = select_signal(reference, opt->channel);
        test = select_signal(test, opt->test_channel);
        options.channel.clear();
      }
      std::optional<Image> mask;
      if (!opt->mask.empty()) {
        const Image source = read_image(opt->mask);
        const Image values = opt->mask_channel.empty() ? source.channel(0) : source.channel(opt->mask_channel);
        // Without thresholds: ignored where > 0.5, as before.
        const bool any = opt->mask_above || opt->mask_below;
        mask = Image(values.width(), values.height(), 1);
        for (std::size_t i = 0; i < values.pixel_count(); ++i) {
          const double v = values.pixels()[i];
          const bool ignored =
              any ? ((opt->mask_above && v > *opt->mask_above) || (opt->mask_below && v < *opt->mask_below)) : v > 0.5;
          mask->pixels()[i] = ignored ? 1.0f : 0.0f;
        }
      } else if (!opt->mask_channel.empty() || opt->mask_above || opt->mask_below) {
        throw UsageError("--mask-channel, --mask-above and --mask-below need --mask");
      }
      options.mask = mask ? &*mask : nullptr;
      metrics = compute_metrics(test, reference, options);
      if (!opt->error_image.empty()) write_error_png(opt->error_image, test, reference, opt->range, options);
    } catch (const ImageError& e) { throw UsageError(e.what()); }
    if (opt->json)
      fmt::print("{}\n", metrics_json(metrics));
    else
      fmt::print("{}", format_metrics(metrics));
  });
}

} // namespace msm::tool
