// The copy shaders of shaders/sat_copy.glsl: what any shader moving a table of 16 B
// texels reaches on a device, timed beside the summed-area table schemes by msm_sat_timing and
// checked (every texel copied) by msm_sat_builder_test. Not part of msm::gpu's interface: both
// programs embed the shaders themselves.
#pragma once

#include "msm/vk/vk.h"
#include "shaders/sat_interface.h"

#include <cstdint>
#include <initializer_list>
#include <iterator>
#include <vector>

namespace msm::gpu::sat_copy {

// What the shader reads and writes: two RGBA32_UINT storage images, two storage buffers of uvec4,
// or an RGBA32F sampled image (texelFetch) into an RGBA32_UINT storage image.
enum class Kind { image, buffer, fetch };
// How its invocations cover a width × height table.
enum class Walk { texel, texel4, row, column };

struct Shader {
  const char* file;
  const char* name;
  Kind kind;
  Walk walk;
};
inline constexpr Shader shaders[] = {
    {"sat_copy_image_texel.comp", "image, texel per invocation", Kind::image, Walk::texel},
    {"sat_copy_image_row.comp", "image, row per invocation", Kind::image, Walk::row},
    {"sat_copy_image_column.comp", "image, column per invocation", Kind::image, Walk::column},
    {"sat_copy_fetch_row.comp", "texelFetch → image, row per invocation", Kind::fetch, Walk::row},
    {"sat_copy_buffer_texel.comp", "buffer, texel per invocation", Kind::buffer, Walk::texel},
    {"sat_copy_buffer_texel4.comp", "buffer, 4 texels per invocation", Kind::buffer, Walk::texel4},
    {"sat_copy_buffer_row.comp", "buffer, row per invocation", Kind::buffer, Walk::row},
    {"sat_copy_buffer_column.comp", "buffer, column per invocation", Kind::buffer, Walk::column},
};
inline constexpr int count = int(std::size(shaders));

// The push constants of every sat_*.comp (shaders/sat_interface.h); the copies read the size only.
using Push = SatPush;

inline std::vector<vk::Program> create_programs(const vk::Context& ctx) {
  using B = vk::Binding;
  std::vector<vk::Program> programs;
  for (const Shader& s : shaders) {
    const B source = s.kind == Kind::buffer  ? B::storage_buffer
                     : s.kind == Kind::fetch ? B::sampled_image
                                             : B::storage_image;
    const B destination = s.kind == Kind::buffer ? B::storage_buffer : B::storage_image;
    programs.push_back(vk::create_program(
        ctx, s.file, {{MSM_BINDING_SAT_COPY_SOURCE, source}, {MSM_BINDING_SAT_COPY_DESTINATION, destination}},
        sizeof(Push)));
  }
  return programs;
}

// Records shader i over a width × height table: src → dst (images in GENERAL; the fetch's source
// with its sampler). The caller's barriers order it against what wrote src and what reads dst.
inline void record(VkCommandBuffer cmd, const vk::Program& program, const Shader& s, uint32_t width, uint32_t height,
                   const vk::Descriptor& src, const vk::Descriptor& dst) {
  uint32_t gx = 1, gy = 1;
  switch (s.walk) {
  case Walk::texel: gx = vk::group_count(width, 64), gy = height; break;
  case Walk::texel4: gx = vk::group_count(width, 256), gy = height; break;
  case Walk::row: gx = vk::group_count(height, 64); break;
  case Walk::column: gx = vk::group_count(width, 64); break;
  }
  vk::dispatch(cmd, program, gx, gy, 1, {{MSM_BINDING_SAT_COPY_SOURCE, src}, {MSM_BINDING_SAT_COPY_DESTINATION, dst}},
               Push{glm::ivec2(int(width), int(height)), 0u, 0u});
}

} // namespace msm::gpu::sat_copy
