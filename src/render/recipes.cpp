#include "recipes.h"

#include "passes/pass.h"

namespace msm::render {

std::vector<std::unique_ptr<Pass>> recipe(const FrameConfig& c) {
  std::vector<std::unique_ptr<Pass>> passes;
  passes.push_back(std::make_unique<ShadowDepthPass>(c));
  if (c.front_back) passes.push_back(std::make_unique<ShadowDepthPass>(c, true)); // Kneiphof §4.2.3
  const Technique& t = *c.technique;
  if (t.depth_based()) {
    // plain, pcf, pcss read the depth map itself.
  } else if (c.one_pass) { // HPG 2017: resolve, blur and encoding in one dispatch
    passes.push_back(std::make_unique<OnePassFilterPass>(c));
    if (c.mip_levels > 1) passes.push_back(std::make_unique<MipmapPass>(c, 0));
  } else if (t.soft()) { // tables instead of blur and mips
    passes.push_back(std::make_unique<MomentResolvePass>(c));
    passes.push_back(std::make_unique<SatPass>(c));
  } else {
    passes.push_back(std::make_unique<MomentResolvePass>(c));
    // Coloured translucency: every channel starts from the same opaque moments.
    if (c.channels() > 1) passes.push_back(std::make_unique<ChannelCopyPass>(c));
    for (int channel = 0; channel < c.channels(); ++channel) {
      if (c.translucent) passes.push_back(std::make_unique<TranslucentPass>(c, channel));
      if (c.taps > 1) passes.push_back(std::make_unique<BlurPass>(c, channel));
      if (c.mip_levels > 1) passes.push_back(std::make_unique<MipmapPass>(c, channel));
    }
  }
  if (c.deferred) passes.push_back(std::make_unique<SurfacesPass>(c));
  passes.push_back(std::make_unique<ShadingPass>(c));
  if (t.prefiltered_scattering()) {
    if (c.filtered_resampling) { // the blurred, mipmapped 4-moment map that rectify samples (§5.2)
      const FrameConfig m = c.resampling_moments();
      passes.push_back(std::make_unique<MomentResolvePass>(m));
      if (m.taps > 1) passes.push_back(std::make_unique<BlurPass>(m, 0));
      if (m.mip_levels > 1) passes.push_back(std::make_unique<MipmapPass>(m, 0));
    }
    passes.push_back(std::make_unique<RectifyPass>(c));
    passes.push_back(std::make_unique<PrefixSumPass>(c));
    if (c.prefix_sum_mips > 1) passes.push_back(std::make_unique<PrefixSumMipmapPass>(c));
  }
  if (t.scatters()) passes.push_back(std::make_unique<ScatteringPass>(c));
  return passes;
}

std::vector<std::string> frame_outputs() { return {kColor, kShadowBuffer}; }

std::vector<std::string> frame_outputs(const FrameConfig& c) {
  if (c.technique->scatters()) return {kColor, kShadowBuffer, kScattering};
  return frame_outputs();
}

bool supports_deferred_shading(const Technique& technique) { return technique.deferred_shading_supported(); }

bool default_deferred_shading(const Technique& technique) { return technique.deferred_shading_default; }

std::vector<std::string> technique_passes(const Technique& technique, bool translucent, bool coloured) {
  RenderSettings defaults;
  FrameConfig c;
  c.technique = &technique;
  c.width = defaults.width;
  c.height = defaults.height;
  c.shadow_size = defaults.shadow_size;
  c.msaa = defaults.msaa;
  c.taps = defaults.filter_size;
  c.one_pass = technique.one_pass_default();
  // The full chain of the default shadow map's size (the device's blit support aside).
  c.mip_levels = defaults.mipmaps && technique.mipmapped() ? full_mip_chain(defaults.shadow_size) : 1;
  c.translucent = translucent && supports_translucency(technique);
  c.coloured = c.translucent && coloured;
  c.deferred = default_deferred_shading(technique);
  std::vector<std::unique_ptr<Pass>> passes = recipe(c);
  std::vector<std::string> names;
  for (size_t i : order_passes(passes, {}, frame_outputs(c))) names.emplace_back(passes[i]->name());
  return names;
}

} // namespace msm::render
