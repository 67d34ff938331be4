// `msm render --probe-rotation-speed DEG --frames K`: a frame sequence of a scene lit by a light
// probe, the probe turned by DEG about +Y each frame and split into its area lights again on the
// device each frame (msm::probe::DeviceProbe), with per-frame timings.
#pragma once

#include "render_common.h"

#include <string>
#include <vector>

namespace msm::tool {

struct ProbeFrames {
  int frames = 1;
  float rotation_speed_deg = 0.0f; // per frame
};

// UsageError unless the scene has a probe and the options are in range (before any output exists).
void check_probe_frames(const scene::Scene& scene, const ProbeFrames& options);

// Renders every technique over the frames: per frame the probe pipeline (one submission, its lights
// read back for the renderer, which fits their shadow frusta on the CPU), then the frame; writes
// <out>/<technique>-frame<k>.{png,exr,json} and <out>/probe-frames.json (per-frame timings), and
// prints a line per frame.
void render_probe_frames(const vk::Context& ctx, render::Renderer& renderer, const scene::Scene& scene,
                         const FrameOptions& frame, const std::vector<std::string>& techniques, const std::string& out,
                         const ProbeFrames& options);

} // namespace msm::tool
