// The descriptor bindings of the renderer's pipelines (set 0, pushed), named once for the shaders'
// layout(binding = ...) and the passes that push them (src/render/passes, by vk::bindings_at and
// vk::descriptors_at). Numbers are per pipeline: each pipeline's bindings run from 0 without gaps.
// frame.glsl declares the frame's uniforms at MSM_BINDING_FRAME and the lights at the binding its
// includer defines as MSM_LIGHT_BINDING; depth_map.glsl the depth map at MSM_DEPTH_BINDING (and
// MSM_BACK_DEPTH_BINDING): the includer defines them from the names below.
#ifndef MSM_RENDER_BINDINGS_H
#define MSM_RENDER_BINDINGS_H

// Every pipeline that includes frame.glsl: the FrameUniforms block.
#define MSM_BINDING_FRAME 0

// The shading (shading.glsl and its variants; the surfaces and deferred passes too): one layout for
// every technique, a white image of the declared kind where a variant reads nothing.
#define MSM_BINDING_SHADING_ALBEDO_TEXTURE 1  // per draw
#define MSM_BINDING_SHADING_SHADOW_MAP 2      // moments0, the depth map, or the summed-area table
#define MSM_BINDING_SHADING_SHADOW_MAP1 3     // moments1 or the second table (six moments); else the first
#define MSM_BINDING_SHADING_BLUE_NOISE 4      // lookup.glsl
#define MSM_BINDING_SHADING_OPACITY_TEXTURE 5 // per draw
#define MSM_BINDING_SHADING_GREEN_MOMENTS 6   // coloured translucency: the green channel's moment images
#define MSM_BINDING_SHADING_GREEN_MOMENTS1 7
#define MSM_BINDING_SHADING_BLUE_MOMENTS 8 // and the blue channel's
#define MSM_BINDING_SHADING_BLUE_MOMENTS1 9
#define MSM_BINDING_SHADING_LIGHTS 10           // LightUniforms[]
#define MSM_BINDING_SHADING_SURFACE_POSITION 11 // the deferred pass's surfaces; white in the forward passes
#define MSM_BINDING_SHADING_SURFACE_NORMAL 12
#define MSM_BINDING_SHADING_SURFACE_ALBEDO 13
#define MSM_BINDING_SHADING_SOFT_CLAMPS 14              // soft_clamps.glsl: lookups the kernel clamped
#define MSM_BINDING_SHADING_SURFACE_GEOMETRIC_NORMAL 15 // the deferred pass's too (its triangle's normal)

// The probe's background (background.frag).
#define MSM_BINDING_BACKGROUND_PROBE 1

// The shadow depth pass (shadow_depth.vert; the alpha-tested variant has the opacity texture).
#define MSM_BINDING_SHADOW_DEPTH_LIGHTS 1
#define MSM_BINDING_SHADOW_DEPTH_MASKED_OPACITY 1
#define MSM_BINDING_SHADOW_DEPTH_MASKED_LIGHTS 2

// Translucent occluders into the moment map (translucent.vert, translucent_moments.glsl).
#define MSM_BINDING_TRANSLUCENT_OPACITY 1
#define MSM_BINDING_TRANSLUCENT_DEPTH 2 // the opaque depth map
#define MSM_BINDING_TRANSLUCENT_LIGHTS 3

// The moment resolve (moment_resolve.glsl).
#define MSM_BINDING_RESOLVE_DEPTH 1
#define MSM_BINDING_RESOLVE_MOMENTS0 2
#define MSM_BINDING_RESOLVE_MOMENTS1 3 // second half of six moments; else moments0 again
#define MSM_BINDING_RESOLVE_BACK_DEPTH 4

// The one-pass filter (one_pass_filter.glsl).
#define MSM_BINDING_ONE_PASS_DEPTH 1
#define MSM_BINDING_ONE_PASS_TARGET 2
#define MSM_BINDING_ONE_PASS_LIGHTS 3 // LightUniforms[] (each layer's kernel)

// The separable blur (blur.comp).
#define MSM_BINDING_BLUR_SOURCE 0
#define MSM_BINDING_BLUR_TARGET 1
#define MSM_BINDING_BLUR_TARGET_MIP1 2
#define MSM_BINDING_BLUR_KERNELS 3 // BlurKernel per layer (frame.h)

// The depth map's samples into a buffer (depth_samples.comp).
#define MSM_BINDING_DEPTH_SAMPLES_MAP 0
#define MSM_BINDING_DEPTH_SAMPLES_BUFFER 1

// The camera's depth pre-pass of alpha-tested objects (camera_depth_masked.frag) and the reduction
// of its depth to the visible range (depth_bounds.comp).
#define MSM_BINDING_CAMERA_DEPTH_OPACITY 0
#define MSM_BINDING_DEPTH_BOUNDS_MAP 0
#define MSM_BINDING_DEPTH_BOUNDS_RESULT 1

// Rectification of the light's map for prefiltered scattering (rectify.glsl).
#define MSM_BINDING_RECTIFY_RECTS 1
#define MSM_BINDING_RECTIFY_LIGHTS 2
#define MSM_BINDING_RECTIFY_SOURCE 3 // the depth map, or the moment map to resample
#define MSM_BINDING_RECTIFY_TARGET 4
#define MSM_BINDING_RECTIFY_TARGET1 5 // six moments

// The prefix sums over the rectified map (prefix_sums.glsl).
#define MSM_BINDING_PREFIX_RECTS 0
#define MSM_BINDING_PREFIX_SOURCE 1
#define MSM_BINDING_PREFIX_TARGET 2
#define MSM_BINDING_PREFIX_SOURCE1 3 // six moments
#define MSM_BINDING_PREFIX_TARGET1 4 // six moments

// The scattering pass (scatter.glsl).
#define MSM_BINDING_SCATTER_SURFACE_RADIANCE 1
#define MSM_BINDING_SCATTER_CAMERA_DEPTH 2
#define MSM_BINDING_SCATTER_SHADOW_MAP 3 // the depth map (ray marching) or the prefix sums
#define MSM_BINDING_SCATTER_BLUE_NOISE 4
#define MSM_BINDING_SCATTER_LIGHTS 5
#define MSM_BINDING_SCATTER_RECTS 6
#define MSM_BINDING_SCATTER_PREFIX_SUMS1 7 // six moments; else any sampled image

#endif // MSM_RENDER_BINDINGS_H
