#include "pass.h"

#include "msm/techniques.h"

#include <fmt/format.h>

namespace msm::render {
namespace {

// Adjacent columns per thread of one_pass_filter.glsl: a workgroup of 32 threads makes strips of
// 32 kOnePassColumns x kOnePassStripH texels.
constexpr int kOnePassColumns = 4;
constexpr int kOnePassStripH = 128;

const vk::Program& one_pass_program(ProgramCache& programs, const FrameConfig& config) {
  const vk::Context& ctx = programs.context();
  int radius = config.taps / 2;
  // Four resolved rows of 32 kOnePassColumns + 2R texels, four floats each (one_pass_filter.glsl).
  uint32_t shared = uint32_t(4 * (32 * kOnePassColumns + 2 * radius) * 16);
  if (shared > ctx.properties().limits.maxComputeSharedMemorySize)
    throw RenderError(fmt::format("the one-pass filter with {} taps needs {} bytes of shared memory; {} has {}",
                                  config.taps, shared, ctx.info().name,
                                  ctx.properties().limits.maxComputeSharedMemorySize));
  // The 32-bit map packs its texel into one integer: its own shader (the others store a vec4).
  bool nl32 = config.technique->formats[0] == TexelFormat::r32_uint;
  std::string shader =
      std::string(nl32 ? "one_pass_filter_nl32" : "one_pass_filter") + (config.msaa == 1 ? "_1x.comp" : ".comp");
  return programs.compute(shader,
                          vk::bindings_at({{MSM_BINDING_FRAME, vk::Binding::uniform_buffer},
                                           {MSM_BINDING_ONE_PASS_DEPTH, vk::Binding::sampled_image},
                                           {MSM_BINDING_ONE_PASS_TARGET, vk::Binding::storage_image},
                                           {MSM_BINDING_ONE_PASS_LIGHTS, vk::Binding::storage_buffer}}),
                          sizeof(ImagePassPush),
                          {{MSM_SPEC_TECHNIQUE, uint32_t(config.technique->id)},
                           {MSM_SPEC_FILTER_RADIUS, uint32_t(radius)},
                           {MSM_SPEC_FILTER_COLUMNS, uint32_t(kOnePassColumns)},
                           {MSM_SPEC_FILTER_SAMPLES, uint32_t(config.msaa)},
                           {MSM_SPEC_CASCADES, config.cascades > 1 ? 1u : 0u}});
}

} // namespace

void OnePassFilterPass::prepare(const PassResources& r) { program_ = &one_pass_program(r.programs, config_); }

void OnePassFilterPass::reflect(PassBuilder& b) const {
  b.read(kShadowDepth, use::sampled(VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT));
  b.create(moment_image(0, 0), moment_image_spec(config_, 0), use::compute_general());
}

void OnePassFilterPass::execute(const PassContext& c) const {
  uint32_t size = uint32_t(config_.shadow_size);
  const GraphImage& depth = c.image(kShadowDepth);
  const GraphImage& moments = c.image(moment_image(0, 0));
  for (int l = 0; l < config_.lights; ++l) {
    c.begin_light(name(), l);
    vk::dispatch(
        c.cmd, *program_, vk::group_count(size, 32 * kOnePassColumns), vk::group_count(size, kOnePassStripH), 1,
        {{MSM_BINDING_FRAME, vk::Descriptor(c.frame.uniforms)},
         {MSM_BINDING_ONE_PASS_DEPTH, vk::Descriptor(depth.layer_views[size_t(l)],
                                                     VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL, c.frame.point_sampler)},
         {MSM_BINDING_ONE_PASS_TARGET, vk::Descriptor(moments.layer_mip0_views[size_t(l)], VK_IMAGE_LAYOUT_GENERAL)},
         {MSM_BINDING_ONE_PASS_LIGHTS, vk::Descriptor(c.frame.lights)}},
        ImagePassPush{glm::ivec4(int(size), int(size), 0, l)});
    c.end_light();
  }
}

} // namespace msm::render
