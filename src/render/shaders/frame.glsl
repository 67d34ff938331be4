// Shared by the renderer's shaders: the frame's uniform block, the lights and the shading helpers.
#include "msm/render/frame.h"

layout(std140, binding = MSM_BINDING_FRAME) uniform FrameBlock { FrameUniforms frame; };

// The frame's lights (FrameUniforms::lights.x of them), at the binding the including shader
// defines as MSM_LIGHT_BINDING (one of msm/render/bindings.h's names).
#ifdef MSM_LIGHT_BINDING
layout(std430, binding = MSM_LIGHT_BINDING) readonly buffer LightBlock { LightUniforms lights[]; };
#endif

// The technique (MSM_TECH_*, msm/techniques.h): a specialization constant, so that each pipeline
// compiles one technique's path only.
layout(constant_id = MSM_SPEC_TECHNIQUE) const int kTechnique = 0;
// The shadow-map lookup (MSM_LOOKUP_*, FrameConfig::lookup): a specialization constant of the
// shading, so that each pipeline compiles one lookup (llvmpipe runs both sides of a branch on a
// uniform under a mask, and lavapipe recompiles a shader whose branches test uniforms).
layout(constant_id = MSM_SPEC_LOOKUP) const int kLookup = MSM_LOOKUP_BILINEAR;
// Four moments stored as two RG images (translucent occluders blend into the map: JCGT §3):
// channels 0, 1 in image 0 and 2, 3 in image 1.
layout(constant_id = MSM_SPEC_SPLIT_RG) const bool kSplitRG = false;

// Normalized 1D Gaussian weight of tap k in [0, taps).
float kernel_weight(int k) { return frame.filter_weights[k / 4][k % 4]; }
