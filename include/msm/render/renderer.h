// msm::render: the headless Vulkan renderer of filtered, soft and translucent shadows. A frame is
// the recipe of passes of its technique (src/render/recipes.cpp), ordered and synchronized by a
// frame graph from what each pass declares (src/render/frame_graph.h; docs/architecture.md):
//
//   shadow_depth   scene -> 16-bit depth, 1x/4x/8x MSAA, one orthographic light frustum per light
//   moment_resolve depth samples -> the technique's channels per sample, averaged, in the
//                  storage basis (compute); skipped by the depth-based techniques
//   translucent    translucent occluders blended into the moments (JCGT §3), where the scene has any
//   blur, mipmaps  separable Gaussian (msm/filter.h) and a mip chain of the moment images
//   (one_pass_filter: resolve + blur in shared memory + storage in one dispatch; HPG 2017)
//   (sat: integer summed-area tables of the soft shadows, instead of blur and mips)
//   shading        Lambert + ambient with every light's shadow (msm/shading.h), over-darkening, tone
//                  mapping, sRGB; plus the shadow buffer (visibility of the visible surface per pixel)
//
// A technique (msm/techniques.h for the per-texel math, msm/cpu/techniques.h for its row of the
// technique table) picks its storage formats, its recipe and its shading shader; everything else is
// shared, so every technique sees the same depth samples and the same filter kernel. PCF evaluates
// exactly that kernel (blur then bilinear lookup) on the depth samples, with a receiver plane from
// the surface normal: it is the reference the filtered techniques approximate.
#pragma once

#include "msm/cpu/techniques.h"
#include "msm/filter.h"
#include "msm/image/image.h"
#include "msm/scene/scene.h"

#include <glm/glm.hpp>

#include <array>
#include <cstdint>
#include <memory>
#include <optional>
#include <span>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

namespace msm::vk {
class Context;
class Image;
} // namespace msm::vk

namespace msm::render {

// Bad settings or an unknown technique: the message says what and which values are allowed.
class RenderError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// The renderer's techniques are the rows of the technique table (msm/cpu/techniques.h) with
// `rendered` set, in the table's order.
std::vector<const Technique*> rendered_techniques();
// Throws RenderError listing the valid names for a name the renderer does not have.
const Technique& find_rendered_technique(std::string_view name);
// Whether a technique can blend translucent occluders into its map (see RenderSettings).
bool supports_translucency(const Technique& technique);
// The passes of a technique's frame with the default settings (one light, the default filter and
// mips; translucent occluders and coloured shadows as given), in the order the frame graph runs
// them (src/render/recipes.cpp); needs no device.
std::vector<std::string> technique_passes(const Technique& technique, bool translucent = false, bool coloured = false);

// Limits against absurd input (checked by RenderSettings::validate before anything is allocated).
inline constexpr int kMaxImageSide = 16384;
inline constexpr long long kMaxImagePixels = 64ll << 20; // 64 Mpixels
inline constexpr int kMaxShadowSize = 8192;
inline constexpr int kMaxOnePassTaps = 17;                  // radius 8 in one_pass_filter.glsl
inline constexpr int kDefaultSatKernel = kSatKernelDefault; // msm/cpu/techniques.h
inline constexpr int kDefaultPcssKernel = kPcssKernelDefault;
inline constexpr int kMaxPcssKernel = kPcssKernelMax;
inline constexpr int kDefaultCascades = 4; // RenderSettings::cascades where one map is too coarse

struct RenderSettings {
  std::string technique = "msm-hamburger-64";
  int width = 1280, height = 720;
  int shadow_size = 1024;                        // texels per side of the square shadow map
  int msaa = 4;                                  // samples of the shadow depth pass: 1, 4 or 8
  int filter_size = MSM_FILTER_DEFAULT_TAPS;     // Gaussian taps per axis (odd, 1..63; 1 = no blur)
  float filter_sigma = MSM_FILTER_DEFAULT_SIGMA; // in texels (msm/filter.h)
  bool mipmaps = true;                           // mip chain of the moment images (trilinear lookups)
  // The technique's parameters by name (msm techniques NAME: type, range, default, meaning); those
  // not given take the papers' defaults.
  ParameterValues parameters;
  // The value of the technique's parameter of that name (msm/cpu/techniques.h); std::invalid_argument
  // if the technique has none of that name.
  float parameter(std::string_view name) const;
  void set_parameter(std::string_view name, float value);  // std::invalid_argument: no such name
  void reset_parameters();                                 // every parameter to its default
  std::string parameter_text(std::string_view name) const; // as a user writes it: a choice's name, a number
  glm::vec4 parameter_vector() const;                      // the parameters as the shaders read them
  float overdarken = 1.0f;                                 // shadow / factor, clamped (JCGT §2.6 uses 0.98); 1 = off
  float normal_offset = 0.0f;                              // lookup offset along the normal, in shadow-map texels
  std::optional<float> depth_bias;   // subtracted from the fragment depth ([0,1] units); default: the technique's
  float resolved_depth_bias() const; // depth_bias or the technique's default
  // Receiver-plane bias of the filtered techniques (msm/bias.h): the fragment depth moves towards
  // the light by the spread of the receiver's own depth over the kernel (σ = slope x the kernel's
  // standard deviation, mips included) times what the technique's bound needs on a plane (4MSM: 1,
  // 6MSM: √3, EVSM4: c⁻σ²/2, VSM/ESM: 0), times this factor, on top of depth_bias. 1 removes the
  // self-shadowing of sloped receivers (grazing light, coarse mips); it also loses short-range
  // shadows of occluders closer than the bias (the railing: leaking x1.6-2).
  // Unset: resolved_receiver_plane_bias's default per shadow map.
  std::optional<float> receiver_plane_bias;
  // receiver_plane_bias, or its default for a map: 1 for a cascade of a directional light, 0 for
  // every other map. The moment bias and the depth bias are constants in [0,1] depth, so the depth
  // spread they absorb in world units grows with the map's depth range: one map fitted to the view
  // spans all of it and absorbs the receiver's spread at mip 0 (docs/results.md, "Translucent
  // occluders"); a cascade's range is its slice's (22 m against 280 m on box_on_ground), and there
  // its ground shadows itself unless the spread is biased (docs/techniques.md, "Cascades").
  float resolved_receiver_plane_bias(bool cascade) const;
  float exposure = 1.0f;
  // How the shading reads a filtered map: automatic = dither for the non-linear techniques (HPG),
  // bilinear for the others; nearest = the texel under the fragment (mip 0); bilinear for the
  // non-linear maps = four decodes, moments interpolated, Φ again.
  enum class Lookup { automatic, bilinear, nearest, dither } lookup = Lookup::automatic;
  // The one-pass filter (resolve + blur in shared memory, then storage) instead of resolve, blur
  // H, blur V through device memory. Default: on for the non-linear techniques (they need it),
  // off for the others; not for 6MSM; at most 17 taps.
  std::optional<bool> one_pass;
  // Deferred shading: a surfaces pass writes the visible surface of each pixel, then the shadows
  // are evaluated once per pixel in a full-screen pass, so their cost follows visible pixels, not
  // shaded quads and overdraw (the same image: the surface is stored bit for bit). Default: on for
  // the per-pixel filters (pcf, pcss and the soft techniques), off for the others; only the
  // depth-based and soft techniques have it (the others' lookup is one filtered fetch).
  std::optional<bool> deferred_shading;
  int frame = 0; // frame number: picks the blue-noise layer and offset
  // Translucent occluders (materials with opacity < 1 or an opacity texture): blended into the
  // moment map back to front after the opaque resolve (JCGT §3), by the linear techniques with
  // one moment image (four-channel ones then store two RG images) in the three-pass pipeline.
  // The depth-based, non-linear and six-moment techniques (and a one-pass filter) draw them
  // without a shadow. Fragments below the threshold opacity are discarded (JCGT: 1%).
  bool translucent_occluders = true;
  // Coloured translucent shadows (JCGT §3): one moment map per colour channel, each blended with
  // the channel's opacity α (1 − the material's transmission_color). Three times the moment
  // images, resolve, blend, blur and mips, three lookups per fragment; off: grey shadows (the
  // opacity itself). Only where translucent occluders are blended (see above).
  bool coloured_translucency = false;
  // Soft shadows (mssm4, mssm6, vssm, pcss): the directional light's angular diameter in degrees
  // (default: the scene's angular_extent_deg) and the largest kernel width W in texels of the
  // blocker search and the filter (summed-area tables: n_t = W²). 0 = the technique's default:
  // 27 for the tables (JCGT's 27² search region), 15 for PCSS (its 15² search: 225 taps, and up to
  // 256 more for the filter). 3..max_soft_kernel(technique).
  std::optional<float> light_extent_deg;
  // A rectangular light's angular height in degrees (Kneiphof §4.1.2; the width is
  // light_extent_deg or each light's own angular_extent_deg): set, every light is a rectangle of
  // that height along its frame's y axis; unset, each keeps its own height, except that
  // light_extent_deg alone makes every light a disc of that diameter.
  std::optional<float> light_height_deg;
  // Kneiphof §4.2.3, the moment soft shadows (mssm4, mssm6, vssm, cssm8, cssm16) only: the map
  // stores the mean of the nearest front-face and back-face depth (a second depth pass culling the
  // faces towards the light; double-sided materials count as both), a depth inside closed
  // occluders instead of on their surface. Meant for closed, convex occluders (the paper's
  // condition); an open, single-sided surface has no back face and averages with what lies behind.
  bool front_back_depth = false;
  // Prefiltered scattering's transmittance-weighted prefix sums along the rectified rows (JCGT
  // §5.1.1): rows = one thread per row walks it once, each texel read and written once (on lavapipe
  // 3.6-6.8x faster than the other, msm bench --scattering); appendix_c = the paper's Appendix C, 8 x 8 threads,
  // eight threads per row each summing the whole row so that a block's writes coalesce. The same
  // sums in the same order: the images agree (ScatteringTest.PrefixSumSchemesAgree).
  enum class PrefixSums { rows, appendix_c } prefix_sums = PrefixSums::rows;
  // JCGT Appendix D.5: a mip chain of the prefix sums (2 x 2 box averages), read by the scattering
  // pass at the level of the pixel's smaller footprint along or across the rows (msm_prefix_sum_lod),
  // against the aliasing of thin shafts where neighbouring pixels skip rows; where the device can
  // blit and filter the storage formats (else none). Off by default: little gain measured
  // (docs/results.md, "Prefix sums: a thread per row; App. D.5's mips").
  bool prefix_sum_mips = false;
  int soft_kernel = 0;
  int resolved_soft_kernel() const; // soft_kernel or the technique's default
  float translucent_alpha_threshold = 0.01f;
  // The frame's shadow-casting lights: empty = the scene's (scene::Scene::lights); at most
  // MSM_MAX_LIGHTS (render/frame.h). Each gets its own shadow map (a layer of the frame's arrays),
  // fitted to the scene like the scene's lights; the shading sums their contributions.
  std::vector<scene::DirectionalLight> lights;
  // Cascaded shadow maps (scene::fit_cascades; docs/techniques.md, "Cascades"): the maps per
  // directional light, 1..scene::kMaxCascades, each shadow_size² texels over a slice of the view
  // depth. Unset: kDefaultCascades where one map's texels would span more than
  // scene::kMaxPixelsPerTexel pixels (scene::shadow_texel_coverage) and the frame can have them
  // (cascades_supported), else 1.
  std::optional<int> cascades;
  float cascade_lambda = float(scene::kDefaultCascadeLambda); // the split scheme: 0 uniform, 1 logarithmic
  bool cascade_stabilize = true; // radius rounded and centre snapped to whole texels (no shimmer)
  // The view depths the cascades split (scene::CascadeOptions::depth_range): reduce = the smallest
  // and largest view depth in the camera's depth buffer (a depth pre-pass and a compute reduction,
  // read back before the frame's shadow maps: sample-distribution shadow maps; its GPU time the
  // frame's pass "depth_bounds"); scene = scene::visible_depth_range's estimate from the scene's
  // bounds (the camera's frustum clipped to them), which counts hidden and empty space too.
  enum class CascadeDepthBounds { reduce, scene } cascade_depth_bounds = CascadeDepthBounds::reduce;
  // Throws RenderError naming the setting and the allowed range.
  void validate() const;
};

// What a render of these settings would allocate, host and device together (the model and its
// constants: msm/util/limits.h), for a scene of `triangles` triangles; the frame's lights are
// s.lights or the scene's `scene_lights`.
std::uint64_t estimated_bytes(const RenderSettings& s, std::uint64_t triangles, std::size_t scene_lights);
// Prefiltered scattering: the transmittance layers K of these settings (the technique's parameter
// w, 0 = the default; rectification.h); 1 for every other technique.
int transmittance_layers(const RenderSettings& s);
// limits::LimitError (msm/util/limits.h) when the scene or the estimate exceeds its limit; the
// message names the technique, the sizes and the limit.
void check_limits(const RenderSettings& s, std::uint64_t triangles, std::size_t scene_lights);

// Cascaded shadow maps (RenderSettings::cascades): why a frame of these settings cannot have them
// (a phrase: soft shadows, scattering, sub-lights, a framing other than "fit"), or none.
std::optional<std::string> cascades_unsupported(const RenderSettings& s, const scene::Scene& scene);
// Whether one map of the scene's first directional light would have texels spanning more than
// scene::kMaxPixelsPerTexel pixels at the nearest visible surface (scene::shadow_texel_coverage).
bool one_map_too_coarse(const RenderSettings& s, const scene::Scene& scene);
// The cascades per directional light of a frame: s.cascades where set (RenderError where above 1
// and cascades_unsupported), else kDefaultCascades where one map is too coarse (too_coarse, where
// the caller knows it, else one_map_too_coarse) and the frame supports cascades, else 1.
int resolved_cascades(const RenderSettings& s, const scene::Scene& scene, std::optional<bool> too_coarse = {});
// The frame's cascades as scene::fit_cascades and scene::shadow_framing_warnings take them
// (resolved_cascades; one where the settings ask for cascades the frame cannot have: the render
// refuses those).
scene::CascadeOptions cascade_options(const RenderSettings& s, const scene::Scene& scene);

// The normalized 1D weights of the blur and PCF (msm/filter.h), tap k at [k]: what the frame's
// uniforms hold and what the ray tracer's filtered effect samples (reference::FilterKernel).
std::vector<float> filter_weights(const RenderSettings& settings);

// GPU time of one pass scope, in milliseconds.
struct PassTime {
  std::string name;
  double ms = 0;
};

// GPU time of one light's share of a pass that works light by light (frames with several lights).
struct LightPassTime {
  std::string pass;
  int light = 0;
  double ms = 0;
};

// The soft techniques' shadow lookups (one per shaded fragment and light) and how many of them had
// their penumbra clamped to the kernel width W (soft.h, msm_soft_penumbra_clamped):
// there the penumbra is narrower than the light makes it (a wide area light needs a wider kernel).
struct SoftKernelClamps {
  std::uint64_t lookups = 0;
  std::uint64_t clamped = 0;
  double share() const noexcept { return lookups ? double(clamped) / double(lookups) : 0.0; }
};

struct RenderResult {
  image::Image color;                      // linear RGB decoded from the sRGB target (write_png re-encodes exactly)
  std::vector<std::uint8_t> color_srgb8;   // the sRGB target's bytes as read back, R,G,B (alpha dropped): what
                                           // encode_png8 stores, the same PNG as encode_png of `color`
  image::Image shadow;                     // "visibility" (of the light at the visible surface, 0 where the surface
                                           // faces away from the light) and "background" (1 where no surface)
  image::Image shadow_rgb;                 // coloured translucency only: "visibility_r", "_g", "_b" (shadow's
                                           // "visibility" is then their mean, as the ray tracer's); else empty
  image::Image scattering;                 // scattering techniques: "scattering_r", "_g", "_b" (linear
                                           // in-scattered radiance of the first light, before exposure) and
                                           // "visible_fraction" (of the ray's in-scattering); else empty
  std::vector<PassTime> passes;            // in execution order; empty where the queue has no timestamps
  double total_ms = 0;                     // sum of the passes
  std::vector<LightPassTime> light_passes; // several lights: each light's share of the passes
  SoftKernelClamps soft_kernel_clamps;     // soft techniques (mssm4/6, vssm, pcss, cssm8/16); else zeros
  std::vector<std::string> warnings;       // where the result is known degraded (soft_kernel_clamp_warning)
  std::optional<glm::dvec2> cascade_depth_range; // with cascades: the view depths they split (cascade_depth_bounds)
};

struct Intermediates;     // the internal header's (msm/render/renderer_internals.h, not installed)
struct RendererInternals; // its access to the test hooks below

// The share of soft lookups clamped above which a render warns: 0.1%, about a pixel-wide band along
// the shadows' edges of a 1024² image (a clamped penumbra is a band of the penumbra's width, far
// wider), while a default scene's occasional grazing lookup stays well below it.
inline constexpr double kSoftKernelClampWarnShare = 1e-3;

// The warning for a render whose share of clamped lookups exceeds kSoftKernelClampWarnShare, naming
// the share and the kernel width; nothing otherwise.
std::optional<std::string> soft_kernel_clamp_warning(const SoftKernelClamps& clamps, int kernel_width);

// Owns the scene's GPU buffers and textures and the pipelines it has built (cached per
// technique, MSAA and filter configuration). Externally synchronized; the Context outlives it.
class Renderer {
 public:
  Renderer(const vk::Context& ctx, const scene::Scene& scene);
  ~Renderer();
  Renderer(const Renderer&) = delete;
  Renderer& operator=(const Renderer&) = delete;

  // What render() checks first: the settings are valid and this device supports them (MSAA
  // count, image sizes, light layers); RenderError naming the problem otherwise. Lets a tool
  // refuse before it creates any output.
  void check(const RenderSettings& settings) const;

  // One frame, submitted and waited for, images read back.
  RenderResult render(const RenderSettings& settings);

  // One frame, submitted and waited for, nothing read back (an interactive viewer blits it): the
  // colour target (R8G8B8A8_SRGB, settings.width x height, left in TRANSFER_SRC_OPTIMAL, valid
  // until the next frame or destruction) and the pass times. The same frame as render().
  struct DeviceFrame {
    const vk::Image* color = nullptr;
    // The first moment image (all lights' layers, all mips; none for the depth-based and the
    // packed 32-bit techniques) and the VkImageLayout it is left in (renderer.h includes no
    // Vulkan header): to show the map, a viewer transitions it and back.
    const vk::Image* moments = nullptr;
    std::uint32_t moments_layout = 0;
    std::vector<PassTime> passes;
    double total_ms = 0;
  };
  DeviceFrame render_on_device(const RenderSettings& settings);

  // Moves the camera of later frames (the shadow maps' "fit" framing follows it).
  void set_camera(const scene::Camera& camera);

  // Draws later frames with the objects of `scene`: the renderer's scene with its objects moved
  // (scene::at_frame; animated objects, `msm render --frames`). Only the objects' meshes, bounds
  // and transforms are taken; the vertex and index buffers are uploaded again into the same
  // buffers (through staging, one submission each), translucent objects sorted again along the
  // renderer's first light, the shadow maps' fitted frusta follow; camera, lights and materials
  // stay the renderer's. RenderError, the renderer unchanged, where an object's mesh differs in
  // vertex or index count from the renderer's scene.
  void move_objects(const scene::Scene& scene);

  // Draws later frames with these lights instead of the renderer's scene's (a viewer adds, moves and
  // switches lights): the directional ones as scene::Scene::lights (RenderSettings::lights, where
  // given, still replaces them), the spot and point ones as its local_lights. RenderError, the
  // renderer unchanged, for no light at all (a scene holds one) or a kind it does not draw, as the
  // constructor refuses it. Translucent objects stay sorted along the first light it was made with.
  void set_lights(std::vector<scene::DirectionalLight> directional, std::vector<scene::LocalLight> local);

  // `frames` frames with the same settings, nothing read back: the per-pass times of each (for
  // msm bench). Precondition: frames >= 1.
  std::vector<std::vector<PassTime>> time_frames(const RenderSettings& settings, int frames);

  // The passes of the frame these settings make, in the order the frame graph runs them.
  std::vector<std::string> frame_passes(const RenderSettings& settings);

  const scene::Scene& scene() const noexcept;

 private:
  // The hooks of the tests and of msm bench, reached through RendererInternals only: the same frame
  // as render() with the intermediates read back, and a frame cut after some passes.
  friend struct RendererInternals;
  RenderResult render(const RenderSettings& settings, Intermediates* intermediates);
  // One frame recorded up to and including its first `passes` passes (frame_passes order; 0:
  // none, only the submission), submitted and waited for, nothing read back. A profiler counts
  // each pass as the difference of two prefixes (msm bench --callgrind). Precondition: settings
  // prepared by a frame with the same configuration first when the count must exclude pipeline
  // creation.
  void submit_frame_prefix(const RenderSettings& settings, std::size_t passes);

  struct Impl;
  std::unique_ptr<Impl> impl_;
};

} // namespace msm::render
