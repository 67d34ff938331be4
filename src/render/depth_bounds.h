// Sample-distribution shadow maps' depth bounds (Lauritzen et al. 2011; MJP's Shadows sample,
// Babylon's autoCalcDepthBounds): the smallest and largest view depth of the surfaces the camera
// shows, from a depth pre-pass of the scene and a compute reduction of its depth buffer, read back
// for scene::fit_cascades (CascadeOptions::depth_range) to split. The readback stalls: a headless
// renderer waits for it before the frame's shadow maps; an engine would split with the previous
// frame's bounds instead (docs/techniques.md, "Cascades").
#pragma once

#include "gpu_scene.h"
#include "program_cache.h"

#include "msm/scene/scene.h"
#include "msm/vk/vk.h"

#include <vector>

namespace msm::render {

struct DepthBounds {
  bool any = false;           // some pixel shows a surface; else the rest is unset
  float min_depth = 1.0f;     // the depth buffer's smallest and largest value below the
  float max_depth = 0.0f;     // cleared 1 ([0, 1], 0 at the near plane)
  glm::dvec2 view_depth{0.0}; // the camera's view depths of the two
  double ms = 0.0;            // GPU time of the pre-pass and the reduction (0: no timestamps)
  std::vector<float> depth;   // the depth buffer, row by row (where asked for)
};

// The camera's view depth of depth-buffer value `depth` under the perspective `projection`
// (Vulkan clip space, depth [0, 1]): clip z = P22 z + P32 and w = -z give -z = P32 / (depth + P22).
double view_depth_of(const glm::mat4& projection, double depth);

class DepthBoundsReducer {
 public:
  DepthBoundsReducer(const vk::Context& ctx, ProgramCache& programs);
  // The pre-pass (the scene's opaque and alpha-tested draws, culled as the shading culls them, at
  // width x height, one sample a pixel, the camera's projection at that aspect) and the reduction,
  // submitted and waited for; with keep_depth the depth buffer is read back too (tests).
  DepthBounds measure(const GpuScene& scene, const scene::Camera& camera, int width, int height,
                      bool keep_depth = false);

 private:
  void record(VkCommandBuffer cmd, const GpuScene& scene, const glm::mat4& view_projection);
  const vk::Context& ctx_;
  const vk::Program &opaque_, &masked_, &reduce_;
  vk::Image depth_; // D32, recreated when the size changes
  vk::Buffer result_;
  vk::Sampler sampler_;
  vk::GpuTimer timer_;
};

} // namespace msm::render
