// Graphics programs: a pipeline for dynamic rendering (no render pass objects) from embedded
// vertex and fragment shaders, with push descriptors like the compute programs (program.h), and
// the few helpers a headless renderer needs around it.
//
//   Program p = create_graphics_program(ctx, {.name = "shading", .vertex_shader = "shading.vert", ...});
//   begin_rendering(cmd, extent, {{colorView, clear}}, {depthView, depthClear});
//   set_viewport_scissor(cmd, extent);
//   bind_program(cmd, p, {frameUniforms, texture}, push);
//   vkCmdDrawIndexed(...);
//   vkCmdEndRendering(cmd);
#pragma once

#include "msm/vk/program.h"

#include <optional>
#include <string>
#include <vector>

namespace msm::vk {

struct VertexAttribute {
  uint32_t location = 0;
  VkFormat format = VK_FORMAT_R32G32B32_SFLOAT;
  uint32_t offset = 0; // bytes into the vertex
};

struct GraphicsDesc {
  std::string name;                // for messages and debuggers
  std::string vertex_shader;       // embedded shader name (shaders.h)
  std::string fragment_shader;     // empty: no fragment stage (depth-only passes)
  std::vector<Binding> bindings;   // set 0, pushed, visible to the vertex and fragment stages
  uint32_t push_constant_size = 0; // vertex and fragment stages
  uint32_t vertex_stride = 0;      // one interleaved vertex buffer at binding 0 (0: no vertex input)
  std::vector<VertexAttribute> attributes;
  std::vector<VkFormat> color_formats; // one per color attachment, in location order
  VkFormat depth_format = VK_FORMAT_UNDEFINED;
  VkSampleCountFlagBits samples = VK_SAMPLE_COUNT_1_BIT;
  VkCompareOp depth_compare = VK_COMPARE_OP_LESS;
  bool depth_write = true;
  // Depth clamp instead of clipping at the near/far planes (where the device supports it):
  // shadow casters outside a light frustum's depth range still cast.
  bool depth_clamp = false;
  // Dynamic depth bias (vkCmdSetDepthBias) is enabled: set it before drawing.
  bool depth_bias = false;
  // "Over" blending on every colour attachment: rgb' = src.rgb * src.a + dst.rgb * (1 - src.a)
  // (alpha' likewise); the factor is the fragment's output alpha, so attachments without an
  // alpha channel (RG targets) blend too. Requires the formats' blend feature.
  bool alpha_blend = false;
  // Per colour attachment (empty: all channels of every attachment).
  std::vector<VkColorComponentFlags> color_write_masks;
  std::vector<SpecConstant> constants; // extra specialization constants for both stages
};

// Triangle lists, counter-clockwise front faces, fill mode; dynamic viewport, scissor and cull
// mode (vkCmdSetCullMode: set before drawing), plus depth bias with desc.depthBias.
// Preconditions (std::invalid_argument otherwise): a vertex shader; at least one attachment;
// the formats support attachment use with these samples (checked through the format properties
// and sample limits, so that unsupported MSAA is a clear error rather than a validation message).
Program create_graphics_program(const Context& ctx, const GraphicsDesc& desc);

struct ColorAttachment {
  VkImageView view = VK_NULL_HANDLE;
  VkClearColorValue clear{};
  VkImageView resolve = VK_NULL_HANDLE; // single-sample image to average into, or null
  bool load = false;                    // keep the contents instead of clearing
  VkImageLayout layout = VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL;
};

struct DepthAttachment {
  VkImageView view = VK_NULL_HANDLE;
  float clear = 1.0f;
  bool load = false; // keep the contents instead of clearing
  VkImageLayout layout = VK_IMAGE_LAYOUT_DEPTH_ATTACHMENT_OPTIMAL;
};

// vkCmdBeginRendering over the whole extent: every attachment cleared (or loaded) and stored,
// in the layout each attachment names (default COLOR_ / DEPTH_ATTACHMENT_OPTIMAL).
void begin_rendering(VkCommandBuffer cmd, VkExtent2D extent, std::span<const ColorAttachment> colors,
                     std::optional<DepthAttachment> depth = std::nullopt);
inline void begin_rendering(VkCommandBuffer cmd, VkExtent2D extent, std::initializer_list<ColorAttachment> colors,
                            std::optional<DepthAttachment> depth = std::nullopt) {
  begin_rendering(cmd, extent, std::span<const ColorAttachment>(colors.begin(), colors.size()), depth);
}

// Viewport (0,0)-(extent), depth [0,1], and the same scissor.
void set_viewport_scissor(VkCommandBuffer cmd, VkExtent2D extent);

// Whether the format can be a depth/color attachment with this many samples on the device.
bool supports_attachment(const Context& ctx, VkFormat format, VkSampleCountFlagBits samples);

} // namespace msm::vk
