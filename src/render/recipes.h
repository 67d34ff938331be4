// A technique is a recipe of passes: the list below, built from the frame's configuration, is
// all that distinguishes one technique's frame from another's. The frame graph orders the passes
// and connects them by the images they declare (frame_graph.h).
#pragma once

#include "frame_config.h"
#include "frame_graph.h"

#include <memory>
#include <string>
#include <vector>

namespace msm::render {

std::vector<std::unique_ptr<Pass>> recipe(const FrameConfig& config);

// The images the frame hands back (left ready for a transfer after the frame).
std::vector<std::string> frame_outputs(const FrameConfig& config);
std::vector<std::string> frame_outputs(); // of the shadow techniques

// Whether a technique is shaded deferred unless the settings say otherwise
// (RenderSettings::deferred_shading): the per-pixel filters, whose cost then follows visible pixels.
bool default_deferred_shading(const Technique& technique);
// Whether it can be: the depth-based and soft techniques (the others' lookups are one filtered fetch,
// and the scattering pass composites the forward radiance).
bool supports_deferred_shading(const Technique& technique);

} // namespace msm::render
