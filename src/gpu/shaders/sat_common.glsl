// Shared by the summed-area table shaders (sat_*.comp): bindings and push constants (sat_interface.h) and the moment fetch.
// The quantization itself is msm_sat_quantize (include/msm/sat.h), the same code as the CPU's.
#ifndef SAT_COMMON_GLSL
#define SAT_COMMON_GLSL
#include "msm/sat.h"
#include "sat_interface.h"

layout(push_constant) uniform PushBlock { SatPush pc; };

// The quantized moments of texel p of the moment image (RGBA or RG; RG images count as (r, g, 0, 0)).
uvec4 sat_quantized_texel(sampler2D moments, ivec2 p) {
  vec4 q = texelFetch(moments, p, 0);
  if ((pc.flags & MSM_SAT_TWO_CHANNELS) != 0u) q = vec4(q.x, q.y, 0.0, 0.0);
  if ((pc.flags & MSM_SAT_UNORM16) != 0u) q = msm_sat_unorm16_texel(q);
  return msm_sat_quantize(q, pc.scale);
}
#endif
