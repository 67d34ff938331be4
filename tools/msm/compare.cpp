// `msm compare REFERENCE TEST`: error metrics of a test image (EXR or PNG) against a reference
// (see msm/image/metrics.h for the definitions), as a table or JSON; optionally the false-colour
// error image. Bad input (missing or malformed file, size mismatch, unknown or ambiguous channel,
// a PNG against an EXR) is a UsageError: exit status 2; so is a test image with NaN or infinite
// pixels where the reference is finite (the metrics are printed first, and say how many).
#include "commands.h"
#include "msm/image/io.h"
#include "msm/image/metrics.h"
#include "vocabulary.h"

#include <fmt/core.h>

#include <map>
#include <optional>

namespace msm::tool {
namespace {

using image::FileFormat;
using image::Image;
using image::ImageFile;

bool has_channel(const Image& image, std::string_view name) { return image.find_channel(name) >= 0; }

// msm render's <technique>.exr and msm reference's visibility.exr: a "visibility" channel with its
// "background" mask and no colour.
bool is_visibility_file(const Image& image) {
  return has_channel(image, "visibility") && has_channel(image, "background") && !has_channel(image, "R");
}

// The choices when select_signal cannot pick a channel by itself (empty: it can).
std::string ambiguous_channels(const Image& image) {
  if (image.channels() == 1 || (image.channels() == 2 && image.channel_names()[1] == "A")) return {};
  if (has_channel(image, "R") && has_channel(image, "G") && has_channel(image, "B")) return {};
  std::string names;
  for (const std::string& n : image.channel_names()) names += (names.empty() ? "" : ", ") + n;
  return names;
}

void check_unambiguous(const std::string& path, const Image& image, const char* option) {
  const std::string names = ambiguous_channels(image);
  if (!names.empty())
    throw UsageError(fmt::format("{}: several channels ({}) and no R,G,B: choose one with {} (e.g. {} {})", path, names,
                                 option, option, image.channel_names().front()));
}

// A PNG holds a picture for display (tone-mapped, clamped, sRGB-encoded 8-bit values), an EXR the
// linear values themselves: compared, they differ by the look, not the shadows (MAE 0.3 for
// identical shadows). Refused unless asked for, naming the files to compare instead.
void check_same_encoding(const std::string& reference_path, const ImageFile& reference, const std::string& test_path,
                         const ImageFile& test) {
  if (reference.format == test.format) return;
  const bool reference_png = reference.format == FileFormat::png;
  const std::filesystem::path png = reference_png ? reference_path : test_path;
  const std::string& exr = reference_png ? test_path : reference_path;
  std::filesystem::path sibling = png;
  sibling.replace_extension(".exr");
  std::error_code ec;
  const std::string instead =
      std::filesystem::is_regular_file(sibling, ec)
          ? fmt::format("use {} (the linear values beside the PNG) instead of {}", sibling.string(), png.string())
          : "compare EXR with EXR (msm render's <technique>.exr with msm reference's visibility.exr) or PNG with PNG "
            "(msm render's <technique>.png with msm reference --effect environment's radiance.png)";
  throw UsageError(fmt::format("{} is an sRGB-encoded PNG (a picture for display) and {} a linear EXR: their values "
                               "differ by the encoding and the tone curve, not only by the shadows; {}; "
                               "--mixed-formats compares them anyway (the PNG decoded to linear)",
                               png.string(), exr, instead));
}

// The mask of msm compare's own outputs: a pixel is ignored where either file marks background.
Image union_of_backgrounds(const Image& a, const Image& b) {
  const Image first = a.channel("background"), second = b.channel("background");
  Image mask(first.width(), first.height(), 1);
  if (second.width() != first.width() || second.height() != first.height()) return mask; // size error follows
  for (std::size_t i = 0; i < mask.pixel_count(); ++i)
    mask.pixels()[i] = first.pixels()[i] > 0.5f || second.pixels()[i] > 0.5f ? 1.0f : 0.0f;
  return mask;
}

} // namespace

void add_compare(CLI::App& app) {
  struct Options {
    std::string reference, test, error_image, mask, mask_channel, channel, test_channel;
    std::string signal = "visibility";
    double range = 0.1;
    std::optional<double> mask_above, mask_below;
    bool json = false, mixed_formats = false;
  };
  auto opt = std::make_shared<Options>();
  auto* cmd = app.add_subcommand("compare", "Error metrics of a test image against a reference (EXR or PNG)");
  cmd->add_option("REFERENCE", opt->reference, "Reference image")->required();
  cmd->add_option("TEST", opt->test, "Test image")->required();
  add_term_flag(cmd, "--json", opt->json);
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
  cmd->add_flag("--mixed-formats", opt->mixed_formats,
                "Compare a PNG with an EXR (refused without it: the PNG's values are a picture for display)");
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
    if (opt->mask.empty() && (!opt->mask_channel.empty() || opt->mask_above || opt->mask_below))
      throw UsageError("--mask-channel, --mask-above and --mask-below need --mask");
    options.channel = opt->channel;
    Metrics metrics;
    try {
      ImageFile reference_file = read_image_file(opt->reference);
      ImageFile test_file = read_image_file(opt->test);
      if (!opt->mixed_formats) check_same_encoding(opt->reference, reference_file, opt->test, test_file);
      Image& reference = reference_file.image;
      Image& test = test_file.image;
      std::optional<Image> mask;
      if (!opt->test_channel.empty()) { // each image's own channel, then the one signal of both
        if (opt->channel.empty()) check_unambiguous(opt->reference, reference, "--channel");
        reference = select_signal(reference, opt->channel);
        test = select_signal(test, opt->test_channel);
        options.channel.clear();
      } else if (opt->channel.empty() && is_visibility_file(reference) && is_visibility_file(test)) {
        // The tools' own outputs (a render against a reference, in either order): their shadows.
        options.channel = "visibility";
        if (opt->mask.empty()) {
          mask = union_of_backgrounds(reference, test);
          fmt::print(stderr, "msm compare: channel visibility, the background of either image masked (--channel "
                             "visibility compares every pixel)\n");
        }
      } else if (opt->channel.empty()) {
        check_unambiguous(opt->reference, reference, "--channel");
        check_unambiguous(opt->test, test, "--channel");
      }
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
      }
      options.mask = mask ? &*mask : nullptr;
      metrics = compute_metrics(test, reference, options);
      if (!opt->error_image.empty()) write_error_png(opt->error_image, test, reference, opt->range, options);
    } catch (const ImageError& e) { throw UsageError(e.what()); }
    if (opt->json)
      fmt::print("{}\n", metrics_json(metrics));
    else
      fmt::print("{}", format_metrics(metrics));
    // NaN or infinity where the reference has a value: the statistics above leave those pixels out,
    // so they would look better the less of the image the test produced.
    if (metrics.non_finite_in_test > 0)
      throw UsageError(fmt::format("{}: {} of {} compared pixels are NaN or infinite where the reference is finite "
                                   "(non_finite_in_test)",
                                   opt->test, metrics.non_finite_in_test, metrics.pixels + metrics.non_finite));
  });
}

} // namespace msm::tool
