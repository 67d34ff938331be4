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
    std::string reference, test, error_image, mask, channel;
    std::string signal = "visibility";
    double range = 0.1;
    bool json = false;
  };
  auto opt = std::make_shared<Options>();
  auto* cmd = app.add_subcommand("compare", "Error metrics of a test image against a reference (EXR or PNG)");
  cmd->add_option("REFERENCE", opt->reference, "Reference image")->required();
  cmd->add_option("TEST", opt->test, "Test image")->required();
  cmd->add_flag("--json", opt->json, "Print JSON");
  cmd->add_option("--error-image", opt->error_image, "Write the false-colour error image (PNG) here");
  cmd->add_option("--range", opt->range, "Difference shown at full colour in the error image (default 0.1)");
  cmd->add_option("--mask", opt->mask, "Image whose first channel > 0.5 marks pixels to ignore");
  cmd->add_option("--channel", opt->channel,
                  "Channel to compare (default: the only one, Y of Y+A, else the luminance of R,G,B)");
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
      const Image reference = read_image(opt->reference);
      const Image test = read_image(opt->test);
      std::optional<Image> mask;
      if (!opt->mask.empty()) mask = read_image(opt->mask);
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
