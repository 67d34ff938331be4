// `msm bench --probe FILE|sky`: GPU time of the light-probe pipeline (msm::probe::DeviceProbe)
// against the cube map's face size and the light count (Kneiphof §6 reports the tables growing with
// the face area and the cut with log N).
#pragma once

#include "render_common.h"

#include <string>
#include <vector>

namespace msm::tool {

struct ProbeBench {
  std::string probe;                                // an equirectangular EXR, or "sky"
  std::vector<int> sizes = {64, 128, 256, 512};     // texels per face side
  std::vector<int> lights = {16, 32, 64, 128, 256}; // regions of the cut
};

// Validates (UsageError), then times `frames` runs after `warmup` per size and light count and
// prints a markdown table (and writes JSON where json is not empty).
void bench_probe(const ProbeBench& options, const std::string& device, int frames, int warmup, const std::string& json,
                 const std::string& markdown);

} // namespace msm::tool
