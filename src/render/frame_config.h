// What a frame is made of: the configuration that picks the recipe (recipes.cpp) and sizes the
// images of the frame graph. A new configuration builds a new graph; pipelines stay cached.
#pragma once

#include "msm/render/frame.h"
#include "msm/render/renderer.h"

#include <vulkan/vulkan.h>

#include <array>
#include <bit>
#include <string>
#include <string_view>

namespace msm::render {

struct FrameConfig {
  const Technique* technique = nullptr;
  int width = 0, height = 0, shadow_size = 0, msaa = 1, taps = 1;
  float sigma = MSM_FILTER_DEFAULT_SIGMA; // of the Gaussian: compiled into the blur
  int lights = 1;                         // shadow-casting lights: layers of every shadow-map image
  uint32_t mip_levels = 1;                // of the filtered moment images (1: no mips)
  bool one_pass = false;                  // one_pass_filter instead of moment_resolve + blur
  // Translucent occluders are blended into the map (JCGT §3): a four-channel technique then
  // stores its moments as two RG images, because the blend factor is the fragment's alpha.
  bool translucent = false;
  // Coloured translucent shadows (JCGT §3): one set of moment images per colour channel, each
  // blended with the channel's opacity α (1 − transmission colour); only with translucent.
  bool coloured = false;
  int soft_kernel = 0; // soft techniques: the tables' largest kernel width W (n_t = W²)
  // The shading's lookup (MSM_LOOKUP_*, as resolved for the technique): a specialization constant of
  // the shading (kLookup), because lavapipe runs both sides of a branch on a uniform and recompiles
  // a shader whose branches test uniforms.
  int lookup = MSM_LOOKUP_BILINEAR;
  // Deferred shading: a surfaces pass (depth, position, normal, albedo of the visible surface), then
  // one shadow evaluation per pixel in a full-screen shading pass (RenderSettings::deferred_shading).
  bool deferred = false;
  // Whether any draw of the scene reads an albedo or opacity texture (ObjectPush::flags x, z): a
  // specialization constant of the shading (shading.glsl, kTexturedDraws), as lavapipe fetches the
  // textures under a branch on the draw's flags for untextured draws too (MSM-64's forward shading
  // on the fence: 14% of its instructions, scripts/callgrind-passes.sh).
  bool textured_draws = true;
  // Whether any light of the frame has sub-lights (scene::DirectionalLight::sub_lights): the
  // shading's kSubLights (shading.glsl), which sums them for the light's unshadowed irradiance.
  bool sub_lights = false;
  // Prefiltered scattering, resampling with filtering (JCGT §5.2; parameter resampling = filtered): the
  // frame also makes each light's blurred, mipmapped 4-moment map (moment_resolve, blur and mipmaps
  // with resampling_moments()), and rectify samples it trilinearly (rectify.glsl).
  bool filtered_resampling = false;
  uint32_t resampling_mips = 1; // of that map (1: no mips, where the device cannot blit RGBA32F)
  // Prefiltered scattering, parameter resampling = bilinear-moments: an on-the-fly filter of rectify (a bilinear
  // sample of the depth map's texels' moments). A specialization constant of rectify, as lavapipe
  // runs both sides of a branch on a uniform: the unfiltered resampling paid for this path (16-20%
  // of the pass, scripts/callgrind-passes.sh).
  bool on_the_fly_resampling = false;
  // Prefiltered scattering: K transmittance layers (rectification.h; parameter layers): K prefix
  // sums per light with the steps Δ_k, mixed per pixel at its own Δ; 1 = the paper's Δ(v) per row.
  int transmittance_layers = 1;
  // RenderSettings::prefix_sums: the row sweep instead of the Appendix C scheme (prefix_sums.glsl).
  bool prefix_sums_appendix_c = false;
  uint32_t prefix_sum_mips = 1; // RenderSettings::prefix_sum_mips: the prefix sums' levels (1: none)
  // Prefiltered scattering's β (parameter beta; scattering.h): MSM_SCATTERING_BETA_* as a
  // specialization constant, so that lavapipe, which runs both sides of a branch on a uniform,
  // runs one: with z read from the uniform the six-moment pass cost 28% more (callgrind, tower,
  // 640x360, 512²: 393.1 M against 308.2 M instructions).
  int scattering_beta = 0;
  // Kneiphof §4.2.3 (RenderSettings::front_back_depth): a second depth pass keeps the nearest back
  // face, and the moment resolve stores the mean of the front- and back-face depth.
  bool front_back = false;
  // Spot lights in the frame (after its directional lights): the shadow pass writes their radial
  // depth and the shading's kSpotLights (shading.glsl) projects, biases and lights by each light's kind.
  int spot_lights = 0;
  // Point lights in the frame (after its spot lights), six layers each, one per cube face
  // (msm/cube_face.h): the same radial depth and shading as the spot lights' layers.
  int point_lights = 0;
  // Cascades per directional light (RenderSettings::cascades resolved; scene::fit_cascades): each
  // cascade is a layer of its own, a light's in a row; above 1 the shading's kCascades weighs each
  // layer by the view depth (msm/cascade.h).
  int cascades = 1;
  bool operator==(const FrameConfig&) const = default;

  // The layers of spot and point lights, the last of the shadow-map arrays.
  int local_light_layers() const { return spot_lights + 6 * point_lights; }

  bool split_rg() const;                   // translucent and four channels in one image
  std::array<VkFormat, 2> formats() const; // of the moment images as allocated
  // Prefiltered scattering: of prefix_sums and prefix_sums1 (UNDEFINED: none; passes/prefiltered_scattering_passes.cpp).
  std::array<VkFormat, 2> prefix_sum_formats() const;
  int moment_images() const;                        // 0 (depth-based), 1 or 2 (6MSM, split_rg)
  int channels() const { return coloured ? 3 : 1; } // sets of moment images
  // The vertical blur writes mip 1 too (three-pass filter with mips and an even size): one pass
  // fewer reads mip 0; the mipmap pass starts at mip 2.
  // The configuration of the moment passes that make the filtered resampling's map: the technique
  // msm-hamburger-128-unit (plain moments (z, z², z³, z⁴) of [0,1] depth in RGBA32F: Algorithm 2
  // reads b1..b3 as they are, without an inverse transform, and a flat occluder's variance after
  // the blur, b2 − b1², keeps the float's precision where 16 bits would round it to a few units of
  // 2^-16 and need a bias), the frame's size, samples, lights and filter; no translucency.
  FrameConfig resampling_moments() const;
  static constexpr std::string_view kResamplingMomentsTechnique = "msm-hamburger-128-unit";
  bool blur_writes_mip1() const { return !one_pass && taps > 1 && mip_levels > 1 && shadow_size % 2 == 0; }
};

VkFormat vk_format(TexelFormat format);
// Levels of a full mip chain of a square image of that side (down to 1 x 1).
inline uint32_t full_mip_chain(int size) { return uint32_t(std::bit_width(uint32_t(size))); }

// Names of the frame's images (the frame graph's resources).
// Prefiltered scattering's transmittance layers when the technique's parameter layers is 0: the paper's
// single Δ(v). 4 layers have 0.4-0.7x its error on the tower and the gate (rows +layers of
// scattering.*), but on lavapipe they make the scattering pass 1.4-2x as costly, below the 10x
// margin to ray marching (docs/results.md, "Single scattering: transmittance layers").
inline constexpr int kDefaultTransmittanceLayers = 1;
inline constexpr const char* kShadowDepth = "shadow_depth";
inline constexpr const char* kShadowDepthBack = "shadow_depth_back"; // FrameConfig::front_back
inline constexpr const char* kColor = "color";
inline constexpr const char* kShadowBuffer = "shadow_buffer";
inline constexpr const char* kCameraDepth = "camera_depth";
// Deferred shading: the surfaces pass's visible surface per pixel (RGBA32F each).
inline constexpr const char* kSurfacePosition = "surface_position";
inline constexpr const char* kSurfaceNormal = "surface_normal";
inline constexpr const char* kSurfaceAlbedo = "surface_albedo";
inline constexpr const char* kSurfaceGeometricNormal = "surface_geometric_normal"; // the triangle's
// Scattering techniques: the shading's linear radiance (RGBA16F, before exposure) and the
// scattering pass's in-scattered radiance and visible fraction (RGBA32F, an output of the frame).
inline constexpr const char* kSurfaceRadiance = "surface_radiance";
inline constexpr const char* kScattering = "scattering";
// Prefiltered scattering: the rectified map (float moments) and its prefix sums (storage format).
inline constexpr const char* kRectified = "rectified";
inline constexpr const char* kPrefixSums = "prefix_sums";
inline constexpr const char* kRectified1 = "rectified1"; // six moments: the second image of each
inline constexpr const char* kPrefixSums1 = "prefix_sums1";
// Moment image i (0 or 1) of colour channel c (0 = the only one, or red; 1 green; 2 blue).
std::string moment_image(int channel, int i);
// Summed-area table of moment image i (soft shadows).
std::string sat_table(int i);

} // namespace msm::render
