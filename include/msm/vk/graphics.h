// Graphics programs: a pipeline for dynamic rendering (no render pass objects) from embedded
// vertex and fragment shaders, with push descriptors like the compute programs (program.h), and
// the few helpers a headless renderer needs around it.
//
//   Program p = createGraphicsProgram(ctx, {.name = "shading", .vertexShader = "shading.vert", ...});
//   beginRendering(cmd, extent, {{colorView, clear}}, {depthView, depthClear});
//   setViewportScissor(cmd, extent);
//   bindProgram(cmd, p, {frameUniforms, texture}, push);
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
  std::string name;            // for messages and debuggers
  std::string vertexShader;    // embedded shader name (shaders.h)
  std::string fragmentShader;  // empty: no fragment stage (depth-only passes)
  std::vector<Binding> bindings; // set 0, pushed, visible to the vertex and fragment stages
  uint32_t pushConstantSize = 0; // vertex and fragment stages
  uint32_t vertexStride = 0;     // one interleaved vertex buffer at binding 0 (0: no vertex input)
  std::vector<VertexAttribute> attributes;
  std::vector<VkFormat> colorFormats; // one per color attachment, in location order
  VkFormat depthFormat = VK_FORMAT_UNDEFINED;
  VkSampleCountFlagBits samples = VK_SAMPLE_COUNT_1_BIT;
  VkCompareOp depthCompare = VK_COMPARE_OP_LESS;
  bool depthWrite = true;
  // Depth clamp instead of clipping at the near/far planes (where the device supports it):
  // shadow casters outside a light frustum's depth range still cast.
  bool depthClamp = false;
  // Dynamic depth bias (vkCmdSetDepthBias) is enabled: set it before drawing.
  bool depthBias = false;
  // "Over" blending on every colour attachment: rgb' = src.rgb * src.a + dst.rgb * (1 - src.a)
  // (alpha' likewise); the factor is the fragment's output alpha, so attachments without an
  // alpha channel (RG targets) blend too. Requires the formats' blend feature.
  bool alphaBlend = false;
  // Per colour attachment (empty: all channels of every attachment).
  std::vector<VkColorComponentFlags> colorWriteMasks;
  std::vector<SpecConstant> constants; // extra specialization constants for both stages
};

// Triangle lists, counter-clockwise front faces, fill mode; dynamic viewport, scissor and cull
// mode (vkCmdSetCullMode: set before drawing), plus depth bias with desc.depthBias.
// Preconditions (std::invalid_argument otherwise): a vertex shader; at least one attachment;
// the formats support attachment use with these samples (checked through the format properties
// and sample limits, so that unsupported MSAA is a clear error rather than a validation message).
Program createGraphicsProgram(const Context& ctx, const GraphicsDesc& desc);

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
  bool load = false;                    // keep the contents instead of clearing
  VkImageLayout layout = VK_IMAGE_LAYOUT_DEPTH_ATTACHMENT_OPTIMAL;
};

// vkCmdBeginRendering over the whole extent: every attachment cleared (or loaded) and stored,
// in the layout each attachment names (default COLOR_ / DEPTH_ATTACHMENT_OPTIMAL).
void beginRendering(VkCommandBuffer cmd, VkExtent2D extent, std::span<const ColorAttachment> colors,
                    std::optional<DepthAttachment> depth = std::nullopt);
inline void beginRendering(VkCommandBuffer cmd, VkExtent2D extent, std::initializer_list<ColorAttachment> colors,
                           std::optional<DepthAttachment> depth = std::nullopt) {
  beginRendering(cmd, extent, std::span<const ColorAttachment>(colors.begin(), colors.size()), depth);
}

// Viewport (0,0)-(extent), depth [0,1], and the same scissor.
void setViewportScissor(VkCommandBuffer cmd, VkExtent2D extent);

// Whether the format can be a depth/color attachment with this many samples on the device.
bool supportsAttachment(const Context& ctx, VkFormat format, VkSampleCountFlagBits samples);

} // namespace msm::vk
