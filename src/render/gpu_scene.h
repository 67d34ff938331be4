// The scene on the device: one interleaved vertex buffer and one index buffer for all objects
// (world space, as the loader flattens them), one draw range per object, and the albedo textures.
#pragma once

#include "msm/render/frame.h"
#include "msm/render/renderer.h"
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
  uint32_t object = 0; // into scene::Scene::objects
  uint32_t first_index = 0, index_count = 0;
  int texture = -1;         // into GpuScene::textures, -1: none (the white texture is bound)
  int opacity_texture = -1; // into GpuScene::opacity_textures, -1: none
  ObjectPush push{};        // albedo, opacity, flags (z: 1 if the opacity texture is used)
  bool double_sided = false;
  bool masked = false;    // alpha-tested (push.transmission.w: the cutoff)
  glm::vec3 center{0.0f}; // of the object's bounds (sorting for the camera)
};

// RenderError naming the kinds of light of `scene` whose shadows the renderer does not draw (the
// light-kind declaration's `rendered`): refused, not left dark.
void refuse_unrendered_lights(const scene::Scene& scene);

struct GpuScene {
  vk::Buffer vertices, indices;
  std::vector<Draw> draws; // opaque objects, alpha-tested ones included
  // Objects with opacity < 1 or an opacity texture, sorted far to near from the first
  // shadow-map layer's light (along a directional light's travel, by the distance from a spot or
  // point light), each one's triangles too (JCGT §3: blended back to front into the moment shadow
  // map; the lights are fixed, so the order is computed once here).
  std::vector<Draw> translucent;
  std::vector<vk::Image> textures;         // RGBA8 sRGB
  std::vector<vk::Image> opacity_textures; // R8 UNORM: scene::opacity_image of the material
  vk::Image white;                         // 1x1, for draws without a texture
  vk::ImageView white_array;               // the same as a one-layer array (unused array bindings)
  vk::Sampler texture_sampler;             // linear, repeat
  // A probe-lit scene's probe (msm::probe::load_probe of its "probe", as the ray tracer loads it):
  // six layers of RGBA32F radiance, the cube's faces, read by texel as the background (empty
  // without a probe: the sky colour is the background).
  vk::Image probe;

  GpuScene(const vk::Context& ctx, const scene::Scene& scene);
  // The vertices of `scene`, whose objects are this scene's moved (scene::at_frame: the same meshes
  // and materials; Renderer::move_objects checks them object by object), uploaded into the same
  // buffers; the translucent triangles and draws sorted again along the light. RenderError where
  // the total vertex or index counts differ. Between frames.
  void move_objects(const vk::Context& ctx, const scene::Scene& scene);
};

} // namespace msm::render
