// `msm render --frames K [--probe-rotation-speed DEG]`: a frame sequence of a dynamic scene, with
// per-frame timings. A scene lit by a light probe has the probe turned by DEG about +Y each frame
// and split into its area lights again on the device each frame (msm::probe::DeviceProbe); a scene
// with animated objects (their "motion") has them moved each frame (scene::at_frame,
// Renderer::move_objects). Both at once where the scene has both.
#pragma once

#include "render_common.h"

#include <string>
#include <vector>

namespace msm::tool {

struct Frames {
  int frames = 1;
  float rotation_speed_deg = 0.0f; // of the probe, per frame
};

// UsageError unless the scene has a probe or animated objects (a probe where the probe is to turn)
// and the options are in range (before any output exists).
void check_frames(const scene::Scene& scene, const Frames& options);

// Renders every technique over the frames: per frame the probe pipeline (one submission, its lights
// read back for the renderer, which fits their shadow frusta on the CPU) and the objects' motion
// (moved on the host, their vertices uploaded), then the frame; writes
// <out>/<technique>-frame<k>.{png,exr,json} and <out>/frames.json (per-frame timings), and prints a
// line per frame.
void render_frames(const vk::Context& ctx, render::Renderer& renderer, const scene::Scene& scene,
                   const FrameOptions& frame, const std::vector<std::string>& techniques, const std::string& out,
                   const Frames& options);

} // namespace msm::tool
