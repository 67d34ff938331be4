#include "program_cache.h"

#include <fmt/format.h>
#include <fmt/ranges.h>

namespace msm::render {
namespace {

std::string key_of(const std::vector<vk::Binding>& bindings, const std::vector<vk::SpecConstant>& constants) {
  std::string key = " bindings";
  for (vk::Binding b : bindings) key += fmt::format(" {}", int(b));
  key += " constants";
  for (const vk::SpecConstant& c : constants) key += fmt::format(" {}={}", c.id, c.value);
  return key;
}

} // namespace

const vk::Program& ProgramCache::compute(const std::string& shader, const std::vector<vk::Binding>& bindings,
                                         uint32_t push_constant_size, const std::vector<vk::SpecConstant>& constants) {
  std::string key = fmt::format("compute {} push {}", shader, push_constant_size) + key_of(bindings, constants);
  auto& slot = programs_[key];
  if (!slot) {
    std::span<const uint32_t> words = vk::embedded_shader(shader);
    slot =
        std::make_unique<vk::Program>(vk::create_program(ctx_, words, shader, bindings, push_constant_size, constants));
  }
  return *slot;
}

const vk::Program& ProgramCache::graphics(const vk::GraphicsDesc& d) {
  std::string key = fmt::format("graphics {} {} {} push {} stride {} samples {} depth {} compare {} write {} clamp {} "
                                "bias {} blend {}",
                                d.name, d.vertex_shader, d.fragment_shader, d.push_constant_size, d.vertex_stride,
                                int(d.samples), int(d.depth_format), int(d.depth_compare), d.depth_write, d.depth_clamp,
                                d.depth_bias, d.alpha_blend) +
                    key_of(d.bindings, d.constants);
  for (const vk::VertexAttribute& a : d.attributes)
    key += fmt::format(" attr {}:{}:{}", a.location, int(a.format), a.offset);
  for (VkFormat f : d.color_formats) key += fmt::format(" colour {}", int(f));
  for (VkColorComponentFlags m : d.color_write_masks) key += fmt::format(" mask {}", m);
  auto& slot = programs_[key];
  if (!slot) slot = std::make_unique<vk::Program>(vk::create_graphics_program(ctx_, d));
  return *slot;
}

} // namespace msm::render
