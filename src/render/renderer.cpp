// The frame: uniforms, the passes in order, readback. Pipelines are built on first use of a
// technique / MSAA combination and kept.
#include "msm/render/renderer.h"

#include "frame_targets.h"
#include "gpu_scene.h"
#include "msm/render/blue_noise.h"
#include "msm/render/frame.h"
#include "msm/soft.h"
#include "msm/techniques.h"
#include "passes/pass.h"

#include <fmt/format.h>
#include <glm/gtc/packing.hpp>

#include <cmath>
#include <cstring>
#include <map>
#include <tuple>

namespace msm::render {

// std140 and the C++ struct agree (frame.h uses vec4/ivec4/mat4 members only).
static_assert(sizeof(FrameUniforms) == 3 * 64 + 7 * 16 + 16 * 16 + 3 * 16 + 4 * 16 + 16);
static_assert(offsetof(FrameUniforms, kernel) == 3 * 64 + 6 * 16);
static_assert(offsetof(FrameUniforms, filter_weights) == 3 * 64 + 7 * 16);
static_assert(offsetof(FrameUniforms, receiver_bias) == sizeof(FrameUniforms) - 16);
static_assert(sizeof(ObjectPush) == 48 && sizeof(ImagePassPush) == 16);

namespace {

// Vulkan's standard sample locations (pixel-relative, y down), as offsets from the centre.
std::vector<glm::vec2> standard_sample_offsets(int samples) {
  static const float four[] = {0.375f, 0.125f, 0.875f, 0.375f, 0.125f, 0.625f, 0.625f, 0.875f};
  static const float eight[] = {0.5625f, 0.3125f, 0.4375f, 0.6875f, 0.8125f, 0.5625f, 0.3125f, 0.1875f,
                                0.1875f, 0.8125f, 0.0625f, 0.4375f, 0.6875f, 0.9375f, 0.9375f, 0.0625f};
  const float* p = samples == 4 ? four : samples == 8 ? eight : nullptr;
  std::vector<glm::vec2> out(size_t(samples), glm::vec2(0.0f));
  if (p)
    for (int i = 0; i < samples; ++i) out[size_t(i)] = glm::vec2(p[2 * i], p[2 * i + 1]) - 0.5f;
  return out;
}

image::Image to_float_image(std::span<const std::byte> bytes, VkFormat format, int width, int height) {
  int channels = 0;
  enum { unorm16, half, Float } kind = Float;
  switch (format) {
  case VK_FORMAT_R16G16B16A16_UNORM:
    channels = 4;
    kind = unorm16;
    break;
  case VK_FORMAT_R16G16_UNORM:
    channels = 2;
    kind = unorm16;
    break;
  case VK_FORMAT_R16G16B16A16_SFLOAT:
    channels = 4;
    kind = half;
    break;
  case VK_FORMAT_R16G16_SFLOAT:
    channels = 2;
    kind = half;
    break;
  case VK_FORMAT_R32G32B32A32_SFLOAT: channels = 4; break;
  case VK_FORMAT_R32G32_SFLOAT: channels = 2; break;
  case VK_FORMAT_R32_SFLOAT: channels = 1; break;
  default: throw RenderError("to_float_image: unexpected format");
  }
  image::Image out(width, height, channels);
  std::span<float> px = out.pixels();
  for (size_t i = 0; i < px.size(); ++i) {
    if (kind == unorm16) {
      uint16_t v;
      std::memcpy(&v, bytes.data() + 2 * i, 2);
      px[i] = float(v) / 65535.0f;
    } else if (kind == half) {
      uint16_t v;
      std::memcpy(&v, bytes.data() + 2 * i, 2);
      px[i] = glm::unpackHalf1x16(v);
    } else {
      std::memcpy(&px[i], bytes.data() + 4 * i, 4);
    }
  }
  return out;
}

} // namespace

struct Renderer::Impl {
  const vk::Context& ctx;
  scene::Scene scene;
  GpuScene gpu;
  glm::mat4 light_view_projection;
  vk::Buffer uniforms;
  vk::GpuTimer timer;
  std::unique_ptr<FrameTargets> targets;
  std::map<int, std::unique_ptr<ShadowDepthPass>> shadow_passes;
  std::map<std::tuple<int, int, bool>, std::unique_ptr<MomentResolvePass>> resolve_passes;
  std::map<std::tuple<int, int, bool, bool>, std::unique_ptr<ShadingPass>> shading_passes;
  std::map<std::tuple<int, int, bool>, std::unique_ptr<TranslucentPass>> translucent_passes;
  std::map<std::tuple<int, int, int>, std::unique_ptr<OnePassFilterPass>> one_pass_passes;
  vk::Image noise;
  std::unique_ptr<BlurPass> blur_pass;
  std::unique_ptr<SatPass> sat_pass;
  std::unique_ptr<vk::Program> depth_copy;
  MipmapPass mipmap_pass;

  Impl(const vk::Context& c, const scene::Scene& s)
      : ctx(c), scene(s), gpu(c, s), light_view_projection(s.light_view_projection()),
        uniforms(vk::create_buffer(c, sizeof(FrameUniforms), VK_BUFFER_USAGE_UNIFORM_BUFFER_BIT, vk::Memory::host)),
        timer(c, 32), noise(upload_blue_noise(c)) {}

  static vk::Image upload_blue_noise(const vk::Context& ctx) {
    const BlueNoise& n = blue_noise();
    if (n.size != 64 || n.channels != 2) throw RenderError("blue noise: expected 64² textures with two channels");
    vk::Image image = vk::create_image(ctx, {.width = 64,
                                             .height = 64,
                                             .format = VK_FORMAT_R8G8_UNORM,
                                             .usage = VK_IMAGE_USAGE_SAMPLED_BIT | VK_IMAGE_USAGE_TRANSFER_DST_BIT,
                                             .layers = uint32_t(n.count)});
    vk::upload_image(ctx, image, std::as_bytes(std::span(n.texels)), VK_IMAGE_LAYOUT_UNDEFINED,
                     VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL);
    return image;
  }

  template <class Map, class Key, class Make>
  auto& cached(Map& map, const Key& key, Make make) {
    auto it = map.find(key);
    if (it == map.end()) it = map.emplace(key, make()).first;
    return *it->second;
  }

  FrameUniforms frame_uniforms(const RenderSettings& s, const Technique& technique) const {
    FrameUniforms u{};
    u.camera_view_projection = scene.camera_view_projection(float(s.width) / float(s.height));
    u.light_view_projection = light_view_projection;
    u.light_normal_matrix = glm::mat4(glm::transpose(glm::inverse(glm::mat3(light_view_projection))));
    u.towards_light = glm::vec4(scene.light.towards_light, 0.0f);
    u.irradiance = glm::vec4(scene.light.irradiance, 0.03f); // ambient factor: as the reference
    u.technique_params = s.params ? *s.params : default_params(technique);
    // One shadow-map texel in world units: the light frustum's width over the map size.
    glm::mat4 inverse = glm::inverse(light_view_projection);
    float texel = glm::length(glm::vec3(inverse * glm::vec4(2.0f, 0.0f, 0.0f, 0.0f))) / float(s.shadow_size);
    bool soft = msm_technique_is_soft(technique.id);
    float depth_bias = s.resolved_depth_bias();
    u.shadow_map =
        glm::vec4(float(s.shadow_size), 1.0f / float(s.shadow_size), s.normal_offset * texel, soft ? 0.0f : depth_bias);
    if (msm_technique_is_area_light(technique.id)) {
      // soft.h: texels of reach per unit of [-1,1] depth = tan(θ/2) w_d / w_t.
      float extent = s.light_extent_deg ? *s.light_extent_deg : scene.light.angular_extent_deg;
      float tan_half = std::tan(glm::radians(extent) * 0.5f);
      float world_per_depth = 0.5f * glm::length(glm::vec3(inverse * glm::vec4(0.0f, 0.0f, 1.0f, 0.0f)));
      float texel_y = glm::length(glm::vec3(inverse * glm::vec4(0.0f, 2.0f, 0.0f, 0.0f))) / float(s.shadow_size);
      // The constant part of msm_soft_depth_bias, in [-1,1] depth.
      u.soft = glm::vec4(tan_half * world_per_depth / texel, tan_half * world_per_depth / texel_y, 2.0f * depth_bias,
                         MSM_SOFT_UMBRA_EPSILON);
      int kernel = s.resolved_soft_kernel();
      uint32_t scale = 0xFFFFFFFFu / uint32_t(kernel * kernel);
      u.soft_kernel = glm::ivec4(kernel, int(scale), 0, 0); // the uint's bits
    }
    u.shading = glm::vec4(s.overdarken, s.exposure, s.translucent_alpha_threshold, 0.0f);
    u.background = glm::vec4(0.55f, 0.65f, 0.8f, 1.0f);
    int radius = s.filter_size / 2;
    u.kernel = glm::ivec4(s.filter_size, s.msaa, radius, 0);
    double sum = 0;
    std::vector<double> w(size_t(s.filter_size));
    for (int k = 0; k < s.filter_size; ++k) {
      double x = k - radius;
      sum += w[size_t(k)] = std::exp(-x * x / (2.0 * double(s.filter_sigma) * s.filter_sigma));
    }
    for (int k = 0; k < s.filter_size; ++k) u.filter_weights[k / 4][k % 4] = float(w[size_t(k)] / sum);
    std::vector<glm::vec2> offsets =
        ctx.properties().limits.standardSampleLocations ? standard_sample_offsets(s.msaa) : std::vector<glm::vec2>(8);
    bool nonlinear = msm_technique_is_nonlinear(technique.id);
    int lookup = s.lookup == RenderSettings::Lookup::nearest    ? MSM_LOOKUP_NEAREST
                 : s.lookup == RenderSettings::Lookup::dither   ? MSM_LOOKUP_DITHER
                 : s.lookup == RenderSettings::Lookup::bilinear ? MSM_LOOKUP_BILINEAR
                 : nonlinear                                    ? MSM_LOOKUP_DITHER
                                                                : MSM_LOOKUP_BILINEAR;
    // A different blue-noise layer and offset each frame (a fixed hash of the frame number).
    uint32_t h = uint32_t(s.frame) * 2654435761u + 0x9e3779b9u;
    h ^= h >> 15;
    h *= 2246822519u;
    h ^= h >> 13;
    u.lookup = glm::ivec4(lookup, int(h % uint32_t(blue_noise().count)), int((h >> 8) & 63u), int((h >> 16) & 63u));
    for (size_t i = 0; i < offsets.size(); ++i) {
      u.sample_offsets[i / 2][int(2 * (i % 2))] = offsets[i].x;
      u.sample_offsets[i / 2][int(2 * (i % 2) + 1)] = offsets[i].y;
    }
    // Receiver-plane bias of the filtered techniques (lookup.glsl, msm/bias.h): the kernel's
    // variance per axis in texels², of the normalized Gaussian taps plus the MSAA sample positions
    // (the resolve averages depths taken there; mean of x and y); the lookup adds its own.
    double kernel_variance = 0;
    for (int k = 0; k < s.filter_size; ++k) kernel_variance += w[size_t(k)] / sum * double((k - radius) * (k - radius));
    for (const glm::vec2& o : offsets) kernel_variance += 0.5 * double(o.x * o.x + o.y * o.y) / double(offsets.size());
    u.receiver_bias = glm::vec4(float(kernel_variance), s.receiver_plane_bias, 0.0f, 0.0f);
    return u;
  }

  // Validates, builds what is missing, writes the uniforms.
  const Technique& prepare(const RenderSettings& s) {
    s.validate();
    const Technique& technique = find_technique(s.technique);
    VkSampleCountFlagBits samples = VkSampleCountFlagBits(s.msaa);
    if (!vk::supports_attachment(ctx, VK_FORMAT_D16_UNORM, samples))
      throw RenderError(
          fmt::format("{} cannot render 16-bit depth with {}x MSAA; use --msaa 1 or 4", ctx.info().name, s.msaa));
    if (uint32_t(std::max(s.width, s.height)) > ctx.properties().limits.maxImageDimension2D ||
        uint32_t(s.shadow_size) > ctx.properties().limits.maxImageDimension2D)
      throw RenderError(fmt::format("{} supports images up to {} texels per side", ctx.info().name,
                                    ctx.properties().limits.maxImageDimension2D));
    bool one_pass = s.one_pass.value_or(msm_technique_is_nonlinear(technique.id));
    bool translucent =
        s.translucent_occluders && !gpu.translucent.empty() && supports_translucency(technique) && !one_pass;
    FrameConfig config{&technique,    s.width,   s.height, s.shadow_size, s.msaa,
                       s.filter_size, s.mipmaps, one_pass, translucent,   translucent && s.coloured_translucency};
    bool split = config.split_rg();
    if (!targets || !(targets->config == config)) {
      targets.reset();
      targets = std::make_unique<FrameTargets>(ctx, config);
    }
    cached(shadow_passes, s.msaa, [&] { return std::make_unique<ShadowDepthPass>(ctx, s.msaa); });
    if (one_pass) {
      cached(one_pass_passes, std::tuple(technique.id, s.msaa, s.filter_size),
             [&] { return std::make_unique<OnePassFilterPass>(ctx, technique, s.msaa, s.filter_size); });
    } else if (config.moment_images()) {
      cached(resolve_passes, std::tuple(technique.id, s.msaa, split),
             [&] { return std::make_unique<MomentResolvePass>(ctx, technique, s.msaa, split); });
      if (translucent)
        cached(translucent_passes, std::tuple(technique.id, s.msaa, split),
               [&] { return std::make_unique<TranslucentPass>(ctx, technique, s.msaa, split, config.formats()); });
      if (!blur_pass) blur_pass = std::make_unique<BlurPass>(ctx);
      if (msm_technique_is_soft(technique.id) && !sat_pass) sat_pass = std::make_unique<SatPass>(ctx);
    }
    cached(shading_passes, std::tuple(technique.id, s.msaa, split, config.coloured),
           [&] { return std::make_unique<ShadingPass>(ctx, technique, s.msaa, split, config.coloured); });
    FrameUniforms u = frame_uniforms(s, technique);
    std::memcpy(uniforms.data(), &u, sizeof(u));
    return technique;
  }

  // Records the passes; `until_resolve` stops after the moment resolve (intermediates).
  void record(VkCommandBuffer cmd, const RenderSettings& s, const Technique& technique, bool until_resolve) {
    timer.reset(cmd);
    FrameContext f{ctx, cmd, timer, *targets, gpu, uniforms, noise, scene.camera.position};
    bool split = targets->config.split_rg();
    const ShadingPass& shading = *shading_passes.at({technique.id, s.msaa, split, targets->config.coloured});
    shadow_passes.at(s.msaa)->execute(f);
    if (targets->config.one_pass) {
      one_pass_passes.at({technique.id, s.msaa, s.filter_size})->execute(f);
      if (until_resolve) return;
      mipmap_pass.execute(f);
    } else if (targets->config.moment_images()) {
      // One set of moment images per colour channel with coloured translucency: the resolve
      // writes channel 0 and copies it to the others; the translucent blend uses each channel's
      // opacity.
      resolve_passes.at({technique.id, s.msaa, split})->execute(f);
      if (until_resolve) return;
      if (msm_technique_is_soft(technique.id)) { // tables instead of blur and mips; no translucency
        sat_pass->execute(f, s.resolved_soft_kernel() * s.resolved_soft_kernel());
      } else {
        for (f.channel = 0; f.channel < targets->config.channels(); ++f.channel) {
          if (targets->config.translucent) translucent_passes.at({technique.id, s.msaa, split})->execute(f);
          if (s.filter_size > 1) blur_pass->execute(f);
          mipmap_pass.execute(f); // also hands the moments over to the shading (layouts)
        }
        f.channel = 0;
      }
    }
    if (until_resolve) return;
    shading.execute(f);
  }

  std::vector<PassTime> read_times() {
    std::vector<PassTime> out;
    for (auto& [name, ms] : timer.read().totals()) out.push_back({name, ms});
    return out;
  }

  void read_intermediates(const RenderSettings& s, const Technique& technique, Intermediates& out) {
    vk::submit_and_wait(ctx, [&](VkCommandBuffer cmd) { record(cmd, s, technique, true); });
    timer.read();
    int size = s.shadow_size;
    if (s.msaa == 1) {
      std::vector<std::byte> bytes =
          vk::readback_image(ctx, targets->shadow_depth, VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL);
      out.depth_samples.resize(size_t(size) * size);
      for (size_t i = 0; i < out.depth_samples.size(); ++i) {
        uint16_t v;
        std::memcpy(&v, bytes.data() + 2 * i, 2);
        out.depth_samples[i] = float(v) / 65535.0f;
      }
    } else {
      if (!depth_copy)
        depth_copy = std::make_unique<vk::Program>(
            vk::create_program(ctx, "depth_samples.comp", {vk::Binding::sampled_image, vk::Binding::storage_buffer},
                               sizeof(ImagePassPush)));
      size_t count = size_t(size) * size * size_t(s.msaa);
      vk::Buffer buffer =
          vk::create_buffer(ctx, count * sizeof(float), VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, vk::Memory::host);
      vk::submit_and_wait(ctx, [&](VkCommandBuffer cmd) {
        uint32_t groups = vk::group_count(uint32_t(size), 8);
        vk::dispatch(cmd, *depth_copy, groups, groups, 1,
                     {vk::Descriptor(targets->shadow_depth.view(), VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL,
                                     targets->point_sampler),
                      vk::Descriptor(buffer)},
                     ImagePassPush{glm::ivec4(size, size, s.msaa, 0)});
      });
      std::span<const float> mapped = buffer.mapped<const float>();
      out.depth_samples.assign(mapped.begin(), mapped.begin() + std::ptrdiff_t(count));
    }
    for (int i = 0; i < targets->config.moment_images(); ++i) {
      std::vector<std::byte> bytes = vk::readback_image(ctx, targets->moments[size_t(i)], VK_IMAGE_LAYOUT_GENERAL);
      VkFormat format = VkFormat(targets->config.formats()[size_t(i)]);
      if (format == VK_FORMAT_R32_UINT) {
        out.packed.resize(size_t(size) * size);
        std::memcpy(out.packed.data(), bytes.data(), out.packed.size() * 4);
        continue;
      }
      (i == 0 ? out.moments : out.moments1) = to_float_image(bytes, format, size, size);
    }
  }
};

Renderer::Renderer(const vk::Context& ctx, const scene::Scene& scene) : impl_(std::make_unique<Impl>(ctx, scene)) {}
Renderer::~Renderer() = default;
const scene::Scene& Renderer::scene() const noexcept { return impl_->scene; }

RenderResult Renderer::render(const RenderSettings& s, Intermediates* intermediates) {
  Impl& m = *impl_;
  const Technique& technique = m.prepare(s);
  if (intermediates) m.read_intermediates(s, technique, *intermediates);
  vk::submit_and_wait(m.ctx, [&](VkCommandBuffer cmd) { m.record(cmd, s, technique, false); });
  RenderResult r;
  r.passes = m.read_times();
  for (const PassTime& p : r.passes) r.total_ms += p.ms;
  if (intermediates && m.targets->config.moment_images() && m.targets->config.formats()[0] != VK_FORMAT_R32_UINT)
    intermediates->filtered =
        to_float_image(vk::readback_image(m.ctx, m.targets->moments[0], VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL),
                       VkFormat(m.targets->config.formats()[0]), s.shadow_size, s.shadow_size);

  std::vector<std::byte> color = vk::readback_image(m.ctx, m.targets->color, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL);
  r.color = image::Image(s.width, s.height, 3);
  std::span<float> c = r.color.pixels();
  for (size_t i = 0; i < r.color.pixel_count(); ++i)
    for (size_t k = 0; k < 3; ++k) c[3 * i + k] = image::srgb_to_linear(float(uint8_t(color[4 * i + k])) / 255.0f);

  std::vector<std::byte> shadow =
      vk::readback_image(m.ctx, m.targets->shadow_buffer, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL);
  // RGBA32F: visibility per colour channel, coverage. With coloured translucency "visibility" is
  // the mean of the channels (as the ray tracer's), and the channels come along.
  bool coloured = m.targets->config.coloured;
  r.shadow = image::Image(s.width, s.height, {"visibility", "background"});
  if (coloured) r.shadow_rgb = image::Image(s.width, s.height, {"visibility_r", "visibility_g", "visibility_b"});
  std::span<float> v = r.shadow.pixels();
  for (size_t i = 0; i < r.shadow.pixel_count(); ++i) {
    float px[4];
    std::memcpy(px, shadow.data() + 16 * i, 16);
    v[2 * i] = coloured ? (px[0] + px[1] + px[2]) / 3.0f : px[0];
    v[2 * i + 1] = 1.0f - px[3];
    if (coloured)
      for (size_t c = 0; c < 3; ++c) r.shadow_rgb.pixels()[3 * i + c] = px[c];
  }
  return r;
}

std::vector<std::vector<PassTime>> Renderer::time_frames(const RenderSettings& s, int frames) {
  if (frames < 1) throw RenderError("time_frames: at least one frame");
  Impl& m = *impl_;
  const Technique& technique = m.prepare(s);
  std::vector<std::vector<PassTime>> out;
  for (int i = 0; i < frames; ++i) {
    vk::submit_and_wait(m.ctx, [&](VkCommandBuffer cmd) { m.record(cmd, s, technique, false); });
    out.push_back(m.read_times());
  }
  return out;
}

} // namespace msm::render
