// The frame graph: a frame is the passes of its recipe (recipes.cpp), each declaring in reflect()
// which images it creates, reads and modifies, and in which state (layout, stages, accesses) it
// uses them; execute() only records its own work. From the declarations the graph
//  - orders the passes (a pass after the creator of everything it uses; the modifiers of an image
//    in recipe order; readers after the last modifier: they see the final image),
//  - refuses a frame whose pass uses an image no pass creates (and that is not imported),
//  - allocates the images (usage flags from the declared uses, format features checked) and keeps
//    them while the frame's configuration stays the same,
//  - places the barriers and layout transitions between passes, and leaves the frame's outputs
//    ready for a transfer (readback).
// In the spirit of Falcor's RenderPass::reflect()/execute(). Images are 2D arrays with one layer per
// light of the frame (FrameConfig::lights); passes that work per light address layer views.
#pragma once

#include "msm/render/frame.h"
#include "msm/render/renderer.h"
#include "msm/vk/vk.h"

#include <map>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

namespace msm::gpu {
class SatBuilder;
}

namespace msm::render {

struct GpuScene;
struct FrameConfig;
class ProgramCache;

// How a pass uses an image during its execution.
struct ImageState {
  VkImageLayout layout = VK_IMAGE_LAYOUT_UNDEFINED;
  VkPipelineStageFlags2 stages = VK_PIPELINE_STAGE_2_NONE;
  VkAccessFlags2 access = VK_ACCESS_2_NONE;
  bool writes() const;
};

namespace use {
// Rendered into (depth test and write; cleared or loaded).
ImageState depth_attachment();
// Rendered into (written, or loaded and blended), in the attachment layout or in GENERAL (the moment
// images, which compute passes also write).
ImageState color_attachment();
ImageState color_attachment_general();
// Read through a sampler.
ImageState sampled(VkPipelineStageFlags2 stages);
// Read and written as storage images (and sampled) by compute shaders, in GENERAL.
ImageState compute_general();
ImageState transfer_source();
ImageState transfer_destination();
} // namespace use

// A transient image of the frame: created by one pass, 2D array with `layers` layers.
struct ImageSpec {
  VkFormat format = VK_FORMAT_UNDEFINED;
  uint32_t width = 0, height = 0;
  uint32_t mips = 1, layers = 1;
  VkSampleCountFlagBits samples = VK_SAMPLE_COUNT_1_BIT;
  VkImageUsageFlags extra_usage = 0; // beyond what the declared uses need (e.g. readback)
  bool operator==(const ImageSpec&) const = default;
};

// What reflect() declares.
class PassBuilder {
 public:
  // A new image, written first by this pass (its earlier contents do not matter).
  void create(std::string name, const ImageSpec& spec, ImageState state);
  // Read only, as another pass (or the host: an imported image) left it.
  void read(std::string name, ImageState state);
  // Read and written in place.
  void modify(std::string name, ImageState state);
  // An image only this pass uses (between its own dispatches); the pass places its barriers,
  // starting from UNDEFINED each frame.
  void scratch(std::string name, const ImageSpec& spec);
  // The pass's own barriers leave `name` in this state (not the one it was declared with).
  void leaves(std::string name, ImageState state);
  // A state the pass puts `name` in between its own barriers (counts for the image's usage flags
  // only; e.g. the mips being written by blits).
  void internally(std::string name, ImageState state);

  enum class Kind { create, read, modify, scratch, internal };
  struct Use {
    std::string name;
    Kind kind;
    ImageState state;
    std::optional<ImageState> end;
    ImageSpec spec; // create, scratch
  };
  const std::vector<Use>& uses() const { return uses_; }

 private:
  std::vector<Use> uses_;
};

class FrameGraph;

// The frame-wide resources a pass records with (host-written before the frame is submitted).
struct FrameResources {
  const GpuScene& scene;
  const vk::Buffer& uniforms;                // FrameUniforms
  const vk::Buffer& lights;                  // LightUniforms[config.lights]
  std::span<const LightUniforms> light_data; // what `lights` holds
  const vk::Image& blue_noise;               // 64 layers of 64² RG8 (blue_noise.h)
  const vk::Sampler& point_sampler;
  const vk::Sampler& linear_sampler;
  glm::vec3 camera_position{0.0f};
  ScatteringPush scattering{};                 // the camera rays of the scattering pass and the background
  const vk::Buffer* rectification = nullptr;   // RectificationUniforms per light (render/rectification_uniforms.h)
  const vk::Sampler* repeat_sampler = nullptr; // linear, repeat: the prefix sums (v wraps on the circle)
  const vk::Buffer* soft_clamps = nullptr;     // two uints: soft lookups unclamped, clamped (soft_clamps.glsl)
};

// An allocated image and its views: the whole array (2D_ARRAY, every mip: for the shading), and per
// layer all mips and mip 0 alone (2D: for the passes that work per light).
struct GraphImage {
  vk::Image image;
  vk::ImageView array_view;
  vk::ImageView array_mip0_view; // images with mips: every layer's mip 0 (a storage target)
  std::vector<vk::ImageView> layer_views, layer_mip0_views;
  std::vector<vk::ImageView> layer_mip1_views; // images with mips: mip 1 alone (a storage target)
  ImageSpec spec;
};

struct PassContext {
  const vk::Context& ctx;
  VkCommandBuffer cmd;
  vk::GpuTimer& timer;
  const FrameGraph& graph;
  const FrameResources& frame;
  const FrameConfig& config;
  const GraphImage& image(std::string_view name) const;
  // Timer scope of one light's share of a pass, "<pass>#<light>", only with several lights.
  void begin_light(std::string_view pass, int light) const;
  void end_light() const;
};

// What passes build their pipelines from, once per frame configuration (the renderer's caches).
struct PassResources {
  ProgramCache& programs;
  const gpu::SatBuilder& sat_builder;
};

class Pass {
 public:
  virtual ~Pass() = default;
  // The pass's name: its GPU timer scope and its name in `msm techniques --passes`.
  virtual std::string_view name() const = 0;
  // Declares the images (needs no device: recipes are listed without one).
  virtual void reflect(PassBuilder& builder) const = 0;
  // Builds (or finds) the pipelines; called once the graph has accepted the frame.
  virtual void prepare(const PassResources& resources) {}
  virtual void execute(const PassContext& context) const = 0;
};

// The order the frame graph runs `passes` in (indices into it), after the checks listed at
// FrameGraph's constructor (which throws the same errors); needs no device.
std::vector<size_t> order_passes(const std::vector<std::unique_ptr<Pass>>& passes,
                                 const std::vector<std::string>& imported, const std::vector<std::string>& outputs);

class FrameGraph {
 public:
  // Orders and checks the passes and allocates their images. `imported`: names the passes may read
  // without a producer (resources the renderer owns); `outputs`: images left in TRANSFER_SRC for
  // readback after the frame. Throws RenderError naming the pass and the image where an input has no
  // producer, two passes create one image, the order has a cycle, or the device lacks a format
  // feature an image's uses need.
  FrameGraph(const vk::Context& ctx, std::vector<std::unique_ptr<Pass>> passes, std::vector<std::string> imported,
             std::vector<std::string> outputs, const PassResources& resources);
  ~FrameGraph();
  FrameGraph(const FrameGraph&) = delete;
  FrameGraph& operator=(const FrameGraph&) = delete;

  // Records every pass in order with the barriers between them, each in its timer scope; with
  // `stop_after`, only up to that pass (and no output transitions).
  void record(VkCommandBuffer cmd, vk::GpuTimer& timer, const FrameResources& frame, const FrameConfig& config,
              std::optional<std::string_view> stop_after = std::nullopt) const;

  // The passes in execution order.
  std::vector<std::string_view> pass_names() const;
  bool has_image(std::string_view name) const;
  // Throws std::out_of_range for an unknown name.
  const GraphImage& image(std::string_view name) const;
  // The layout `name` is in after the last record() (for readbacks).
  VkImageLayout layout_after_record(std::string_view name) const;

 private:
  struct Node;
  const vk::Context& ctx_;
  std::vector<Node> nodes_; // in execution order
  std::vector<std::string> imported_, outputs_;
  std::map<std::string, GraphImage, std::less<>> images_;
  mutable std::map<std::string, VkImageLayout, std::less<>> final_layouts_;
};

} // namespace msm::render
