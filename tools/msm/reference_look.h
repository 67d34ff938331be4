// The ray tracer's radiance in the renderer's look (ACES after the exposure; where no surface is, the
// renderer's sky, or the probe of a probe-lit scene as traced), so that a reference compares with
// `msm render`'s colour image: `msm reference`'s radiance.png and `msm demo`'s ground-truth panels.
#pragma once

#include "msm/image/image.h"
#include "msm/reference/reference.h"
#include "msm/shading.h"

#include <cmath>

namespace msm::tool {

inline image::Image reference_look(const reference::Result& truth, float exposure) {
  image::Image rgb = image::tone_map(truth.radiance, {std::log2(exposure), image::ToneCurve::aces});
  for (int y = 0; y < rgb.height(); ++y)
    for (int x = 0; x < rgb.width(); ++x)
      if (!truth.probe_background && truth.visibility.at(x, y, 1) > 0.5f) // the "background" channel
        for (int c = 0; c < 3; ++c) rgb.at(x, y, c) = MSM_SKY_RADIANCE[c];
  return rgb;
}

} // namespace msm::tool
