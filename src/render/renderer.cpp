// The frame: settings -> configuration -> frame graph (recipes.cpp, frame_graph.h), uniforms of the
// frame and of its lights, recording, readback. Graphs are rebuilt when the configuration changes;
// pipelines stay in the program cache.
#include "msm/render/renderer.h"

#include "depth_bounds.h"
#include "frame_config.h"
#include "frame_graph.h"
#include "gpu_scene.h"
#include "passes/pass.h"
#include "program_cache.h"
#include "recipes.h"

#include "msm/cascade.h"
#include "msm/cube_face.h"
#include "msm/filter.h"
#include "msm/gpu/sat_builder.h"
#include "msm/noise/blue_noise.h"
#include "msm/render/frame.h"
#include "msm/render/rectification_uniforms.h"
#include "msm/render/renderer_internals.h"
#include "msm/sat.h"
#include "msm/scattering.h"
#include "msm/shading.h"
#include "msm/soft.h"
#include "msm/techniques.h"
#include "msm/util/limits.h"

#include <fmt/format.h>
#include <glm/gtc/matrix_transform.hpp>
#include <glm/gtc/packing.hpp>

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <cstring>
#include <type_traits>

namespace msm::render {

// The lights' storage buffer: the frame's lights, then each one's sub-lights after a summary entry
// (at most 256 lights, 256 sub-lights and 256 summaries).
constexpr std::size_t kLightSlots = 3 * MSM_MAX_LIGHTS;
static_assert(MSM_MAX_LIGHTS == scene::kMaxLights);

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

// Layer 0 of a readback (layers are tightly packed, layer after layer).
image::Image to_float_image(std::span<const std::byte> bytes, VkFormat format, int width, int height) {
  int channels = 0;
  enum { unorm16, half, single } kind = single;
  switch (format) {
  case VK_FORMAT_R16G16B16A16_UNORM: channels = 4, kind = unorm16; break;
  case VK_FORMAT_R16G16_UNORM: channels = 2, kind = unorm16; break;
  case VK_FORMAT_R16G16B16A16_SFLOAT: channels = 4, kind = half; break;
  case VK_FORMAT_R16G16_SFLOAT: channels = 2, kind = half; break;
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

// Whether any draw, opaque or translucent, reads an albedo or opacity texture (FrameConfig::textured_draws).
bool has_textured_draws(const GpuScene& scene) {
  auto textured = [](const Draw& d) { return d.push.flags.x != 0 || d.push.flags.z != 0; };
  return std::ranges::any_of(scene.draws, textured) || std::ranges::any_of(scene.translucent, textured);
}

bool has_features(const vk::Context& ctx, VkFormat format, VkFormatFeatureFlags features) {
  VkFormatProperties props{};
  vkGetPhysicalDeviceFormatProperties(ctx.physical_device(), format, &props);
  return (props.optimalTilingFeatures & features) == features;
}

// The levels of a full mip chain of a size² image when it is wanted and the device can make it by
// linear blits and filter it in each of `formats` (VK_FORMAT_UNDEFINED: no image); else 1.
template <size_t N>
uint32_t mip_chain_levels(const vk::Context& ctx, bool wanted, const std::array<VkFormat, N>& formats, int count,
                          int size) {
  for (int i = 0; i < count && wanted; ++i)
    wanted = formats[size_t(i)] == VK_FORMAT_UNDEFINED ||
             has_features(ctx, formats[size_t(i)],
                          VK_FORMAT_FEATURE_BLIT_SRC_BIT | VK_FORMAT_FEATURE_BLIT_DST_BIT |
                              VK_FORMAT_FEATURE_SAMPLED_IMAGE_FILTER_LINEAR_BIT);
  return wanted ? uint32_t(std::bit_width(uint32_t(size))) : 1u;
}

} // namespace

// The shading's lookup (MSM_LOOKUP_*): the settings', else dithered for the non-linear maps (their
// texels are decoded before any interpolation) and bilinear for the others.
int resolved_lookup(const RenderSettings& s, const Technique& technique) {
  switch (s.lookup) {
  case RenderSettings::Lookup::nearest: return MSM_LOOKUP_NEAREST;
  case RenderSettings::Lookup::dither: return MSM_LOOKUP_DITHER;
  case RenderSettings::Lookup::bilinear: return MSM_LOOKUP_BILINEAR;
  default: return msm_technique_is_nonlinear(technique.id) ? MSM_LOOKUP_DITHER : MSM_LOOKUP_BILINEAR;
  }
}

std::vector<float> filter_weights(const RenderSettings& s) {
  std::vector<float> w(size_t(s.filter_size));
  for (int k = 0; k < s.filter_size; ++k) w[size_t(k)] = msm_gaussian_weight(k, s.filter_size, s.filter_sigma);
  return w;
}

struct Renderer::Impl {
  const vk::Context& ctx;
  scene::Scene scene;
  GpuScene gpu;
  vk::Buffer uniforms, lights;
  vk::Buffer rectification; // RectificationUniforms per light (prefiltered scattering)
  vk::Buffer soft_clamps;   // the soft lookups unclamped and clamped (soft_clamps.glsl), zeroed per frame
  vk::GpuTimer timer;
  vk::Image noise;
  vk::Sampler point_sampler, linear_sampler;
  vk::Sampler repeat_sampler; // prefiltered scattering's lookups (scatter.glsl clamps u itself)
  ProgramCache programs;
  gpu::SatBuilder sat_builder;
  std::unique_ptr<vk::Program> depth_copy;
  FrameConfig config;
  std::unique_ptr<FrameGraph> graph;
  std::vector<LightUniforms> light_data;
  ScatteringPush scattering{}; // scattering techniques
  // Fitting a light's frustum visits every vertex: one fit per light direction, kept.
  // The fitted frame of each light, by its direction and x axis (light_frame).
  std::vector<std::pair<std::pair<glm::vec3, std::optional<glm::vec3>>, scene::LightFrame>> frames;
  // The cascades of each light (scene::fit_cascades) by its direction, x axis and the settings they
  // follow; and one_map_too_coarse by image and map size. Both follow the camera and the vertices.
  struct CascadeKey {
    glm::vec3 towards_light;
    std::optional<glm::vec3> x_axis;
    int count, shadow_size;
    float lambda;
    bool stabilize;
    std::optional<glm::dvec2> depth_range;
    bool operator==(const CascadeKey&) const = default;
  };
  std::vector<std::pair<CascadeKey, std::vector<scene::Cascade>>> cascade_fits;
  // The camera's depth bounds (RenderSettings::cascade_depth_bounds reduce), made on first use; the
  // range the frame's cascades split (unset: the scene's estimate) and the GPU time of measuring
  // it, which the next read_times reports as the pass "depth_bounds".
  std::unique_ptr<DepthBoundsReducer> depth_bounds;
  std::optional<glm::dvec2> split_range;
  std::optional<double> depth_bounds_ms;
  mutable std::vector<std::pair<glm::ivec3, bool>> too_coarse;

  Impl(const vk::Context& c, const scene::Scene& s)
      : ctx(c), scene(s), gpu(c, s),
        uniforms(vk::create_buffer(c, sizeof(FrameUniforms), VK_BUFFER_USAGE_UNIFORM_BUFFER_BIT, vk::Memory::host)),
        lights(vk::create_buffer(c, sizeof(LightUniforms) * kLightSlots, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT,
                                 vk::Memory::host)),
        rectification(vk::create_buffer(c, sizeof(RectificationUniforms) * MSM_MAX_LIGHTS,
                                        VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, vk::Memory::host)),
        soft_clamps(
            vk::create_buffer(c, 2 * sizeof(std::uint32_t), VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, vk::Memory::host)),
        timer(c, 32), noise(upload_blue_noise(c)), point_sampler(vk::create_sampler(c, VK_FILTER_NEAREST)),
        linear_sampler(vk::create_sampler(c, VK_FILTER_LINEAR)),
        repeat_sampler(vk::create_sampler(c, VK_FILTER_LINEAR, VK_SAMPLER_ADDRESS_MODE_REPEAT)), programs(c),
        sat_builder(c) {}

  static vk::Image upload_blue_noise(const vk::Context& ctx) {
    const msm::noise::BlueNoise& n = msm::noise::blue_noise();
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

  const scene::LightFrame& light_frame(const scene::DirectionalLight& light) {
    const std::pair<glm::vec3, std::optional<glm::vec3>> key(light.towards_light, light.x_axis);
    for (const auto& [k, frame] : frames)
      if (k == key) return frame;
    if (frames.size() >= 64) frames.clear();            // a light dragged around in a viewer
    frames.emplace_back(key, scene.light_frame(light)); // depends on the direction and x axis only
    return frames.back().second;
  }

  const std::vector<scene::Cascade>& cascade_fit(const RenderSettings& s, const scene::DirectionalLight& light,
                                                 int count) {
    const CascadeKey key{light.towards_light, light.x_axis,        count,      s.shadow_size,
                         s.cascade_lambda,    s.cascade_stabilize, split_range};
    for (const auto& [k, fit] : cascade_fits)
      if (k == key) return fit;
    if (cascade_fits.size() >= 64) cascade_fits.clear(); // a light dragged around in a viewer
    const scene::CascadeOptions options{
        .count = count, .lambda = s.cascade_lambda, .stabilize = s.cascade_stabilize, .depth_range = split_range};
    cascade_fits.emplace_back(key, scene::fit_cascades(scene, light, s.shadow_size, options));
    return cascade_fits.back().second;
  }

  // The view depths the frame's cascades split: with cascade_depth_bounds reduce, the camera's depth
  // buffer's range, measured anew each frame (the readback stalls: an engine would split with the
  // previous frame's); unset (fit_cascades' scene estimate) with scene, one map, or no surface seen.
  void measure_split_range(const RenderSettings& s, int count) {
    split_range.reset();
    depth_bounds_ms.reset();
    if (count <= 1 || s.cascade_depth_bounds != RenderSettings::CascadeDepthBounds::reduce) return;
    if (!depth_bounds) depth_bounds = std::make_unique<DepthBoundsReducer>(ctx, programs);
    const DepthBounds b = depth_bounds->measure(gpu, scene.camera, s.width, s.height);
    depth_bounds_ms = b.ms;
    if (b.any) split_range = b.view_depth;
  }

  // The cascades per directional light of these settings (resolved_cascades, its measure cached).
  int cascades(const RenderSettings& s) const {
    if (s.cascades || cascades_unsupported(s, scene)) return resolved_cascades(s, scene, false);
    const glm::ivec3 key(s.width, s.height, s.shadow_size);
    auto it = std::ranges::find(too_coarse, key, &std::pair<glm::ivec3, bool>::first);
    if (it == too_coarse.end()) {
      too_coarse.emplace_back(key, one_map_too_coarse(s, scene));
      it = too_coarse.end() - 1;
    }
    return resolved_cascades(s, scene, it->second);
  }

  // The layers (and shading entries) of the frame's shadow-map arrays: the directional lights'
  // cascades, then one per spot light, then six per point light (its cube faces).
  int layers(const RenderSettings& s) const {
    return int(lights_of(s).size()) * cascades(s) + int(spot_lights().size()) + int(kCubeFaces * point_lights().size());
  }

  const std::vector<scene::DirectionalLight>& lights_of(const RenderSettings& s) const {
    return s.lights.empty() ? scene.lights : s.lights;
  }

  // The scene's spot lights, whose shadow-map layers follow the directional lights'.
  std::vector<scene::LocalLight> spot_lights() const {
    std::vector<scene::LocalLight> spots;
    std::ranges::copy_if(scene.local_lights, std::back_inserter(spots), &scene::LocalLight::spot);
    return spots;
  }

  // The scene's point lights, six layers each (one per cube face), after the spot lights'.
  std::vector<scene::LocalLight> point_lights() const {
    std::vector<scene::LocalLight> points;
    std::ranges::copy_if(scene.local_lights, std::back_inserter(points),
                         [](const scene::LocalLight& l) { return l.kind == scene::LightKind::point; });
    return points;
  }

  static constexpr std::size_t kCubeFaces = 6;

  FrameUniforms frame_uniforms(const RenderSettings& s, const Technique& technique) const {
    FrameUniforms u{};
    u.camera_view_projection = scene.camera_view_projection(float(s.width) / float(s.height));
    u.technique_params = s.parameter_vector();
    bool area_light = msm_technique_is_area_light(technique.id);
    float depth_bias = s.resolved_depth_bias();
    // The tables' techniques bias in soft.h (u.soft.z); PCSS, like every other, in the fragment depth.
    u.shadow_map = glm::vec4(float(s.shadow_size), 1.0f / float(s.shadow_size), 0.0f,
                             msm_technique_is_soft(technique.id) ? 0.0f : depth_bias);
    if (area_light) {
      // The constant part of msm_soft_depth_bias, in [-1,1] depth.
      u.soft = glm::vec4(0.0f, 0.0f, 2.0f * depth_bias, MSM_SOFT_UMBRA_EPSILON);
      int kernel = s.resolved_soft_kernel();
      u.soft_kernel = glm::ivec4(kernel, int(msm_sat_scale(kernel * kernel)), 0, 0); // the uint's bits
    }
    u.shading = glm::vec4(s.overdarken, s.exposure, s.translucent_alpha_threshold, 0.0f);
    u.kernel = glm::ivec4(s.filter_size, s.msaa, s.filter_size / 2, 0);
    std::vector<float> weights = filter_weights(s);
    for (int k = 0; k < s.filter_size; ++k) u.filter_weights[k / 4][k % 4] = weights[size_t(k)];
    std::vector<glm::vec2> offsets =
        ctx.properties().limits.standardSampleLocations ? standard_sample_offsets(s.msaa) : std::vector<glm::vec2>(8);
    int lookup = resolved_lookup(s, technique);
    // A different blue-noise layer and offset each frame (a fixed hash of the frame number).
    uint32_t h = uint32_t(s.frame) * 2654435761u + 0x9e3779b9u;
    h ^= h >> 15;
    h *= 2246822519u;
    h ^= h >> 13;
    u.lookup = glm::ivec4(lookup, int(h % uint32_t(msm::noise::blue_noise().count)), int((h >> 8) & 63u),
                          int((h >> 16) & 63u));
    for (size_t i = 0; i < offsets.size(); ++i) {
      u.sample_offsets[i / 2][int(2 * (i % 2))] = offsets[i].x;
      u.sample_offsets[i / 2][int(2 * (i % 2) + 1)] = offsets[i].y;
    }
    u.receiver_bias = glm::vec4(layer_kernel(s, 1.0f, false).z, 0.0f, 0.0f, 0.0f);
    u.lights = glm::ivec4(layers(s), 0, 0, 0);
    u.camera_viewport = glm::vec4(float(s.width), float(s.height), 0.0f, 0.0f);
    return u;
  }

  // LightUniforms::kernel of a layer whose texels are 1 / scale times the size of the first
  // cascade's (1: every layer but the farther cascades): the Gaussian whose filter has the same
  // width in world units (msm/cascade.h), with what the chain adds in the layer's own texels (the
  // bilinear lookup's tent, 1/6 texel², and the MSAA sample positions': the resolve averages depths
  // taken there; mean of x and y); and, for the receiver-plane bias (lookup.glsl, msm/bias.h), its
  // variance per axis in texels² with the MSAA positions' (the lookup adds its own), and its
  // multiplier (RenderSettings::resolved_receiver_plane_bias: a cascade's map or another).
  glm::vec4 layer_kernel(const RenderSettings& s, float scale, bool cascade) const {
    std::vector<glm::vec2> offsets =
        ctx.properties().limits.standardSampleLocations ? standard_sample_offsets(s.msaa) : std::vector<glm::vec2>(8);
    double msaa_variance = 0.0;
    for (const glm::vec2& o : offsets) msaa_variance += 0.5 * double(o.x * o.x + o.y * o.y) / double(offsets.size());
    const int taps = msm_cascade_filter_taps(s.filter_size, scale);
    const float sigma =
        msm_cascade_filter_sigma(s.filter_size, s.filter_sigma, scale, float(msaa_variance + 1.0 / 6.0));
    return glm::vec4(sigma, float(taps), float(msm_gaussian_variance(taps, sigma) + msaa_variance),
                     s.resolved_receiver_plane_bias(cascade));
  }

  LightUniforms light_uniforms(const RenderSettings& s, const Technique& technique,
                               const scene::DirectionalLight& light, const scene::LightFrame& f) {
    LightUniforms u{};
    u.view_projection = f.view_projection;
    u.normal_matrix = glm::mat4(glm::transpose(glm::inverse(glm::mat3(f.view_projection))));
    glm::dvec2 texel = f.texel(s.shadow_size);
    u.towards_light = glm::vec4(light.towards_light, s.normal_offset * float(texel.x));
    u.irradiance = glm::vec4(light.irradiance, 0.0f);
    u.kernel = layer_kernel(s, 1.0f, false);
    if (msm_technique_is_area_light(technique.id)) {
      // The light's two half extents along the frame's axes (a disc: its radius both), the search
      // region and filter per axis from them.
      const scene::DirectionalLight drawn = scene::overridden_light(light, s.light_extent_deg, s.light_height_deg);
      // soft.h: texels of reach per unit of [-1,1] depth.
      vec2 spread = msm_soft_spread(drawn.tan_half_extents(), float(0.5 * f.depth_extent), vec2(texel));
      // The shading integrates the cosine over the disc (msm_cone_cosine), or over the rectangle
      // clipped by the horizon (msm_rect_light_cosine, on the frame's x axis as the ray tracer
      // samples it); the other techniques shade their lights as points (soft.z = 0, rect_extent = 0:
      // max(n·l, 0)), as their shadows are hard.
      u.soft = glm::vec4(spread, drawn.cone_half_angle(), 0.0f);
      u.rect_x_axis = glm::vec4(glm::vec3(f.x_axis), 0.0f);
      u.rect_extent = glm::vec4(drawn.rectangle_extents(), 0.0f, 0.0f);
    }
    return u;
  }

  // A directional light's entries of lights[]: one, or one per cascade with the view depths of its
  // share (msm/cascade.h), each with its own map and normal offset (of its own texels) and the
  // filter of the first cascade's width in world units.
  void add_directional_light(const RenderSettings& s, const Technique& technique, const scene::DirectionalLight& light,
                             int count) {
    if (count == 1) {
      light_data.push_back(light_uniforms(s, technique, light, light_frame(light)));
      return;
    }
    const std::vector<scene::Cascade>& cascades = cascade_fit(s, light, count);
    const double first_texel = cascades.front().frame.texel(s.shadow_size).x;
    for (const scene::Cascade& c : cascades) {
      LightUniforms u = light_uniforms(s, technique, light, c.frame);
      u.cascade = glm::vec4(float(c.fade_in.x), float(c.fade_in.y), float(c.fade_out.x), float(c.fade_out.y));
      u.kernel = layer_kernel(s, float(first_texel / c.frame.texel(s.shadow_size).x), true);
      light_data.push_back(u);
    }
  }

  // A spot light as the shadow pass and the shading read it (docs/techniques.md, "Light kinds"): a
  // perspective map over the outer cone, radial distance / range its depth; the normal offset of
  // RenderSettings::normal_offset texels of the map's width where the receiver is.
  // Soft shadows: soft.w the sphere's radius (soft.h's spot geometry; the shading's cone of the
  // sphere); 0 for the techniques of hard shadows, which shade a point.
  static LightUniforms spot_light_uniforms(const RenderSettings& s, const Technique& technique,
                                           const scene::LocalLight& spot) {
    const glm::vec3 up = std::abs(spot.direction.y) > 0.99f ? glm::vec3(0.0f, 0.0f, 1.0f) : glm::vec3(0.0f, 1.0f, 0.0f);
    const float outer = glm::radians(spot.outer_cone_deg);
    // The near plane clips nothing (depth clamp, gl_FragDepth): it only has to be positive.
    const glm::mat4 projection = glm::perspective(2.0f * outer, 1.0f, 1e-3f * spot.range, spot.range);
    LightUniforms u{};
    u.view_projection = projection * glm::lookAt(spot.position, spot.position + spot.direction, up);
    u.normal_matrix = glm::mat4(glm::transpose(glm::inverse(glm::mat3(u.view_projection))));
    u.irradiance = glm::vec4(spot.intensity, 0.0f);
    u.spot_position = glm::vec4(spot.position, spot.range);
    u.spot_axis = glm::vec4(spot.direction, std::tan(outer));
    const float texel_angle = 2.0f * std::tan(outer) / float(s.shadow_size);
    u.spot_cone = glm::vec4(spot.cos_outer(), spot.cos_inner(), s.normal_offset * texel_angle, 0.0f);
    if (msm_technique_is_area_light(technique.id)) u.soft = glm::vec4(0.0f, 0.0f, 0.0f, spot.radius);
    return u;
  }

  // Face `face` of a point light as the shadow pass and the shading read it: a spot light's entry
  // (radial distance / range, the same biases) whose perspective view looks along the face's axis
  // (msm/cube_face.h) over a square a guard band wider than the face's 90 degrees, so that the
  // blur and the lookup's filter near a seam read the neighbouring face's texels rendered, not a
  // clamped edge (docs/techniques.md, "Light kinds"). spot_cone.w: the face's number + 1, which
  // the shading reads to evaluate the light once, at its first face's entry, from the face that
  // holds the receiver's direction.
  // Soft shadows: soft.w the sphere's radius, as a spot's (soft.h's spot geometry in the face's
  // perspective).
  static LightUniforms point_face_uniforms(const RenderSettings& s, const Technique& technique,
                                           const scene::LocalLight& point, int face) {
    const float g = msm_cube_face_half_width(float(point_light_guard_texels(s, technique)), float(s.shadow_size));
    const glm::mat4 projection = glm::perspective(2.0f * std::atan(g), 1.0f, 1e-3f * point.range, point.range);
    LightUniforms u{};
    u.view_projection =
        projection * glm::lookAt(point.position, point.position + msm_cube_face_forward(face), msm_cube_face_up(face));
    u.normal_matrix = glm::mat4(glm::transpose(glm::inverse(glm::mat3(u.view_projection))));
    u.irradiance = glm::vec4(point.intensity, 0.0f);
    u.spot_position = glm::vec4(point.position, point.range);
    u.spot_axis = glm::vec4(msm_cube_face_forward(face), g);
    const float texel_angle = 2.0f * g / float(s.shadow_size);
    u.spot_cone = glm::vec4(point.cos_outer(), point.cos_inner(), s.normal_offset * texel_angle, float(face + 1));
    if (msm_technique_is_area_light(technique.id)) u.soft = glm::vec4(0.0f, 0.0f, 0.0f, point.radius);
    return u;
  }

  // The guard band of a point light's faces, in texels beyond the 90-degree part on each side: the
  // lookup's reach — the blur's radius and past it PCF's taps + 1, a bilinear fetch, the MSAA
  // samples; for the soft techniques (no blur) the widest search or filter region, half the kernel
  // width W (soft.h clamps every region to it), plus the grid-aligned search rectangle's rounding
  // out to whole texels — the normal offset, which can move the looked-up point past the seam of
  // the face picked for the surface, and two texels for the coarser mips and the receiver-plane
  // slope.
  static int point_light_guard_texels(const RenderSettings& s, const Technique& technique) {
    const int reach =
        msm_technique_is_area_light(technique.id) ? (s.resolved_soft_kernel() + 1) / 2 + 1 : s.filter_size / 2 + 2;
    return reach + int(std::ceil(s.normal_offset)) + 2;
  }

  // A sub-light as the shading reads it: its direction, irradiance (on a surface facing it) and the
  // rectangle of msm_light_cosine; no shadow map of its own.
  static LightUniforms sub_light_uniforms(const scene::DirectionalLight& sub) {
    LightUniforms u{};
    u.towards_light = glm::vec4(sub.towards_light, 0.0f);
    u.irradiance = glm::vec4(sub.irradiance, 0.0f);
    u.soft = glm::vec4(0.0f, 0.0f, sub.cone_half_angle(), 0.0f);
    u.rect_x_axis = glm::vec4(sub.x_axis.value_or(glm::vec3(0.0f)), 0.0f);
    u.rect_extent = glm::vec4(sub.rectangle_extents(), 0.0f, 0.0f);
    return u;
  }

  // The entry before a light's sub-lights (frame.h's SubLightsSummary).
  static LightUniforms sub_lights_summary(const scene::DirectionalLight& light) {
    const scene::SubLightsLinearPart part = scene::sub_lights_linear_part(light);
    return msm_sub_lights_summary_entry({part.irradiance_by_direction, part.bounds, part.x_axis, part.y_axis});
  }

  // The settings are valid and this device can render them (RenderError naming what it lacks).
  void check(const RenderSettings& s) const {
    s.validate();
    try {
      RenderSettings counted = s; // its cascades' maps too
      counted.cascades = cascades(s);
      check_limits(counted, scene.triangle_count(), scene.lights.size());
    } catch (const limits::LimitError& e) { throw RenderError(e.what()); }
    if (!vk::supports_attachment(ctx, VK_FORMAT_D16_UNORM, VkSampleCountFlagBits(s.msaa)))
      throw RenderError(
          fmt::format("{} cannot render 16-bit depth with {}x MSAA; use --msaa 1 or 4", ctx.info().name, s.msaa));
    if (uint32_t(std::max(s.width, s.height)) > ctx.properties().limits.maxImageDimension2D ||
        uint32_t(s.shadow_size) > ctx.properties().limits.maxImageDimension2D)
      throw RenderError(fmt::format("{} supports images up to {} texels per side", ctx.info().name,
                                    ctx.properties().limits.maxImageDimension2D));
    // CSSM stacks its tiles along y in one image (cssm.h).
    const int tiles = msm_technique_tiles(find_rendered_technique(s.technique).id);
    if (std::uint64_t(s.shadow_size) * std::uint64_t(tiles) > ctx.properties().limits.maxImageDimension2D)
      throw RenderError(fmt::format("{} stacks {} shadow maps of {}² in one image: {} supports {} texels per side; use "
                                    "--shadow-size {} or less",
                                    s.technique, tiles, s.shadow_size, ctx.info().name,
                                    ctx.properties().limits.maxImageDimension2D,
                                    ctx.properties().limits.maxImageDimension2D / uint32_t(tiles)));
    const std::vector<scene::DirectionalLight>& frame_lights = lights_of(s);
    std::size_t slots = frame_lights.size();
    for (const scene::DirectionalLight& l : frame_lights) slots += l.sub_lights.size() + (l.sub_lights.empty() ? 0 : 1);
    if (slots > kLightSlots)
      throw RenderError(
          fmt::format("{} lights, sub-lights and their summaries: the renderer holds {}", slots, kLightSlots));
    const std::vector<scene::LocalLight> spots = spot_lights(), points = point_lights();
    const std::size_t cascade_layers = frame_lights.size() * std::size_t(cascades(s) - 1);
    slots += spots.size() + kCubeFaces * points.size() + cascade_layers;
    if (slots > kLightSlots)
      throw RenderError(fmt::format("{} lights, sub-lights, their summaries, cascades and point lights' faces (6 "
                                    "each): the renderer holds {}",
                                    slots, kLightSlots));
    if (!spots.empty()) check_spot_lights(s, spots, "spot");
    if (!points.empty()) check_spot_lights(s, points, "point");
    if (std::size_t(layers(s)) > ctx.properties().limits.maxImageArrayLayers)
      throw RenderError(fmt::format("{} shadow-map layers ({} cascades per directional light, 6 per point light): {} "
                                    "supports {} layers per image",
                                    layers(s), cascades(s), ctx.info().name,
                                    ctx.properties().limits.maxImageArrayLayers));
  }

  // What the renderer draws with spot and point lights (`kind`): the hard and filtered techniques
  // of one depth per texel and the soft techniques, opaque and translucent occluders, a finite range
  // (the stored depth is distance / range); with spot lights also single scattering, by ray marching
  // and prefiltered (rectification.h's spot section).
  void check_spot_lights(const RenderSettings& s, const std::vector<scene::LocalLight>& spots,
                         std::string_view kind) const {
    const Technique& technique = find_rendered_technique(s.technique);
    const bool spot = kind == "spot";
    if (spot && technique.prefiltered_scattering()) check_spot_prefiltered_scattering(s, technique, spots);
    const char* unsupported = !spot && technique.scatters() ? "scattering" : nullptr;
    if (unsupported)
      throw RenderError(fmt::format("{} with {} lights: the renderer draws {} lights' hard, filtered and soft shadows "
                                    "only; the ray tracer (msm reference) traces them",
                                    unsupported, kind, kind));
    if (!spot) check_point_light_guard_band(s, technique);
    for (const scene::LocalLight& spot : spots)
      if (!(spot.range < scene::LocalLight::kInfiniteRange))
        throw RenderError(fmt::format("a {} light without \"range\": the renderer's {} shadow maps store distance / "
                                      "range, so a {} light it draws needs a finite range",
                                      kind, kind, kind));
  }

  // The prefiltered scattering of spot lights (rectification.h's spot section): the spot's map
  // resampled without filtering, one weight per row (no transmittance layers), and a camera off the
  // light (the rectification's axis runs from the light through the camera).
  void check_spot_prefiltered_scattering(const RenderSettings& s, const Technique& technique,
                                         const std::vector<scene::LocalLight>& spots) const {
    const std::string resampling = s.parameter_text("resampling");
    if (resampling != "none")
      throw RenderError(fmt::format("{} with spot lights and --set resampling={}: a spot light's rectified map is "
                                    "resampled without filtering only (--set resampling=none)",
                                    technique.name, resampling));
    if (transmittance_layers(s) != 1)
      throw RenderError(fmt::format("{} with spot lights and --set layers={}: a spot light's prefix sums weigh each "
                                    "row at one angle, without transmittance layers (--set layers=1)",
                                    technique.name, transmittance_layers(s)));
    for (const scene::LocalLight& spot : spots)
      if (!(glm::distance(scene.camera.position, spot.position) > 1e-4f * spot.range))
        throw RenderError(fmt::format("{}: the camera is at a spot light's position; the prefiltered scattering "
                                      "rectifies about the line from the light through the camera",
                                      technique.name));
  }

  // A point light's faces keep at least half their texels per side for their 90-degree part: a
  // guard band (point_light_guard_texels) of more than a quarter of the map on each side would
  // leave the cube too few texels (and at half the map none).
  static void check_point_light_guard_band(const RenderSettings& s, const Technique& technique) {
    const int guard = point_light_guard_texels(s, technique);
    if (4 * guard <= s.shadow_size) return;
    const bool soft = msm_technique_is_area_light(technique.id);
    throw RenderError(fmt::format(
        "{} with point lights at --shadow-size {}: each cube face's guard band ({} texels on each side, the {} and the "
        "normal offset) would take more than a quarter of the face's map; use --shadow-size {} or more{}",
        technique.name, s.shadow_size, guard, soft ? "soft kernel's half width" : "filter's reach", 4 * guard,
        soft ? " or a smaller soft kernel" : " or a smaller filter"));
  }

  // Validates, (re)builds the frame graph where the configuration changed, writes the uniforms.
  const Technique& prepare(const RenderSettings& s) {
    check(s);
    const Technique& technique = find_rendered_technique(s.technique);
    const std::vector<scene::DirectionalLight>& frame_lights = lights_of(s);
    bool one_pass = s.one_pass.value_or(technique.one_pass_default());
    bool translucent =
        s.translucent_occluders && !gpu.translucent.empty() && supports_translucency(technique) && !one_pass;
    FrameConfig c{.technique = &technique,
                  .width = s.width,
                  .height = s.height,
                  .shadow_size = s.shadow_size,
                  .msaa = s.msaa,
                  .taps = s.filter_size,
                  .sigma = s.filter_sigma,
                  .lights = layers(s),
                  .one_pass = one_pass,
                  .translucent = translucent,
                  .coloured = translucent && s.coloured_translucency,
                  .soft_kernel = technique.soft() ? s.resolved_soft_kernel() : 0,
                  .lookup = resolved_lookup(s, technique),

                  .deferred = s.deferred_shading.value_or(default_deferred_shading(technique)) &&
                              supports_deferred_shading(technique),
                  .textured_draws = has_textured_draws(gpu),
                  .sub_lights = std::ranges::any_of(
                      lights_of(s), [](const scene::DirectionalLight& l) { return !l.sub_lights.empty(); }),
                  .front_back = s.front_back_depth,
                  .spot_lights = int(spot_lights().size()),
                  .point_lights = int(point_lights().size()),
                  .cascades = cascades(s)};
    // The non-linear maps are decoded before any interpolation and the tables replace the mips: only
    // the linear maps get a mip chain, where the device can blit their formats.
    c.mip_levels =
        mip_chain_levels(ctx, s.mipmaps && technique.mipmapped(), c.formats(), c.moment_images(), s.shadow_size);
    if (!technique.nonlinear())
      for (int i = 0; i < c.moment_images(); ++i)
        if (!has_features(ctx, c.formats()[size_t(i)], VK_FORMAT_FEATURE_SAMPLED_IMAGE_FILTER_LINEAR_BIT))
          throw RenderError(fmt::format("{} cannot filter format {} linearly ({})", ctx.info().name,
                                        int(c.formats()[size_t(i)]), technique.name));
    // Prefiltered scattering: the transmittance layers (rectification.h), the β and the resampling,
    // whose filtered kind (JCGT §5.2) adds the passes of the frame's blurred, mipmapped 4-moment map
    // (recipe, FrameConfig::resampling_moments).
    const std::string resampling = technique.prefiltered_scattering() ? s.parameter_text("resampling") : "none";
    if (technique.prefiltered_scattering()) {
      c.transmittance_layers = transmittance_layers(s);
      c.prefix_sums_appendix_c = s.prefix_sums == RenderSettings::PrefixSums::appendix_c;
      c.prefix_sum_mips = mip_chain_levels(ctx, s.prefix_sum_mips, c.prefix_sum_formats(), 2, s.shadow_size);
      c.scattering_beta = technique.has_parameter("beta") ? int(s.parameter("beta")) : MSM_SCATTERING_BETA_PROPORTIONAL;
      c.on_the_fly_resampling = resampling == "bilinear-moments";
    }
    if (resampling == "filtered") {
      c.filtered_resampling = true;
      const VkFormat f = c.resampling_moments().formats()[0];
      if (!has_features(ctx, f, VK_FORMAT_FEATURE_SAMPLED_IMAGE_FILTER_LINEAR_BIT))
        throw RenderError(fmt::format("{} cannot filter RGBA32F linearly: the filtered resampling of {} needs it "
                                      "(--set resampling=none resamples without filtering)",
                                      ctx.info().name, technique.name));
      c.resampling_mips = mip_chain_levels(ctx, s.mipmaps, std::array<VkFormat, 1>{f}, 1, s.shadow_size);
    }
    if (!graph || !(config == c)) {
      graph.reset();
      graph = std::make_unique<FrameGraph>(ctx, recipe(c), std::vector<std::string>{}, frame_outputs(c),
                                           PassResources{programs, sat_builder});
      config = c;
    }
    FrameUniforms u = frame_uniforms(s, technique);
    // glm's types are standard-layout with user-written copies (not TriviallyCopyable to the
    // standard); their bytes are the std140/std430 layout the shaders read (frame.h).
    static_assert(std::is_standard_layout_v<FrameUniforms> && std::is_standard_layout_v<LightUniforms>);
    std::memcpy(uniforms.data(), &u, sizeof(u)); // NOLINT(bugprone-undefined-memory-manipulation)
    std::ranges::fill(soft_clamps.mapped<std::uint32_t>(), 0u);
    light_data.clear();
    measure_split_range(s, c.cascades);
    for (const scene::DirectionalLight& light : frame_lights) add_directional_light(s, technique, light, c.cascades);
    const std::size_t first_local_light = light_data.size();
    for (const scene::LocalLight& spot : spot_lights()) light_data.push_back(spot_light_uniforms(s, technique, spot));
    for (const scene::LocalLight& point : point_lights())
      for (int face = 0; face < int(kCubeFaces); ++face)
        light_data.push_back(point_face_uniforms(s, technique, point, face));
    for (std::size_t i = first_local_light; i < light_data.size(); ++i)
      light_data[i].kernel = layer_kernel(s, 1.0f, false);
    // Sub-lights after the frame's lights, each light's after their summary, whose index and the
    // sub-lights' count are in the light's rect_extent.zw (shading.glsl).
    for (std::size_t i = 0; i < frame_lights.size(); ++i) {
      const std::vector<scene::DirectionalLight>& subs = frame_lights[i].sub_lights;
      if (subs.empty()) continue; // and the light has one cascade (cascades_unsupported)
      light_data[i].rect_extent.z = float(light_data.size());
      light_data[i].rect_extent.w = float(subs.size());
      light_data.push_back(sub_lights_summary(frame_lights[i]));
      for (const scene::DirectionalLight& sub : subs) light_data.push_back(sub_light_uniforms(sub));
    }
    // NOLINTNEXTLINE(bugprone-undefined-memory-manipulation): standard layout, see above
    std::memcpy(lights.data(), light_data.data(), light_data.size() * sizeof(LightUniforms));
    scattering = scattering_push(s, technique);
    if (technique.prefiltered_scattering()) {
      std::vector<RectificationUniforms> r;
      for (const scene::DirectionalLight& light : frame_lights) r.push_back(rectification_uniforms(s, light));
      for (const scene::LocalLight& spot : spot_lights()) r.push_back(spot_rectification_uniforms(s, spot));
      // NOLINTNEXTLINE(bugprone-undefined-memory-manipulation): standard layout (vec4 members only)
      std::memcpy(rectification.data(), r.data(), r.size() * sizeof(RectificationUniforms));
    }
    return technique;
  }

  // The scattering pass's parameters: the camera's rays and the scene's medium (none: the pass only
  // tone maps).
  ScatteringPush scattering_push(const RenderSettings& s, const Technique& technique) const {
    ScatteringPush p{};
    glm::dmat4 view_projection(scene.camera_view_projection(float(s.width) / float(s.height)));
    p.inverse_view_projection = glm::mat4(glm::inverse(view_projection));
    p.camera = glm::vec4(scene.camera.position, 0.0f);
    if (scene.medium)
      p.medium = glm::vec4(scene.medium->extinction, scene.medium->scattering_albedo, scene.medium->g, 1.0f);
    p.march = glm::ivec4(msm_technique_march_samples(technique.id), msm_technique_scatter_representation6(technique.id),
                         0, 0);
    for (int c = 0; c < 3; ++c) p.sky[c] = msm_aces_inverse(MSM_SKY_RADIANCE[c]) / s.exposure;
    return p;
  }

  // The camera's far-plane corners in order around the quad (world).
  glm::mat4x3 far_corners(const RenderSettings& s) const {
    glm::dmat4 inverse = glm::inverse(glm::dmat4(scene.camera_view_projection(float(s.width) / float(s.height))));
    glm::mat4x3 corners;
    const glm::dvec2 ndc[4] = {{-1.0, -1.0}, {1.0, -1.0}, {1.0, 1.0}, {-1.0, 1.0}}; // around the quad
    for (int j = 0; j < 4; ++j) {
      glm::dvec4 p = inverse * glm::dvec4(ndc[j], 1.0, 1.0);
      corners[j] = glm::vec3(glm::dvec3(p) / p.w);
    }
    return corners;
  }

  // The rectification of one light for this camera (rectification.h, JCGT Appendix A): the bounds
  // cover the pyramid from the camera to its far plane. The passes read one per light (std430 array).
  RectificationUniforms rectification_uniforms(const RenderSettings& s, const scene::DirectionalLight& light) {
    RectificationFrame f = msm_rectification_frame(scene.camera.position, light.towards_light);
    RectifiedBounds b = msm_rectification_bounds(f, far_corners(s));
    float extinction = scene.medium ? scene.medium->extinction : 0.0f;
    return msm_rectification_uniforms(
        f, b,
        glm::vec4(float(s.shadow_size), float(s.shadow_size), float(light_frame(light).depth_extent), extinction));
  }

  // A spot light's rectification (rectification.h's spot section): the camera's frame towards the
  // light, the view's γ bounds, ψ over the spot's outer cone, φ over the narrower of the view's and
  // the cone's wedges.
  RectificationUniforms spot_rectification_uniforms(const RenderSettings& s, const scene::LocalLight& spot) const {
    RectificationFrame f = msm_spot_rectification_frame(scene.camera.position, spot.position);
    const glm::vec3 axis = glm::normalize(spot.direction);
    const RectifiedBounds b = msm_spot_rectified_bounds(
        msm_rectification_bounds(f, far_corners(s)),
        glm::vec3(glm::dot(f.x_axis, axis), glm::dot(f.y_axis, axis), glm::dot(f.z_axis, axis)),
        glm::radians(spot.outer_cone_deg));
    const float extinction = scene.medium ? scene.medium->extinction : 0.0f;
    RectificationUniforms u =
        msm_rectification_uniforms(f, b, glm::vec4(float(s.shadow_size), float(s.shadow_size), 0.0f, extinction));
    u.spot = glm::vec4(glm::distance(scene.camera.position, spot.position), scene.medium ? scene.medium->g : 0.0f,
                       spot.cos_outer(), spot.cos_inner());
    u.spot_axis = glm::vec4(axis, 0.0f);
    return u;
  }

  void record(VkCommandBuffer cmd, std::optional<std::string_view> stop_after = std::nullopt) {
    timer.reset(cmd);
    FrameResources resources{gpu,   uniforms,      lights,         light_data,
                             noise, point_sampler, linear_sampler, scene.camera.position};
    resources.scattering = scattering;
    resources.rectification = &rectification;
    resources.repeat_sampler = &repeat_sampler;
    resources.soft_clamps = &soft_clamps;
    // The previous frame's counts were written by its shading: ordered before this frame's.
    vk::pipeline_barrier(
        cmd, vk::memory_barrier(VK_PIPELINE_STAGE_2_FRAGMENT_SHADER_BIT, VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT,
                                VK_PIPELINE_STAGE_2_FRAGMENT_SHADER_BIT,
                                VK_ACCESS_2_SHADER_STORAGE_READ_BIT | VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT));
    graph->record(cmd, timer, resources, config, stop_after);
  }

  // Pass totals (outermost scopes) and, with several lights, each light's share.
  void read_times(std::vector<PassTime>& passes, std::vector<LightPassTime>* per_light) {
    if (depth_bounds_ms) passes.push_back({"depth_bounds", *depth_bounds_ms}); // before the frame
    depth_bounds_ms.reset();
    vk::TimerResults r = timer.read();
    for (const vk::TimerScope& scope : r.scopes) {
      if (scope.depth == 0) {
        auto it = std::find_if(passes.begin(), passes.end(), [&](const PassTime& p) { return p.name == scope.name; });
        if (it == passes.end())
          passes.push_back({scope.name, scope.ms()});
        else
          it->ms += scope.ms();
      } else if (per_light) {
        size_t hash = scope.name.rfind('#');
        if (hash != std::string::npos)
          per_light->push_back({scope.name.substr(0, hash), std::stoi(scope.name.substr(hash + 1)), scope.ms()});
      }
    }
  }

  void read_intermediates(const RenderSettings& s, Intermediates& out) {
    std::string_view until = config.one_pass                                      ? "one_pass_filter"
                             : msm_technique_is_depth_based(config.technique->id) ? "shadow_depth"
                                                                                  : "moment_resolve";
    vk::submit_and_wait(ctx, [&](VkCommandBuffer cmd) { record(cmd, until); });
    timer.read();
    int size = s.shadow_size;
    const GraphImage& depth = graph->image(kShadowDepth);
    size_t texels = size_t(size) * size_t(size);
    if (s.msaa == 1) {
      std::vector<std::byte> bytes =
          vk::readback_image(ctx, depth.image, graph->layout_after_record(kShadowDepth)); // every layer
      out.depth_samples.resize(texels);
      for (size_t i = 0; i < texels; ++i) {
        uint16_t v;
        std::memcpy(&v, bytes.data() + 2 * i, 2);
        out.depth_samples[i] = float(v) / 65535.0f;
      }
    } else {
      if (!depth_copy)
        depth_copy = std::make_unique<vk::Program>(
            vk::create_program(ctx, "depth_samples.comp",
                               {{MSM_BINDING_DEPTH_SAMPLES_MAP, vk::Binding::sampled_image},
                                {MSM_BINDING_DEPTH_SAMPLES_BUFFER, vk::Binding::storage_buffer}},
                               sizeof(ImagePassPush)));
      size_t count = texels * size_t(s.msaa);
      vk::Buffer buffer =
          vk::create_buffer(ctx, count * sizeof(float), VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, vk::Memory::host);
      // The frame cut after the depth pass (the depth-based techniques) leaves the map a depth
      // attachment, which a sampled image may not be: it is made read-only first (the next frame
      // creates it anew).
      const VkImageLayout recorded = graph->layout_after_record(kShadowDepth);
      const VkImageLayout layout =
          recorded == VK_IMAGE_LAYOUT_DEPTH_ATTACHMENT_OPTIMAL ? VK_IMAGE_LAYOUT_DEPTH_READ_ONLY_OPTIMAL : recorded;
      vk::submit_and_wait(ctx, [&](VkCommandBuffer cmd) {
        if (layout != recorded)
          vk::pipeline_barrier(cmd, vk::image_barrier(depth.image.handle(), depth.image.aspect(),
                                                      VK_PIPELINE_STAGE_2_LATE_FRAGMENT_TESTS_BIT,
                                                      VK_ACCESS_2_DEPTH_STENCIL_ATTACHMENT_WRITE_BIT, recorded,
                                                      VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT,
                                                      VK_ACCESS_2_SHADER_SAMPLED_READ_BIT, layout));
        uint32_t groups = vk::group_count(uint32_t(size), 8);
        vk::dispatch(cmd, *depth_copy, groups, groups, 1,
                     {{MSM_BINDING_DEPTH_SAMPLES_MAP, vk::Descriptor(depth.layer_views[0], layout, point_sampler)},
                      {MSM_BINDING_DEPTH_SAMPLES_BUFFER, vk::Descriptor(buffer)}},
                     ImagePassPush{glm::ivec4(size, size, s.msaa, 0)});
      });
      std::span<const float> mapped = buffer.mapped<const float>();
      out.depth_samples.assign(mapped.begin(), mapped.begin() + std::ptrdiff_t(count));
    }
    for (int i = 0; i < config.moment_images(); ++i) {
      std::string name = moment_image(0, i);
      std::vector<std::byte> bytes =
          vk::readback_image(ctx, graph->image(name).image, graph->layout_after_record(name));
      VkFormat format = config.formats()[size_t(i)];
      if (format == VK_FORMAT_R32_UINT) {
        out.packed.resize(texels);
        std::memcpy(out.packed.data(), bytes.data(), texels * 4);
        continue;
      }
      (i == 0 ? out.moments : out.moments1) = to_float_image(bytes, format, size, size);
    }
  }
};

std::optional<std::string> soft_kernel_clamp_warning(const SoftKernelClamps& clamps, int kernel_width) {
  if (!(clamps.share() > kSoftKernelClampWarnShare)) return std::nullopt;
  return fmt::format(
      "warning: {:.2f}% of the soft shadow lookups ({} of {}) had their penumbra clamped to the {}-texel "
      "soft kernel: there the penumbrae are narrower than the light makes them "
      "(a wider soft kernel or a smaller shadow map reaches further)",
      100.0 * clamps.share(), clamps.clamped, clamps.lookups, kernel_width);
}

Renderer::Renderer(const vk::Context& ctx, const scene::Scene& scene) : impl_(std::make_unique<Impl>(ctx, scene)) {}
Renderer::~Renderer() = default;
const scene::Scene& Renderer::scene() const noexcept { return impl_->scene; }
void Renderer::check(const RenderSettings& s) const { impl_->check(s); }

RenderResult Renderer::render(const RenderSettings& s) { return render(s, nullptr); }

RenderResult Renderer::render(const RenderSettings& s, Intermediates* intermediates) {
  Impl& m = *impl_;
  m.prepare(s);
  if (intermediates) m.read_intermediates(s, *intermediates);
  vk::submit_and_wait(m.ctx, [&](VkCommandBuffer cmd) { m.record(cmd); });
  RenderResult r;
  m.read_times(r.passes, m.config.lights > 1 ? &r.light_passes : nullptr);
  for (const PassTime& p : r.passes) r.total_ms += p.ms;
  std::span<const std::uint32_t> clamps = m.soft_clamps.mapped<const std::uint32_t>();
  r.soft_kernel_clamps = {.lookups = std::uint64_t(clamps[0]) + clamps[1], .clamped = clamps[1]};
  if (m.config.cascades > 1) r.cascade_depth_range = m.split_range.value_or(scene::visible_depth_range(m.scene));
  if (std::optional<std::string> w = soft_kernel_clamp_warning(r.soft_kernel_clamps, s.resolved_soft_kernel()))
    r.warnings.push_back(*w);
  const FrameGraph& g = *m.graph;
  std::string moments0 = moment_image(0, 0);
  if (intermediates && g.has_image(moments0) && m.config.formats()[0] != VK_FORMAT_R32_UINT)
    intermediates->filtered =
        to_float_image(vk::readback_image(m.ctx, g.image(moments0).image, g.layout_after_record(moments0)),
                       m.config.formats()[0], s.shadow_size, s.shadow_size);

  std::vector<std::byte> color = vk::readback_image(m.ctx, g.image(kColor).image, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL);
  r.color = image::Image(s.width, s.height, 3);
  r.color_srgb8.resize(3 * r.color.pixel_count());
  std::span<float> c = r.color.pixels();
  const std::array<float, 256>& decode = image::srgb8_to_linear_table(); // one lookup a value
  for (size_t i = 0; i < r.color.pixel_count(); ++i)
    for (size_t k = 0; k < 3; ++k) {
      const auto code = uint8_t(color[4 * i + k]);
      r.color_srgb8[3 * i + k] = code;
      c[3 * i + k] = decode[code];
    }

  if (g.has_image(kScattering)) {
    image::Image rgba =
        to_float_image(vk::readback_image(m.ctx, g.image(kScattering).image, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL),
                       VK_FORMAT_R32G32B32A32_SFLOAT, s.width, s.height);
    r.scattering =
        image::Image(s.width, s.height, {"scattering_r", "scattering_g", "scattering_b", "visible_fraction"});
    std::copy(rgba.pixels().begin(), rgba.pixels().end(), r.scattering.pixels().begin());
  }

  std::vector<std::byte> shadow =
      vk::readback_image(m.ctx, g.image(kShadowBuffer).image, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL);
  // RGBA32F: visibility per colour channel, coverage. With coloured translucency "visibility" is
  // the mean of the channels (as the ray tracer's), and the channels come along.
  bool coloured = m.config.coloured;
  r.shadow = image::Image(s.width, s.height, {"visibility", "background"});
  if (coloured) r.shadow_rgb = image::Image(s.width, s.height, {"visibility_r", "visibility_g", "visibility_b"});
  std::span<float> v = r.shadow.pixels();
  for (size_t i = 0; i < r.shadow.pixel_count(); ++i) {
    float px[4];
    std::memcpy(px, shadow.data() + 16 * i, 16);
    v[2 * i] = coloured ? (px[0] + px[1] + px[2]) / 3.0f : px[0];
    v[2 * i + 1] = 1.0f - px[3];
    if (coloured)
      for (size_t k = 0; k < 3; ++k) r.shadow_rgb.pixels()[3 * i + k] = px[k];
  }
  return r;
}

Renderer::DeviceFrame Renderer::render_on_device(const RenderSettings& s) {
  Impl& m = *impl_;
  m.prepare(s);
  vk::submit_and_wait(m.ctx, [&](VkCommandBuffer cmd) { m.record(cmd); });
  DeviceFrame f;
  m.read_times(f.passes, nullptr);
  for (const PassTime& p : f.passes) f.total_ms += p.ms;
  f.color = &m.graph->image(kColor).image;
  std::string moments0 = moment_image(0, 0);
  if (m.graph->has_image(moments0) && m.config.formats()[0] != VK_FORMAT_R32_UINT) {
    f.moments = &m.graph->image(moments0).image;
    f.moments_layout = uint32_t(m.graph->layout_after_record(moments0));
  }
  return f;
}

void Renderer::set_camera(const scene::Camera& camera) {
  scene::Camera& c = impl_->scene.camera;
  if (c.position == camera.position && c.target == camera.target && c.up == camera.up &&
      c.fov_y_deg == camera.fov_y_deg && c.near == camera.near && c.far == camera.far)
    return;
  c = camera;
  impl_->frames.clear(); // the fitted light frusta depend on the camera
  impl_->cascade_fits.clear();
  impl_->too_coarse.clear();
}

void Renderer::move_objects(const scene::Scene& scene) {
  Impl& m = *impl_;
  if (scene.objects.size() != m.scene.objects.size())
    throw RenderError(fmt::format("move_objects: {} objects, the renderer's scene has {}", scene.objects.size(),
                                  m.scene.objects.size()));
  for (std::size_t o = 0; o < scene.objects.size(); ++o) {
    const scene::Mesh &moved = scene.objects[o].mesh, &mine = m.scene.objects[o].mesh;
    if (moved.positions.size() != mine.positions.size() || moved.indices.size() != mine.indices.size())
      throw RenderError(fmt::format("move_objects: object {} ('{}') has another mesh than the renderer's scene", o,
                                    scene.objects[o].name));
  }
  for (std::size_t o = 0; o < scene.objects.size(); ++o) {
    scene::Object& mine = m.scene.objects[o];
    mine.mesh = scene.objects[o].mesh;
    mine.bounds = scene.objects[o].bounds;
    mine.transform = scene.objects[o].transform;
  }
  m.gpu.move_objects(m.ctx, m.scene); // sorted along the renderer's light, with its materials
  m.frames.clear();                   // the fitted light frusta depend on the vertices
  m.cascade_fits.clear();
  m.too_coarse.clear();
}

void Renderer::set_lights(std::vector<scene::DirectionalLight> directional, std::vector<scene::LocalLight> local) {
  if (directional.empty() && local.empty()) throw RenderError("no light: the renderer draws at least one");
  scene::Scene lit; // the kinds alone, checked before anything changes
  lit.lights = directional;
  lit.local_lights = local;
  refuse_unrendered_lights(lit);
  Impl& m = *impl_;
  m.scene.lights = std::move(directional);
  m.scene.local_lights = std::move(local);
}

std::vector<std::vector<PassTime>> Renderer::time_frames(const RenderSettings& s, int frames) {
  if (frames < 1) throw RenderError("time_frames: at least one frame");
  Impl& m = *impl_;
  std::vector<std::vector<PassTime>> out;
  for (int i = 0; i < frames; ++i) {
    m.prepare(s); // each frame measures its cascades' depth bounds anew, as a moving camera's would
    vk::submit_and_wait(m.ctx, [&](VkCommandBuffer cmd) { m.record(cmd); });
    out.emplace_back();
    m.read_times(out.back(), nullptr);
  }
  return out;
}

void Renderer::submit_frame_prefix(const RenderSettings& s, std::size_t passes) {
  Impl& m = *impl_;
  m.prepare(s);
  std::vector<std::string_view> names = m.graph->pass_names();
  if (passes > names.size()) throw RenderError(fmt::format("the frame has {} passes, not {}", names.size(), passes));
  vk::submit_and_wait(m.ctx, [&](VkCommandBuffer cmd) {
    if (passes == 0)
      m.timer.reset(cmd);
    else
      m.record(cmd, names[passes - 1]);
  });
}

std::vector<std::string> Renderer::frame_passes(const RenderSettings& s) {
  impl_->prepare(s);
  std::vector<std::string> out;
  for (std::string_view name : impl_->graph->pass_names()) out.emplace_back(name);
  return out;
}

} // namespace msm::render
