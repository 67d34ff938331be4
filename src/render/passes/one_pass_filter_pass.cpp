#include "pass.h"

#include "msm/techniques.h"

#include <fmt/format.h>

namespace msm::render {

const PassDecl& OnePassFilterPass::decl() {
  static const PassDecl d{
      "one_pass_filter", {"shadow_depth", "frame.filter_weights", "frame.technique_params"}, {"moments"}};
  return d;
}

namespace {

vk::Program one_pass_program(const vk::Context& ctx, const Technique& technique, int msaa, int taps) {
  int radius = taps / 2;
  // The tile of resolved moments: (32 + 2R) x (16 + 2R) texels of four floats (one_pass_filter.glsl).
  uint32_t shared = uint32_t((32 + 2 * radius) * (16 + 2 * radius) * 16);
  if (shared > ctx.properties().limits.maxComputeSharedMemorySize)
    throw RenderError(fmt::format("the one-pass filter with {} taps needs {} bytes of shared memory; {} has {}", taps,
                                  shared, ctx.info().name, ctx.properties().limits.maxComputeSharedMemorySize));
  bool nl32 = technique.id == MSM_TECH_NL32;
  std::string shader =
      std::string(nl32 ? "one_pass_filter_nl32" : "one_pass_filter") + (msaa == 1 ? "_1x.comp" : ".comp");
  return vk::create_program(ctx, shader,
                            {vk::Binding::uniform_buffer, vk::Binding::sampled_image, vk::Binding::storage_image},
                            sizeof(ImagePassPush), {{0, uint32_t(technique.id)}, {1, uint32_t(radius)}});
}

} // namespace

OnePassFilterPass::OnePassFilterPass(const vk::Context& ctx, const Technique& technique, int msaa, int taps)
    : program_(one_pass_program(ctx, technique, msaa, taps)) {}

void OnePassFilterPass::execute(FrameContext& f) const {
  PassScope scope(f, decl());
  const FrameTargets& t = f.targets;
  vk::pipeline_barrier(f.cmd, vk::image_barrier(t.moments[0].handle(), VK_IMAGE_ASPECT_COLOR_BIT,
                                                VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT, 0, VK_IMAGE_LAYOUT_UNDEFINED,
                                                VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT,
                                                VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT, VK_IMAGE_LAYOUT_GENERAL, 0, 1));
  uint32_t size = uint32_t(t.config.shadow_size);
  vk::dispatch(f.cmd, program_, vk::group_count(size, 32), vk::group_count(size, 16), 1,
               {vk::Descriptor(f.uniforms),
                vk::Descriptor(t.shadow_depth.view(), VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL, t.point_sampler),
                vk::Descriptor(t.moments_mip0[0], VK_IMAGE_LAYOUT_GENERAL)},
               ImagePassPush{glm::ivec4(int(size), int(size), 0, 0)});
  vk::pipeline_barrier(
      f.cmd, vk::memory_barrier(VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT, VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT,
                                VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT | VK_PIPELINE_STAGE_2_FRAGMENT_SHADER_BIT |
                                    VK_PIPELINE_STAGE_2_TRANSFER_BIT,
                                VK_ACCESS_2_SHADER_SAMPLED_READ_BIT | VK_ACCESS_2_TRANSFER_READ_BIT));
}

} // namespace msm::render
