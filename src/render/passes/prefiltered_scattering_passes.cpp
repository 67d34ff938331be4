#include "pass.h"

#include "msm/techniques.h"

#include <span>

namespace msm::render {
namespace {
constexpr VkPipelineStageFlags2 kCompute = VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT;
constexpr VkImageLayout kReadOnly = VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL;
uint32_t size(const FrameConfig& c) { return uint32_t(c.shadow_size); } // the rectified map's side
int representation6(const FrameConfig& c) { return msm_technique_scatter_representation6(c.technique->id); }
// Klehm et al.'s convolution shadow map: 32 coefficients in the layers of one array image.
bool csm(const FrameConfig& c) { return c.technique->scattering == Scattering::prefiltered_csm; }
constexpr uint32_t kCsmLayers = MSM_CSM_MAX_TEXELS;
// Transmittance layers (rectification.h): K prefix sums per light, with K steps Δ_k.
uint32_t layers(const FrameConfig& c) { return uint32_t(c.transmittance_layers); }
// The prefix sums are stored into mip 0 of every layer (App. D.5's mips follow: PrefixSumMipmapPass).
const vk::ImageView& mip0(const GraphImage& g) { return g.spec.mips > 1 ? g.array_mip0_view : g.array_view; }

} // namespace

// The prefix sums' storage formats (JCGT §5.3, §5.4.3): Θ4* in RGBA16; Θ6* in two RGB10A2 (odd,
// even), RGBA16 + RG16 or RGBA32F + RG32F ((odd, even.x), (even.y, even.z)).
std::array<VkFormat, 2> FrameConfig::prefix_sum_formats() const {
  switch (representation6(*this)) {
  case MSM_REP6_UNORM10: return {VK_FORMAT_A2B10G10R10_UNORM_PACK32, VK_FORMAT_A2B10G10R10_UNORM_PACK32};
  case MSM_REP6_UNORM16: return {VK_FORMAT_R16G16B16A16_UNORM, VK_FORMAT_R16G16_UNORM};
  case MSM_REP6_FLOAT: return {VK_FORMAT_R32G32B32A32_SFLOAT, VK_FORMAT_R32G32_SFLOAT};
  default: return {csm(*this) ? VK_FORMAT_R8G8B8A8_UNORM : VK_FORMAT_R16G16B16A16_UNORM, VK_FORMAT_UNDEFINED};
  }
}

bool prefix_sums_have_two_images(const FrameConfig& c) { return representation6(c) >= 0; }

void RectifyPass::prepare(const PassResources& r) {
  bool six = prefix_sums_have_two_images(config_);
  std::string shader = std::string(csm(config_) ? "rectify_csm"
                                   : six        ? "rectify6"
                                                : "rectify") +
                       // Filtered resampling reads the moment map, whatever the depth map's samples.
                       (config_.filtered_resampling ? "_filtered.comp"
                        : config_.msaa == 1         ? "_1x.comp"
                                                    : ".comp");
  std::vector<vk::BindingAt> bindings = {{MSM_BINDING_FRAME, vk::Binding::uniform_buffer},
                                         {MSM_BINDING_RECTIFY_RECTS, vk::Binding::storage_buffer},
                                         {MSM_BINDING_RECTIFY_LIGHTS, vk::Binding::storage_buffer},
                                         {MSM_BINDING_RECTIFY_SOURCE, vk::Binding::sampled_image},
                                         {MSM_BINDING_RECTIFY_TARGET, vk::Binding::storage_image}};
  if (six) bindings.push_back({MSM_BINDING_RECTIFY_TARGET1, vk::Binding::storage_image});
  program_ = &r.programs.compute(shader, vk::bindings_at(bindings), sizeof(ImagePassPush),
                                 {{MSM_RECTIFY_ON_THE_FLY_SPEC_ID, config_.on_the_fly_resampling ? 1u : 0u},
                                  // Spot lights' rectification (rectify.glsl): compiled only where the frame has them.
                                  {MSM_SPEC_SPOT_LIGHTS, config_.spot_lights > 0 ? 1u : 0u}});
}

void RectifyPass::reflect(PassBuilder& b) const {
  // Filtered resampling (§5.2): the blurred, mipmapped moment map; else the depth map.
  b.read(config_.filtered_resampling ? moment_image(0, 0) : std::string(kShadowDepth), use::sampled(kCompute));
  // A layer per light (every light its own rectified map).
  const uint32_t lights = uint32_t(config_.lights);
  ImageSpec spec{
      .format = VK_FORMAT_R32G32B32A32_SFLOAT, .width = size(config_), .height = size(config_), .layers = lights};
  // CSM: eight layers of coefficients in [0,1] per light for 8-bit storage; half floats lose nothing of that.
  if (csm(config_))
    b.create(kRectified,
             {.format = VK_FORMAT_R16G16B16A16_SFLOAT,
              .width = size(config_),
              .height = size(config_),
              .layers = kCsmLayers * lights},
             use::compute_general());
  else
    b.create(kRectified, spec, use::compute_general());
  if (prefix_sums_have_two_images(config_)) b.create(kRectified1, spec, use::compute_general());
}

void RectifyPass::execute(const PassContext& c) const {
  uint32_t groups = vk::group_count(size(config_), 8);
  for (int l = 0; l < config_.lights; ++l) {
    c.begin_light(name(), l);
    const size_t layer = size_t(l);
    std::vector<vk::DescriptorAt> d = {
        {MSM_BINDING_FRAME, vk::Descriptor(c.frame.uniforms)},
        {MSM_BINDING_RECTIFY_RECTS, vk::Descriptor(*c.frame.rectification)},
        {MSM_BINDING_RECTIFY_LIGHTS, vk::Descriptor(c.frame.lights)},
        {MSM_BINDING_RECTIFY_SOURCE,
         config_.filtered_resampling // every mip, trilinear
             ? vk::Descriptor(c.image(moment_image(0, 0)).layer_views[layer], kReadOnly, c.frame.linear_sampler)
             : vk::Descriptor(c.image(kShadowDepth).layer_views[layer], kReadOnly, c.frame.point_sampler)},
        {MSM_BINDING_RECTIFY_TARGET,
         csm(config_) ? vk::Descriptor(c.image(kRectified).array_view, VK_IMAGE_LAYOUT_GENERAL) // layers 8 l + t
                      : vk::Descriptor(c.image(kRectified).layer_views[layer], VK_IMAGE_LAYOUT_GENERAL)}};
    if (prefix_sums_have_two_images(config_))
      d.push_back({MSM_BINDING_RECTIFY_TARGET1,
                   vk::Descriptor(c.image(kRectified1).layer_views[layer], VK_IMAGE_LAYOUT_GENERAL)});
    const ImagePassPush push{glm::ivec4(config_.shadow_size, config_.shadow_size, l, 0)};
    vk::dispatch(c.cmd, *program_, groups, groups, 1, vk::descriptors_at(d), std::as_bytes(std::span(&push, 1)));
    c.end_light();
  }
}

void PrefixSumPass::prepare(const PassResources& r) {
  int rep = representation6(config_);
  std::string shader = rep == MSM_REP6_UNORM10   ? "prefix_sums6_10.comp"
                       : rep == MSM_REP6_UNORM16 ? "prefix_sums6_16.comp"
                       : rep == MSM_REP6_FLOAT   ? "prefix_sums6_32.comp"
                       : csm(config_)            ? "prefix_sums_csm.comp"
                                                 : "prefix_sums.comp";
  // Six moments read and write a second image pair.
  std::vector<vk::BindingAt> bindings = {{MSM_BINDING_PREFIX_RECTS, vk::Binding::storage_buffer},
                                         {MSM_BINDING_PREFIX_SOURCE, vk::Binding::sampled_image},
                                         {MSM_BINDING_PREFIX_TARGET, vk::Binding::storage_image}};
  if (rep >= 0) {
    bindings.push_back({MSM_BINDING_PREFIX_SOURCE1, vk::Binding::sampled_image});
    bindings.push_back({MSM_BINDING_PREFIX_TARGET1, vk::Binding::storage_image});
  }
  program_ = &r.programs.compute(shader, vk::bindings_at(bindings), sizeof(ImagePassPush),
                                 {{MSM_PREFIX_ROWS_SPEC_ID, config_.prefix_sums_appendix_c ? 0u : 1u},
                                  {MSM_SPEC_SPOT_LIGHTS, config_.spot_lights > 0 ? 1u : 0u}});
}

void PrefixSumPass::reflect(PassBuilder& b) const {
  std::array<VkFormat, 2> formats = config_.prefix_sum_formats();
  // K transmittance layers per light (CSM: eight image layers each), light l's from K l.
  const uint32_t prefix_layers = uint32_t(config_.lights) * layers(config_);
  // Per moment image: the rectified image read, its prefix sums created.
  auto prefix_sums = [&](const char* rectified, const char* sums, VkFormat format, uint32_t image_layers) {
    b.read(rectified, use::sampled(kCompute));
    b.create(sums,
             {.format = format,
              .width = size(config_),
              .height = size(config_),
              .mips = config_.prefix_sum_mips,
              .layers = image_layers},
             use::compute_general());
  };
  prefix_sums(kRectified, kPrefixSums, formats[0], (csm(config_) ? kCsmLayers : 1) * prefix_layers);
  if (prefix_sums_have_two_images(config_)) prefix_sums(kRectified1, kPrefixSums1, formats[1], prefix_layers);
}

void PrefixSumPass::execute(const PassContext& c) const {
  // CSM: the whole rectified array, the light's eight layers (times K transmittance layers) one per
  // dispatch z; the others read the light's layer and write its K layers, one per dispatch z. The
  // prefix sums are written through the whole array (prefix_sums.glsl picks the layer).
  const bool array = csm(config_);
  const uint32_t rows_per_group = config_.prefix_sums_appendix_c ? 8 : 64; // prefix_sums.glsl
  const GraphImage &rectified = c.image(kRectified), &prefix_sums = c.image(kPrefixSums);
  for (int l = 0; l < config_.lights; ++l) {
    c.begin_light(name(), l);
    const size_t layer = size_t(l);
    std::vector<vk::DescriptorAt> d = {
        {MSM_BINDING_PREFIX_RECTS, vk::Descriptor(*c.frame.rectification)},
        {MSM_BINDING_PREFIX_SOURCE,
         vk::Descriptor(array ? rectified.array_view : rectified.layer_views[layer], kReadOnly, c.frame.point_sampler)},
        {MSM_BINDING_PREFIX_TARGET, vk::Descriptor(mip0(prefix_sums), VK_IMAGE_LAYOUT_GENERAL)}};
    if (prefix_sums_have_two_images(config_)) {
      d.push_back({MSM_BINDING_PREFIX_SOURCE1,
                   vk::Descriptor(c.image(kRectified1).layer_views[layer], kReadOnly, c.frame.point_sampler)});
      d.push_back({MSM_BINDING_PREFIX_TARGET1, vk::Descriptor(mip0(c.image(kPrefixSums1)), VK_IMAGE_LAYOUT_GENERAL)});
    }
    const ImagePassPush push{glm::ivec4(config_.shadow_size, config_.shadow_size, l, int(layers(config_)))};
    vk::dispatch(c.cmd, *program_, vk::group_count(size(config_), rows_per_group), 1,
                 (array ? kCsmLayers : 1) * layers(config_), vk::descriptors_at(d), std::as_bytes(std::span(&push, 1)));
    c.end_light();
  }
}

// The prefix-sum images of the frame: one, or two for six moments.
static std::span<const char* const> prefix_sum_images(const FrameConfig& c) {
  static constexpr const char* kNames[] = {kPrefixSums, kPrefixSums1};
  return std::span(kNames, prefix_sums_have_two_images(c) ? 2 : 1);
}

void PrefixSumMipmapPass::reflect(PassBuilder& b) const {
  for (const char* name : prefix_sum_images(config_)) {
    b.modify(name, use::transfer_source());
    b.internally(name, use::transfer_destination());
  }
}

void PrefixSumMipmapPass::execute(const PassContext& c) const {
  for (const char* name : prefix_sum_images(config_)) {
    const GraphImage& g = c.image(name);
    record_mip_chain(c.cmd, g.image.handle(), config_.shadow_size, 1, g.spec.mips, g.spec.layers);
  }
}

} // namespace msm::render
