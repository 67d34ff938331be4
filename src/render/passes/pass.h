// The passes a frame is composed of (recipes.cpp picks them per technique). Each declares in
// reflect() what it creates, reads and modifies (frame_graph.h) and records only its own work in
// execute(); the frame graph places the barriers between passes. A pass that works per light loops
// over the layers of its images (one per light), each light in a timer scope of its own when the
// frame has several.
#pragma once

#include "../frame_config.h"
#include "../frame_graph.h"
#include "../gpu_scene.h"
#include "../program_cache.h"

#include "msm/gpu/sat_builder.h"

#include <memory>
#include <string_view>

namespace msm::render {

// Scene -> shadow_depth (D16, MSAA, one layer per light): orthographic depth, depth clamp, both faces.
// back: shadow_depth_back, the nearest back face (Kneiphof §4.2.3, FrameConfig::front_back): the
// faces towards the light are culled, except on double-sided materials, which count as both.
class ShadowDepthPass : public Pass {
 public:
  explicit ShadowDepthPass(const FrameConfig& config, bool back = false) : config_(config), back_(back) {}
  std::string_view name() const override { return back_ ? "shadow_depth_back" : "shadow_depth"; }
  void prepare(const PassResources& r) override;
  void reflect(PassBuilder& b) const override;
  void execute(const PassContext& c) const override;

 private:
  const vk::Program* program_ = nullptr;
  const vk::Program* masked_program_ = nullptr; // alpha-tested draws: a fragment stage discards cut-outs
  const vk::Program* spot_program_ = nullptr;   // spot lights' layers: radial depth, alpha-tested
  FrameConfig config_;
  bool back_ = false;
};

// shadow_depth -> moment images (mip 0) of channel 0: per sample msm_technique_generate, averaged,
// in the storage basis (compute).
class MomentResolvePass : public Pass {
 public:
  explicit MomentResolvePass(const FrameConfig& config) : config_(config) {}
  std::string_view name() const override { return "moment_resolve"; }
  void prepare(const PassResources& r) override;
  void reflect(PassBuilder& b) const override;
  void execute(const PassContext& c) const override;

 private:
  const vk::Program* program_ = nullptr;
  FrameConfig config_;
};

// Coloured translucency: the moment images of channel 0 (the opaque occluders) copied to the green
// and blue channels' images, which the translucent pass then blends differently.
class ChannelCopyPass : public Pass {
 public:
  explicit ChannelCopyPass(const FrameConfig& config) : config_(config) {}
  std::string_view name() const override { return "channel_copy"; }
  void reflect(PassBuilder& b) const override;
  void execute(const PassContext& c) const override;

 private:
  FrameConfig config_;
};

// shadow_depth -> moment images (mip 0) in one dispatch: resolve, Gaussian in shared memory,
// encoding (HPG 2017 §4). One pipeline per technique, MSAA and filter radius.
class OnePassFilterPass : public Pass {
 public:
  explicit OnePassFilterPass(const FrameConfig& config) : config_(config) {}
  std::string_view name() const override { return "one_pass_filter"; }
  void prepare(const PassResources& r) override;
  void reflect(PassBuilder& b) const override;
  void execute(const PassContext& c) const override;

 private:
  const vk::Program* program_ = nullptr;
  FrameConfig config_;
};

// Translucent objects blended into the moment images (mip 0) of one colour channel, back to front
// (JCGT §3), with the opaque depth samples as the occlusion of each fragment.
class TranslucentPass : public Pass {
 public:
  TranslucentPass(const FrameConfig& config, int channel) : config_(config), channel_(channel) {}
  std::string_view name() const override { return "translucent"; }
  void prepare(const PassResources& r) override;
  void reflect(PassBuilder& b) const override;
  void execute(const PassContext& c) const override;

 private:
  const vk::Program* program_ = nullptr;
  FrameConfig config_;
  int channel_;
};

// blur.comp's specialization constants: the fetches per side of the widest kernel it blurs with
// (msm/filter.h's pairs of `taps`), bilinear or as point pairs; the shader's bindings are the
// source (sampled through a linear, clamp-to-edge sampler when bilinear), the target and the
// layers' kernels (a storage buffer of BlurKernel, the push constant's size.w the layer's).
// With mip1 the shader blurs 2 x 2 texels per invocation and writes their average to binding 2
// (dispatch over half the size in each direction; the size even).
std::vector<vk::SpecConstant> blur_constants(int taps, bool bilinear, bool mip1);
// A layer's kernel for blur.comp: `taps` (at most the compiled taps) and σ in its texels.
BlurKernel blur_kernel(int taps, float sigma);

// Moment images (mip 0) of one channel -> separable Gaussian (msm/filter.h) in place, through a
// float scratch image; the vertical direction also writes mip 1 where FrameConfig::blur_writes_mip1().
class BlurPass : public Pass {
 public:
  BlurPass(const FrameConfig& config, int channel) : config_(config), channel_(channel) {}
  std::string_view name() const override { return "blur"; }
  void prepare(const PassResources& r) override;
  void reflect(PassBuilder& b) const override;
  void execute(const PassContext& c) const override;

 private:
  const vk::Program *program_ = nullptr, *vertical_program_ = nullptr;
  vk::Buffer kernels_; // BlurKernel per layer, written as each frame is recorded
  FrameConfig config_;
  int channel_;
};

// Mips first_mip .. mips - 1 of every layer of a square image of side `size`, each the linear blit
// (2 x 2 box average) of the previous one; the image's mips are all in TRANSFER_SRC before and after.
void record_mip_chain(VkCommandBuffer cmd, VkImage image, int32_t size, uint32_t first_mip, uint32_t mips,
                      uint32_t layers);

// Moment images of one channel: mips 1.. (2.. where the blur wrote mip 1) by linear blits of the
// previous mip (averages of moments are moments).
class MipmapPass : public Pass {
 public:
  MipmapPass(const FrameConfig& config, int channel) : config_(config), channel_(channel) {}
  std::string_view name() const override { return "mipmaps"; }
  void reflect(PassBuilder& b) const override;
  void execute(const PassContext& c) const override;

 private:
  FrameConfig config_;
  int channel_;
};

// Moment images (unfiltered Θ4*, Θ6* or (z, z²)) -> 32-bit integer summed-area tables of the soft
// shadows (JCGT §4.2, msm::gpu::SatBuilder, rows then columns), one per moment image.
class SatPass : public Pass {
 public:
  explicit SatPass(const FrameConfig& config) : config_(config) {}
  std::string_view name() const override { return "sat"; }
  void prepare(const PassResources& r) override;
  void reflect(PassBuilder& b) const override;
  void execute(const PassContext& c) const override;

 private:
  const gpu::SatBuilder* builder_ = nullptr; // the renderer's (its pipelines outlive a configuration)
  FrameConfig config_;
};

// Deferred shading (FrameConfig::deferred): the opaque scene -> camera_depth and the visible
// surface of each pixel (surface_position, surface_normal, surface_albedo, and its triangle's normal
// surface_geometric_normal), cut-outs discarded.
class SurfacesPass : public Pass {
 public:
  explicit SurfacesPass(const FrameConfig& config) : config_(config) {}
  std::string_view name() const override { return "surfaces"; }
  void prepare(const PassResources& r) override;
  void reflect(PassBuilder& b) const override;
  void execute(const PassContext& c) const override;

 private:
  const vk::Program* program_ = nullptr;
  FrameConfig config_;
};

// Scene + shadow_depth, moment images or tables -> color (sRGB) and shadow_buffer: Lambert + ambient
// with every light's shadow (msm/shading.h), over-darkening, ACES; translucent surfaces blended over.
// Deferred: the opaque surfaces come from the surfaces pass, shaded by one full-screen triangle.
class ShadingPass : public Pass {
 public:
  explicit ShadingPass(const FrameConfig& config) : config_(config) {}
  std::string_view name() const override { return "shading"; }
  void prepare(const PassResources& r) override;
  void reflect(PassBuilder& b) const override;
  void execute(const PassContext& c) const override;

 private:
  // opaque (forward, or the full-screen deferred one); translucent over it (forward); a probe-lit
  // scene's background
  const vk::Program *program_ = nullptr, *translucent_program_ = nullptr, *background_program_ = nullptr;
  FrameConfig config_;
};

// Scattering techniques: camera_depth + surface_radiance + every light's shadow map (ray marching) or
// prefix sums (prefiltered) -> color (sRGB) and scattering (in-scattered radiance, visible fraction):
// single scattering of every light in the scene's medium, summed, composited over the surfaces, tone
// mapped (a full-screen triangle, JCGT §5.5's deferred pass).
class ScatteringPass : public Pass {
 public:
  explicit ScatteringPass(const FrameConfig& config) : config_(config) {}
  std::string_view name() const override { return "scattering"; }
  void prepare(const PassResources& r) override;
  void reflect(PassBuilder& b) const override;
  void execute(const PassContext& c) const override;

 private:
  bool prefiltered() const;
  bool six_moments() const;
  const vk::Program* program_ = nullptr;
  FrameConfig config_;
};

// Prefiltered scattering (JCGT §5.1.1, §5.2): each light's depth map resampled into its rectified map
// (its layer; compute, rectify.glsl, one dispatch per light): moments of the rectified depth in float.
class RectifyPass : public Pass {
 public:
  explicit RectifyPass(const FrameConfig& config) : config_(config) {}
  std::string_view name() const override { return "rectify"; }
  void prepare(const PassResources& r) override;
  void reflect(PassBuilder& b) const override;
  void execute(const PassContext& c) const override;

 private:
  const vk::Program* program_ = nullptr;
  FrameConfig config_;
};

// Each light's rectified map -> transmittance-weighted prefix sums along its rows (a thread per row,
// or JCGT Appendix C's 8 x 8 scheme: prefix_sums.glsl; one dispatch per light), in the technique's
// storage format.
class PrefixSumPass : public Pass {
 public:
  explicit PrefixSumPass(const FrameConfig& config) : config_(config) {}
  std::string_view name() const override { return "prefix_sums"; }
  void prepare(const PassResources& r) override;
  void reflect(PassBuilder& b) const override;
  void execute(const PassContext& c) const override;

 private:
  const vk::Program* program_ = nullptr;
  FrameConfig config_;
};

// Six-moment prefiltered scattering: two images per map (rectified, prefix sums).
bool prefix_sums_have_two_images(const FrameConfig& config);

// JCGT App. D.5: the prefix sums' mip chain (FrameConfig::prefix_sum_mips > 1), linear blits of every
// layer (a 2 x 2 box average of prefix sums is the prefix sum of the averaged rows at the mean end).
class PrefixSumMipmapPass : public Pass {
 public:
  explicit PrefixSumMipmapPass(const FrameConfig& config) : config_(config) {}
  std::string_view name() const override { return "prefix_sum_mips"; }
  void reflect(PassBuilder& b) const override;
  void execute(const PassContext& c) const override;

 private:
  FrameConfig config_;
};

// The images every shadow-map pass creates.
ImageSpec moment_image_spec(const FrameConfig& config, int i);
// Binds the scene's vertex and index buffers (every graphics pass draws the scene).
void bind_scene(VkCommandBuffer cmd, const GpuScene& scene);

} // namespace msm::render
