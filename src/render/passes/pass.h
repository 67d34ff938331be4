// The passes of a frame. Each declares what it reads and writes (PassDecl, apart from execute)
// and records itself inside a GPU timer scope of its name; the renderer composes them. A pass
// leaves its outputs in the layout and with the barrier its consumers need (stated per pass).
#pragma once

#include "../frame_targets.h"
#include "../gpu_scene.h"

#include "msm/soft/sat_builder.h"

#include <memory>
#include <string_view>
#include <vector>

namespace msm::render {

struct PassDecl {
  std::string_view name; // also the GPU timer scope
  std::vector<std::string_view> inputs, outputs;
};

// What execute() records with.
struct FrameContext {
  const vk::Context& ctx;
  VkCommandBuffer cmd;
  vk::GpuTimer& timer;
  const FrameTargets& targets;
  const GpuScene& scene;
  const vk::Buffer& uniforms;  // FrameUniforms
  const vk::Image& blue_noise; // 64 layers of 64² RG8 (blue_noise.h)
  glm::vec3 camera_position;
  // The colour channel whose moment images resolve, translucent, blur and mips work on
  // (FrameTargets::moment_image; always 0 unless the frame has coloured translucency).
  int channel = 0;
};

// Scene -> shadow_depth (D16, MSAA), left SHADER_READ_ONLY for compute and fragment reads.
class ShadowDepthPass {
 public:
  static const PassDecl& decl();
  ShadowDepthPass(const vk::Context& ctx, int msaa);
  void execute(FrameContext& f) const;

 private:
  vk::Program program_;
  vk::Program masked_program_; // alpha-tested draws: a fragment stage that discards the cut-outs
};

// shadow_depth -> moments[0..1] mip 0 (GENERAL), visible to compute and fragment reads. With
// coloured translucency the opaque moments of channel 0 are then copied to the other channels
// (the same opaque occluders; only the translucent blend differs), in the same timer scope.
class MomentResolvePass {
 public:
  static const PassDecl& decl();
  MomentResolvePass(const vk::Context& ctx, const Technique& technique, int msaa, bool split_rg);
  void execute(FrameContext& f) const;

 private:
  vk::Program program_;
};

// shadow_depth -> moments mip 0 (GENERAL) in one dispatch: resolve, Gaussian in shared memory,
// encoding (HPG 2017 §4); visible to transfer, compute and fragment reads. One per technique,
// MSAA and filter radius (specialization constants).
class OnePassFilterPass {
 public:
  static const PassDecl& decl();
  OnePassFilterPass(const vk::Context& ctx, const Technique& technique, int msaa, int taps);
  void execute(FrameContext& f) const;

 private:
  vk::Program program_;
};

// Translucent objects -> blended into moments mip 0 (GENERAL, as colour attachments), back to
// front (JCGT §3); after the resolve, before the blur. Visible to compute and transfer.
class TranslucentPass {
 public:
  static const PassDecl& decl();
  TranslucentPass(const vk::Context& ctx, const Technique& technique, int msaa, bool split_rg,
                  const std::array<int, 2>& formats);
  void execute(FrameContext& f) const;

 private:
  vk::Program program_;
};

// moments mip 0 (unfiltered Θ4*, Θ6* or (z, z²)) -> sat_tables (GENERAL): the 32-bit integer
// summed-area tables of the soft shadows (JCGT §4.2, msm::soft::SatBuilder), one per moment
// image, visible to fragment reads.
class SatPass {
 public:
  static const PassDecl& decl();
  explicit SatPass(const vk::Context& ctx);
  void execute(FrameContext& f, int max_kernel_texels) const;

 private:
  std::unique_ptr<soft::SatBuilder> builder_;
};

// moments mip 0 -> blur_temp -> moments mip 0 (GENERAL), visible to transfer, compute, fragment.
class BlurPass {
 public:
  static const PassDecl& decl();
  explicit BlurPass(const vk::Context& ctx);
  void execute(FrameContext& f) const;

 private:
  vk::Program program_;
};

// moments mip 0 -> mips 1.. by linear blits (GENERAL), visible to fragment reads.
class MipmapPass {
 public:
  static const PassDecl& decl();
  void execute(FrameContext& f) const;
};

// Scene + shadow_depth or moments -> color (sRGB) and shadow_buffer, left TRANSFER_SRC.
class ShadingPass {
 public:
  static const PassDecl& decl();
  ShadingPass(const vk::Context& ctx, const Technique& technique, int msaa, bool split_rg, bool coloured);
  void execute(FrameContext& f) const;

 private:
  vk::Program program_, translucent_program_; // opaque; translucent objects blended over it
  bool depth_based_, nonlinear_, soft_;
};

// Scope guard for the timer scope of a pass.
class PassScope {
 public:
  PassScope(FrameContext& f, const PassDecl& decl) : f_(f) { f_.timer.begin(f_.cmd, decl.name); }
  ~PassScope() { f_.timer.end(f_.cmd); }
  PassScope(const PassScope&) = delete;
  PassScope& operator=(const PassScope&) = delete;

 private:
  FrameContext& f_;
};

} // namespace msm::render
