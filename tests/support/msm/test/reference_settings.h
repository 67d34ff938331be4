// The ray tracer's settings as the tests state them: an effect at an image size and a number of
// samples per pixel, every other setting at its default (the caller changes what its test is about).
#pragma once
#include "msm/reference/reference.h"

namespace msm::test {

inline reference::Settings reference_settings(reference::Effect effect, int width, int height, int samples) {
  reference::Settings s;
  s.effect = effect;
  s.width = width;
  s.height = height;
  s.samples = samples;
  return s;
}

} // namespace msm::test
