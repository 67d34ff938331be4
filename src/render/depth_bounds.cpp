#include "depth_bounds.h"

#include "passes/pass.h"

#include "msm/render/bindings.h"
#include "msm/render/frame.h"

#include <bit>
#include <cstring>

namespace msm::render {
namespace {

// The pre-pass's push constants: the draw's (alpha test) and the camera's view-projection.
struct CameraDepthPush {
  ObjectPush object;
  glm::mat4 view_projection;
};
static_assert(sizeof(CameraDepthPush) == 128, "camera_depth.vert's push block");

constexpr VkFormat kDepthFormat = VK_FORMAT_D32_SFLOAT;
constexpr std::uint32_t kInfinityBits = 0x7f800000u;

vk::GraphicsDesc camera_depth_desc(bool masked) {
  vk::GraphicsDesc d{.name = masked ? "camera_depth (alpha-tested)" : "camera_depth",
                     .vertex_shader = "camera_depth.vert",
                     .fragment_shader = masked ? "camera_depth_masked.frag" : "",
                     .push_constant_size = sizeof(CameraDepthPush),
                     .vertex_stride = sizeof(Vertex),
                     .attributes = {{0, VK_FORMAT_R32G32B32_SFLOAT, offsetof(Vertex, position)},
                                    {2, VK_FORMAT_R32G32_SFLOAT, offsetof(Vertex, uv)}},
                     .depth_format = kDepthFormat};
  if (masked) d.bindings = vk::bindings_at({{MSM_BINDING_CAMERA_DEPTH_OPACITY, vk::Binding::sampled_image}});
  return d;
}

} // namespace

double view_depth_of(const glm::mat4& projection, double depth) {
  return double(projection[3][2]) / (depth + double(projection[2][2]));
}

DepthBoundsReducer::DepthBoundsReducer(const vk::Context& ctx, ProgramCache& programs)
    : ctx_(ctx), opaque_(programs.graphics(camera_depth_desc(false))),
      masked_(programs.graphics(camera_depth_desc(true))),
      reduce_(programs.compute("depth_bounds.comp",
                               vk::bindings_at({{MSM_BINDING_DEPTH_BOUNDS_MAP, vk::Binding::sampled_image},
                                                {MSM_BINDING_DEPTH_BOUNDS_RESULT, vk::Binding::storage_buffer}}),
                               sizeof(ImagePassPush))),
      result_(vk::create_buffer(ctx, 2 * sizeof(std::uint32_t), VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, vk::Memory::host)),
      sampler_(vk::create_sampler(ctx, VK_FILTER_NEAREST)), timer_(ctx, 2) {}

void DepthBoundsReducer::record(VkCommandBuffer cmd, const GpuScene& scene, const glm::mat4& view_projection) {
  const VkExtent2D size{depth_.width(), depth_.height()};
  vk::pipeline_barrier(cmd, vk::image_barrier(depth_.handle(), depth_.aspect(), VK_PIPELINE_STAGE_2_NONE, 0,
                                              VK_IMAGE_LAYOUT_UNDEFINED, VK_PIPELINE_STAGE_2_EARLY_FRAGMENT_TESTS_BIT,
                                              VK_ACCESS_2_DEPTH_STENCIL_ATTACHMENT_WRITE_BIT,
                                              VK_IMAGE_LAYOUT_DEPTH_ATTACHMENT_OPTIMAL));
  vk::begin_rendering(cmd, size, {}, vk::DepthAttachment{depth_.view(), 1.0f});
  vk::set_viewport_scissor(cmd, size);
  bind_scene(cmd, scene);
  for (const Draw& d : scene.draws) {
    vkCmdSetCullMode(cmd, d.double_sided ? VK_CULL_MODE_NONE : VK_CULL_MODE_BACK_BIT);
    const CameraDepthPush push{d.push, view_projection};
    if (d.masked) {
      const vk::Image& opacity =
          d.opacity_texture >= 0 ? scene.opacity_textures[size_t(d.opacity_texture)] : scene.white;
      vk::bind_program(
          cmd, masked_,
          {{MSM_BINDING_CAMERA_DEPTH_OPACITY,
            vk::Descriptor(opacity.view(), VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL, scene.texture_sampler)}},
          push);
    } else {
      vk::bind_program(cmd, opaque_, {}, push);
    }
    vkCmdDrawIndexed(cmd, d.index_count, 1, d.first_index, 0, 0);
  }
  vkCmdEndRendering(cmd);
  vk::pipeline_barrier(
      cmd, vk::image_barrier(depth_.handle(), depth_.aspect(), VK_PIPELINE_STAGE_2_LATE_FRAGMENT_TESTS_BIT,
                             VK_ACCESS_2_DEPTH_STENCIL_ATTACHMENT_WRITE_BIT, VK_IMAGE_LAYOUT_DEPTH_ATTACHMENT_OPTIMAL,
                             VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT, VK_ACCESS_2_SHADER_SAMPLED_READ_BIT,
                             VK_IMAGE_LAYOUT_DEPTH_READ_ONLY_OPTIMAL));
  vk::dispatch(
      cmd, reduce_, vk::group_count(size.width, 16), vk::group_count(size.height, 16), 1,
      {{MSM_BINDING_DEPTH_BOUNDS_MAP, vk::Descriptor(depth_.view(), VK_IMAGE_LAYOUT_DEPTH_READ_ONLY_OPTIMAL, sampler_)},
       {MSM_BINDING_DEPTH_BOUNDS_RESULT, vk::Descriptor(result_)}},
      ImagePassPush{glm::ivec4(int(size.width), int(size.height), 0, 0)});
}

DepthBounds DepthBoundsReducer::measure(const GpuScene& scene, const scene::Camera& camera, int width, int height,
                                        bool keep_depth) {
  if (!depth_ || int(depth_.width()) != width || int(depth_.height()) != height)
    depth_ = vk::create_image(ctx_, {.width = uint32_t(width),
                                     .height = uint32_t(height),
                                     .format = kDepthFormat,
                                     .usage = VK_IMAGE_USAGE_DEPTH_STENCIL_ATTACHMENT_BIT | VK_IMAGE_USAGE_SAMPLED_BIT |
                                              VK_IMAGE_USAGE_TRANSFER_SRC_BIT});
  const std::uint32_t start[2] = {kInfinityBits, 0u};
  std::memcpy(result_.data(), start, sizeof(start));
  const glm::mat4 projection = camera.projection(float(width) / float(height));
  vk::submit_and_wait(ctx_, [&](VkCommandBuffer cmd) {
    timer_.reset(cmd);
    timer_.begin(cmd, "depth_bounds");
    record(cmd, scene, projection * camera.view());
    timer_.end(cmd);
  });
  DepthBounds b;
  for (const vk::TimerScope& scope : timer_.read().scopes) b.ms += scope.ms();
  const std::span<const std::uint32_t> bits = result_.mapped<const std::uint32_t>();
  b.any = bits[0] != kInfinityBits;
  if (b.any) {
    b.min_depth = std::bit_cast<float>(bits[0]);
    b.max_depth = std::bit_cast<float>(bits[1]);
    b.view_depth = {view_depth_of(projection, b.min_depth), view_depth_of(projection, b.max_depth)};
  }
  if (keep_depth) {
    const std::vector<std::byte> bytes = vk::readback_image(ctx_, depth_, VK_IMAGE_LAYOUT_DEPTH_READ_ONLY_OPTIMAL);
    b.depth.resize(std::size_t(width) * std::size_t(height));
    std::memcpy(b.depth.data(), bytes.data(), b.depth.size() * sizeof(float));
  }
  return b;
}

} // namespace msm::render
