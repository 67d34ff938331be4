// msm_image_write_fixtures DIR: writes the images of the `msm compare` CLI tests into DIR and
// checks them through the library (read back exactly, known metrics). Exit 0 on success.
//   step.exr        16x8 "Y": 0 for x < 8, 1 from x = 8 (a vertical edge)
//   step_shift.exr  the same edge one pixel left (1 from x = 7): MAE = 8/128 = 0.0625, leaking
//   small.exr       8x8 (size mismatch with the above)
//   named.exr       16x8 channels visibility, sample_count, std_error
//   nan.exr         16x8 "Y", every pixel NaN (a test that produced nothing)
//   step.png        step.exr as a PNG (beside it: the EXR to use instead)
//   alone/step.png  the same PNG with no EXR beside it
//   render.exr      16x8 visibility, background (msm render's EXR): the step, background in x < 2
//                   with visibility 0
//   truth.exr       16x8 visibility, background, sample_count, std_error (msm reference's
//                   visibility.exr): the same step and background, visibility 1 in the background,
//                   so that only the background differs (MAE 2/16 = 0.125 unmasked, 0 masked)
#include "msm/image/io.h"
#include "msm/image/metrics.h"

#include <cstdio>
#include <exception>
#include <limits>

using namespace msm::image;

namespace {
Image step(int edge) {
  Image im(16, 8, 1);
  for (int y = 0; y < 8; ++y)
    for (int x = 0; x < 16; ++x) im.at(x, y) = x >= edge ? 1.0f : 0.0f;
  return im;
}
} // namespace

int main(int argc, char** argv) {
  if (argc != 2) {
    std::fprintf(stderr, "usage: %s DIR\n", argv[0]);
    return 2;
  }
  try {
    const std::filesystem::path dir = argv[1];
    std::filesystem::create_directories(dir);
    const Image a = step(8), b = step(7);
    Image named(16, 8, {"visibility", "sample_count", "std_error"});
    for (int y = 0; y < 8; ++y)
      for (int x = 0; x < 16; ++x) {
        named.at(x, y, 0) = x >= 8 ? 1.0f : 0.0f;
        named.at(x, y, 1) = 64.0f;
        named.at(x, y, 2) = 0.01f;
      }
    write_exr(dir / "step.exr", a);
    write_exr(dir / "step_shift.exr", b);
    write_exr(dir / "small.exr", Image(8, 8, 1, 0.5f));
    write_exr(dir / "named.exr", named);
    write_exr(dir / "nan.exr", Image(16, 8, 1, std::numeric_limits<float>::quiet_NaN()));
    write_png(dir / "step.png", a);
    std::filesystem::create_directories(dir / "alone");
    write_png(dir / "alone" / "step.png", a);
    Image render(16, 8, {"visibility", "background"});
    Image truth(16, 8, {"visibility", "background", "sample_count", "std_error"});
    for (int y = 0; y < 8; ++y)
      for (int x = 0; x < 16; ++x) {
        const bool background = x < 2;
        render.at(x, y, 0) = background ? 0.0f : a.at(x, y);
        truth.at(x, y, 0) = background ? 1.0f : a.at(x, y);
        render.at(x, y, 1) = truth.at(x, y, 1) = background ? 1.0f : 0.0f;
        truth.at(x, y, 2) = 16.0f;
      }
    write_exr(dir / "render.exr", render);
    write_exr(dir / "truth.exr", truth);
    if (!(read_image(dir / "step.exr") == a) || !(read_image(dir / "named.exr") == named)) {
      std::fprintf(stderr, "read back differs\n");
      return 1;
    }
    const Metrics m = compute_metrics(read_image(dir / "step_shift.exr"), read_image(dir / "step.exr"));
    if (m.mae != 0.0625 || m.light_leaking != 0.0625 || m.over_darkening != 0.0) {
      std::fprintf(stderr, "unexpected metrics:\n%s", format_metrics(m).c_str());
      return 1;
    }
    return 0;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "error: %s\n", e.what());
    return 1;
  }
}
