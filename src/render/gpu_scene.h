// The scene on the device: one interleaved vertex buffer and one index buffer for all objects
// (world space, as the loader flattens them), one draw range per object, and the albedo textures.
#pragma once

#include "msm/render/frame.h"
#include "msm/scene/scene.h"
#include "msm/vk/vk.h"

#include <cstdint>
#include <vector>

namespace msm::render {

struct Vertex {
  glm::vec3 position;
  glm::vec3 normal;
  glm::vec2 uv;
};
static_assert(sizeof(Vertex) == 32, "the pipelines' vertex stride and attribute offsets assume this layout");

struct Draw {
  uint32_t first_index = 0, index_count = 0;
  int texture = -1;      // into GpuScene::textures, -1: none (the white texture is bound)
  ObjectPush push{};     // albedo, opacity, flags
  bool double_sided = false;
};

struct GpuScene {
  vk::Buffer vertices, indices;
  std::vector<Draw> draws;
  std::vector<vk::Image> textures;  // RGBA8 sRGB
  vk::Image white;                  // 1x1, for draws without a texture
  vk::Sampler texture_sampler;      // linear, repeat

  GpuScene(const vk::Context& ctx, const scene::Scene& scene);
};

} // namespace msm::render
