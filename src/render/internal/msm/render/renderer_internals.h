// The renderer's hooks for its tests and for msm bench, outside the installed API: this header is
// on msm::render's include path in the build tree only (src/render/CMakeLists.txt) and is not
// installed.
#pragma once

#include "msm/render/renderer.h"

#include <cstddef>
#include <cstdint>
#include <vector>

namespace msm::render {

// What tests compare against the CPU: the depth samples and the resolved moment image (before
// the blur), read back when requested.
struct Intermediates {
  std::vector<float> depth_samples;  // shadow_size² x msaa, sample-major per texel, row-major
  image::Image moments;              // resolve output of image 0 (as stored: UNORM/half/float);
                                     // with the one-pass filter: its (filtered, encoded) output
  std::vector<std::uint32_t> packed; // R32_UINT maps (msm-nl32): the texels as stored
  image::Image moments1;             // of image 1 (6MSM), else empty
  image::Image filtered;             // image 0 after blur (mip 0)
};

struct RendererInternals {
  // The frame of Renderer::render with the intermediates read back.
  static RenderResult render(Renderer& renderer, const RenderSettings& settings, Intermediates& intermediates) {
    return renderer.render(settings, &intermediates);
  }
  // The frame cut after its first `passes` passes (Renderer::submit_frame_prefix).
  static void submit_frame_prefix(Renderer& renderer, const RenderSettings& settings, std::size_t passes) {
    renderer.submit_frame_prefix(settings, passes);
  }
};

} // namespace msm::render
