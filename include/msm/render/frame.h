// Parameters the renderer's host code hands to its shaders, declared once for both (the
// Falcor HostDeviceShared idea on top of msm/shared.h). Only vec4, ivec4 and mat4 members, so
// that std140 (GLSL) and the C++ layout agree without implicit padding; the C++ build checks sizes
// and offsets with the static_asserts at the end.
#ifndef MSM_RENDER_FRAME_H
#define MSM_RENDER_FRAME_H
#include "msm/filter.h"
#include "msm/render/bindings.h"
MSM_BEGIN

// The largest number of shadow-casting lights in one frame (the layers of the shadow-map arrays;
// Vulkan guarantees 256 array layers; the image-based lighting of Kneiphof uses up to 256 lights).
const int MSM_MAX_LIGHTS = 256;

// The receiver plane's depth slope per texel ([0,1] depth, along each axis of the map) is clamped
// to this: grazing planes would otherwise reach any depth. The shading and the ray-traced filtered
// reference clamp alike.
const float MSM_MAX_RECEIVER_DEPTH_SLOPE = 0.02f;

// The uniform block of every pass of one frame (binding 0 where a pass uses it).
struct FrameUniforms {
  mat4 camera_view_projection;
  vec4 technique_params;   // see msm/techniques.h
  vec4 shadow_map;         // x: size in texels, y: 1 / size, z: unused, w: depth bias in [0,1] depth
  vec4 shading;            // x: over-darkening factor (1 = off), y: exposure,
                           // z: translucent alpha threshold, w: unused
  ivec4 kernel;            // x: taps per axis (odd), y: MSAA samples, z: radius, w: unused
  vec4 filter_weights[16]; // normalized 1D Gaussian weights (msm/filter.h), tap k at [k / 4][k % 4]
  ivec4 lookup;            // x: shadow-map lookup (MSM_LOOKUP_*), y: blue-noise layer,
                           // zw: blue-noise offset in pixels (per frame)
  vec4 soft;               // soft shadows: xy: unused (per light), z: constant depth bias, w: ε_u
  ivec4 soft_kernel;       // x: kernel width W (n_t = W²), y: table scale (uint bits)
  vec4 sample_offsets[4];  // MSAA sample positions relative to the texel centre, in
                           // texels: sample 2i in [i].xy, 2i + 1 in [i].zw
  vec4 receiver_bias;      // receiver-plane bias of the filtered techniques (lookup.glsl):
                           // x: the kernel's variance per axis in texels² (blur + MSAA), yzw:
                           // unused (the multiplier is each layer's, LightUniforms::kernel.w)
  ivec4 lights;            // x: number of lights (layers of the shadow-map arrays), yzw: unused
  vec4 camera_viewport;    // xy: the camera image's size in pixels (msm_surface_footprint), zw: unused
};

// One shadow-casting light of the frame, directional or spot, or one cascade of a directional light
// (each cascade an entry of its own, the light's cascades in a row): its shadow map is layer `index`
// of every shadow-map array of the frame (a storage buffer of these, binding named by each pipeline).
struct LightUniforms {
  mat4 view_projection; // world -> its shadow-map clip space (directional: orthographic, depth in
                        // [0,1]; spot: perspective, its map storing radial distance / range)
  mat4 normal_matrix;   // inverse transpose of the 3x3 part (normals -> clip space)
  vec4 towards_light;   // xyz: unit direction from the scene towards the light,
                        // w: normal offset in world units (RenderSettings::normal_offset texels)
  vec4 irradiance;      // rgb: irradiance on a surface facing the light (a spot: its radiant
                        // intensity, W/sr, msm_local_light_irradiance), a: unused
  vec4 soft;            // soft shadows: xy: texels of reach per unit of [-1,1] depth
                        // (msm_soft_spread), z: the light's cone half-angle in radians for the
                        // shading's msm_cone_cosine (0: a point light, max(n·l, 0)), w: a spot
                        // light's radius (soft.h's msm_spot_soft_spread; 0: hard shadows)
  vec4 rect_x_axis;     // xyz: a rectangular light's x axis (its frame's, Scene::light_frame), w: unused
  vec4 rect_extent;     // xy: a rectangular light's half extents as tangents (0: a disc or a point,
                        // shaded by soft.z); the shading's msm_light_cosine takes both. zw: its
                        // sub-lights (w of them, 0: none): entry z of the same array their summary
                        // (SubLightsSummary below), [z + 1, z + 1 + w) the sub-lights
  vec4 spot_position;   // a spot light: xyz its position, w its range (> 0); w = 0: a directional light
  vec4 spot_axis;       // xyz: the unit direction the spot shines in, w: tan of its outer half-angle
  vec4 spot_cone;       // x: cos of the outer half-angle, y: of the inner, z: normal offset in world
                        // units per metre of distance from the light, w: unused
  vec4 cascade;         // a directional light's cascade (msm/cascade.h's msm_cascade_weight): the view
                        // depths where its weight rises from 0 (x) to 1 (y) and falls from 1 (z) to 0
                        // (w); all 0: no cascades (weight 1)
  vec4 kernel;          // the Gaussian filter of this layer (msm/filter.h), in its own texels: x: σ, y: taps
                        // (odd), z: its variance per axis in texels² with the MSAA sample positions'
                        // (the receiver-plane bias, lookup.glsl), w: that bias's multiplier (0 = off;
                        // RenderSettings::resolved_receiver_plane_bias). A cascade's is the frame's
                        // scaled to the same width in world units (msm_cascade_filter_*), every other
                        // layer's the frame's (FrameUniforms::filter_weights, ::receiver_bias.x).
};

// The entry before a light's sub-lights in the lights' array: their linear part and the rectangle
// that holds them all (scene::SubLightsLinearPart; shading.glsl's sub_lights_irradiance). It is an
// entry of the same array, so it is stored in a LightUniforms's place and read back by name with
// the two functions below, the only code that knows where each field sits: irradiance_by_direction
// in view_projection's 3 × 3, bounds in view_projection[3].xy, the axes in normal_matrix[0] and [1].
struct SubLightsSummary {
  mat3 irradiance_by_direction; // msm_linear_irradiance's matrix
  vec2 bounds;                  // the rectangle's tangent bounds (msm_light_tangent_bounds)
  vec3 x_axis;                  // the rectangle's axes
  vec3 y_axis;
};
MSM_FN LightUniforms msm_sub_lights_summary_entry(SubLightsSummary s) {
  mat4 packed = mat4(s.irradiance_by_direction);
  packed[3] = vec4(s.bounds, 0.0f, 1.0f);
  mat4 axes = mat4(vec4(s.x_axis, 0.0f), vec4(s.y_axis, 0.0f), vec4(0.0f), vec4(0.0f));
  vec4 zero = vec4(0.0f);
  return LightUniforms(packed, axes, zero, zero, zero, zero, zero, zero, zero, zero, zero, zero);
}
MSM_FN SubLightsSummary msm_sub_lights_summary(mat4 view_projection, mat4 normal_matrix) {
  return SubLightsSummary(mat3(view_projection), vec2(view_projection[3][0], view_projection[3][1]),
                          vec3(normal_matrix[0]), vec3(normal_matrix[1]));
}

// How the shading reads a filtered shadow map.
const int MSM_LOOKUP_BILINEAR = 0; // hardware (tri)linear; for the non-linear maps: four decodes
const int MSM_LOOKUP_NEAREST = 1;  // the texel under the fragment, mip 0
const int MSM_LOOKUP_DITHER = 2;   // nearest after a blue-noise offset of up to half a texel (HPG)

// Per draw of the shadow, translucent and shading passes (push constants).
struct ObjectPush {
  vec4 albedo_opacity; // rgb: albedo (multiplies the texture), a: opacity
  ivec4 flags;         // x: 1 if the albedo texture is used, y: 1 if double-sided,
                       // z: 1 if the opacity texture is used, w: the colour channel
                       // the translucent pass blends (-1: grey, the opacity itself)
  vec4 transmission;   // rgb: transmission colour (the channel's opacity is
                       // opacity (1 - transmission)), a: alpha cutoff of alpha-tested
                       // surfaces (0: none; alpha_test.glsl)
  ivec4 light;         // x: the light (shadow-map layer) the shadow and translucent passes draw for
};

// Specialization-constant ids, one meaning each, set by the passes (src/render/passes) and declared
// by the shaders with these names (constant_id = MSM_SPEC_...). The frame's shaders (frame.glsl and
// those including it: the shading, translucent, moment-resolve, one-pass-filter and scattering
// passes' shaders):
#define MSM_SPEC_TECHNIQUE 0          // int: MSM_TECH_* (frame.glsl)
#define MSM_SPEC_FILTER_RADIUS 1      // int: the one-pass filter's taps are 2 r + 1 (one_pass_filter.glsl)
#define MSM_SPEC_FILTER_COLUMNS 2     // int: the one-pass filter's adjacent columns per thread
#define MSM_SPEC_SPLIT_RG 3           // bool: four moments in two RG images (frame.glsl)
#define MSM_SPEC_LIGHT_COUNT 4        // int: the frame's lights (light_loop.glsl)
#define MSM_SPEC_LINEAR_RADIANCE 5    // bool: the shading writes linear radiance (shading.glsl)
#define MSM_SPEC_PREFIX_SUM_MIPS 6    // bool: scatter.glsl reads the prefix sums' mips
#define MSM_SPEC_DEPTH_SAMPLES 7      // int: the depth map's MSAA samples (shading_depth.glsl)
#define MSM_SPEC_PCF_TAPS 8           // int: the PCF kernel's taps (shading_depth.glsl)
#define MSM_SPEC_LOOKUP 9             // int: MSM_LOOKUP_* (frame.glsl)
#define MSM_SPEC_TEXTURED_DRAWS 10    // bool: some draw has an albedo or opacity texture (shading.glsl)
#define MSM_SPEC_SUB_LIGHTS 11        // bool: some light has sub-lights (shading.glsl)
#define MSM_SPEC_FILTER_SAMPLES 12    // int: MSAA samples per texel of the one-pass filter
#define MSM_SPEC_FRONT_BACK 13        // bool: the mean of front- and back-face depth (moment_resolve.glsl)
#define MSM_SPEC_SCATTER_LAYERS 14    // int: transmittance layers per light (scatter.glsl)
#define MSM_SPEC_SCATTER_BETA_MODE 15 // int: MSM_SCATTERING_BETA_* (scatter.glsl)
#define MSM_SPEC_SPOT_LIGHTS 16       // bool: some light of the frame is a spot light (shading.glsl)
#define MSM_SPEC_CASCADES 17          // bool: the directional lights have cascades (shading, one-pass filter)
// The blur's specialization constants (blur.comp, passes/blur_pass.cpp): id MSM_BLUR_SPEC_ID holds
// the fetches per side of the frame's widest kernel (msm_filter_pairs of the largest kernel: 16;
// each layer's offsets and weights are its BlurKernel's); + 2 + 2 MSM_BLUR_MAX_PAIRS is true for
// bilinear fetches, false for each pair's two texels (exact: the 32-bit float maps), + 3 + 2
// MSM_BLUR_MAX_PAIRS true where the vertical direction also writes mip 1.
#define MSM_BLUR_SPEC_ID 100
#define MSM_BLUR_MAX_PAIRS 16
// The prefix sums' scheme (prefix_sums.glsl, RenderSettings::prefix_sums): true for the row sweep
// (64 rows per group of 8 x 8 threads), false for Appendix C's (8 rows per group).
#define MSM_PREFIX_ROWS_SPEC_ID 200
// Rectify's resampling without the moment map (rectify.glsl, FrameConfig::on_the_fly_resampling):
// true for the on-the-fly filter of the depth map's moments, false for its nearest texel.
#define MSM_RECTIFY_ON_THE_FLY_SPEC_ID 201

// The blur's kernel of one layer of the shadow-map arrays (blur.comp, passes/blur_pass.cpp), in
// msm/filter.h's bilinear pairs of taps: value 0 the centre weight, 2 j - 1 and 2 j the offset and
// the weight of pair j in [1, MSM_BLUR_MAX_PAIRS] (value i at values[i / 4][i % 4]; the pairs beyond
// the layer's kernel weigh 0). Computed by the host, so every layer's weights are msm/filter.h's to
// the bit.
const int MSM_BLUR_KERNEL_VEC4S = (2 * MSM_BLUR_MAX_PAIRS + 4) / 4;
struct BlurKernel {
  vec4 values[MSM_BLUR_KERNEL_VEC4S];
};

// The compute passes on shadow-map images (push constants).
struct ImagePassPush {
  ivec4 size; // xy: image size in texels, z: pass-specific (rectify, prefix_sums: the light),
              // w: pass-specific (prefix_sums: the transmittance layers K; blur: the layer, whose
              // BlurKernel it reads; one-pass filter: the layer), else unused
};

// The scattering pass (push constants): single scattering of every light of the frame in the
// scene's medium, composited over the linear surface radiance (scattering.h).
struct ScatteringPush {
  mat4 inverse_view_projection; // camera clip space -> world (pixels' rays and far-plane ends)
  vec4 camera;                  // xyz: camera position, w: unused
  vec4 medium;                  // x: extinction σt, y: scattering albedo ρ, z: HG g,
                                // w: 1 with a medium, 0 without (the pass only tone maps)
  ivec4 march;                  // x: ray-marching samples per pixel, y: six-moment storage
                                // (MSM_REP6_*, prefiltered), zw: unused
  vec4 sky;                     // rgb: the background's linear radiance (msm_aces_inverse of
                                // MSM_SKY_RADIANCE over the exposure: shown as before), a: unused
};

MSM_END

#if MSM_CPP
#include <cstddef>
// std140/std430 and the C++ structs agree (vec4/ivec4/mat4 members only).
static_assert(sizeof(msm::FrameUniforms) == 544 && offsetof(msm::FrameUniforms, technique_params) == 64 &&
              offsetof(msm::FrameUniforms, filter_weights) == 128 && offsetof(msm::FrameUniforms, lookup) == 384 &&
              offsetof(msm::FrameUniforms, sample_offsets) == 432 && offsetof(msm::FrameUniforms, lights) == 512 &&
              offsetof(msm::FrameUniforms, camera_viewport) == 528);
static_assert(sizeof(msm::LightUniforms) == 288 && offsetof(msm::LightUniforms, normal_matrix) == 64 &&
              offsetof(msm::LightUniforms, towards_light) == 128 && offsetof(msm::LightUniforms, rect_extent) == 192 &&
              offsetof(msm::LightUniforms, spot_cone) == 240 && offsetof(msm::LightUniforms, cascade) == 256 &&
              offsetof(msm::LightUniforms, kernel) == 272);
static_assert(sizeof(msm::BlurKernel) == 144);
static_assert(sizeof(msm::ObjectPush) == 64 && offsetof(msm::ObjectPush, light) == 48);
static_assert(sizeof(msm::ImagePassPush) == 16);
static_assert(sizeof(msm::ScatteringPush) == 128 && offsetof(msm::ScatteringPush, sky) == 112);
#endif

#endif // MSM_RENDER_FRAME_H
