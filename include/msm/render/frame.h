// Parameters the renderer's host code hands to its shaders, declared once for both (the
// Falcor HostDeviceShared idea on top of msm/shared.h). Only vec4, ivec4 and mat4 members, so
// that std140 (GLSL) and the C++ layout agree without implicit padding; the host checks sizes
// and offsets with static_asserts (src/render/frame_layout.cpp).
#ifndef MSM_RENDER_FRAME_H
#define MSM_RENDER_FRAME_H
#include "msm/shared.h"
MSM_BEGIN

// Largest filter (odd number of taps per axis) of the blur and PCF: 63 taps fill 16 vec4s.
const int MSM_MAX_FILTER_TAPS = 63;

// The receiver plane's depth slope per texel ([0,1] depth, along each axis of the map) is clamped
// to this: grazing planes would otherwise reach any depth. The shading and the ray-traced filtered
// reference clamp alike.
const float MSM_MAX_RECEIVER_DEPTH_SLOPE = 0.02f;

// The uniform block of every pass of one frame (binding 0 where a pass uses it).
struct FrameUniforms {
  mat4 camera_view_projection;
  mat4 light_view_projection; // world -> shadow-map clip space (orthographic)
  mat4 light_normal_matrix;   // inverse transpose of its 3x3 part (normals -> clip space)
  vec4 towards_light;         // xyz: unit direction from the scene towards the light
  vec4 irradiance;            // rgb: irradiance of the light; a: ambient factor
  vec4 technique_params;      // see msm/techniques.h
  vec4 shadow_map;            // x: size in texels, y: 1 / size,
                              // z: normal offset in world units, w: depth bias in [0,1] depth
  vec4 shading;               // x: over-darkening factor (1 = off), y: exposure,
                              // z: translucent alpha threshold, w: unused
  vec4 background;            // rgb: linear colour of pixels without a surface
  ivec4 kernel;               // x: taps per axis (odd), y: MSAA samples, z: radius, w: unused
  vec4 filter_weights[16];    // normalized 1D Gaussian weights, tap k at [k / 4][k % 4]
  ivec4 lookup;               // x: shadow-map lookup (MSM_LOOKUP_*), y: blue-noise layer,
                              // zw: blue-noise offset in pixels (per frame)
  vec4 soft;                  // soft shadows: xy: texels of reach per unit of [-1,1] depth
                              // (soft.h msm_soft_spread), z: constant depth bias, w: ε_u
  ivec4 soft_kernel;          // x: kernel width W (n_t = W²), y: table scale (uint bits)
  vec4 sample_offsets[4];     // MSAA sample positions relative to the texel centre, in
                              // texels: sample 2i in [i].xy, 2i + 1 in [i].zw
  vec4 receiver_bias;         // receiver-plane bias of the filtered techniques (lookup.glsl):
                              // x: the kernel's variance per axis in texels² (blur + MSAA),
                              // y: multiplier of the bias each bound needs (0 = off), zw: unused
};

// How the shading reads a filtered shadow map.
const int MSM_LOOKUP_BILINEAR = 0; // hardware (tri)linear; for the non-linear maps: four decodes
const int MSM_LOOKUP_NEAREST = 1;  // the texel under the fragment, mip 0
const int MSM_LOOKUP_DITHER = 2;   // nearest after a blue-noise offset of up to half a texel (HPG)

// Per draw of the shading pass (push constants).
struct ObjectPush {
  vec4 albedo_opacity; // rgb: albedo (multiplies the texture), a: opacity
  ivec4 flags;         // x: 1 if the albedo texture is used, y: 1 if double-sided,
                       // z: 1 if the opacity texture is used, w: the colour channel
                       // the translucent pass blends (-1: grey, the opacity itself)
  vec4 transmission;   // rgb: transmission colour (the channel's opacity is
                       // opacity (1 - transmission)), a: alpha cutoff of alpha-tested
                       // surfaces (0: none; alpha_test.glsl)
};

// The compute passes on shadow-map images (push constants).
struct ImagePassPush {
  ivec4 size; // xy: image size in texels, z: pass-specific, w: unused
};

MSM_END
#endif // MSM_RENDER_FRAME_H
