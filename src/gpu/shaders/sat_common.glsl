// Shared by the summed-area table shaders (sat_*.comp): push constants and the moment fetch.
// The quantization itself is msm_sat_quantize (include/msm/sat.h), the same code as the CPU's.
#ifndef SAT_COMMON_GLSL
#define SAT_COMMON_GLSL
#include "msm/sat.h"

// msm::gpu::SatBuilder's SatPush (sat_builder.cpp), 16 bytes.
layout(push_constant) uniform Push {
  ivec2 size;   // of the moment image and the table
  uint scale;   // msm_sat_scale(max_kernel_texels)
  uint flags;   // SAT_UNORM16: UNORM16 texels (decoded as the C++ build does), else float;
                // SAT_TWO_CHANNELS: z and w are 0 (a fetch from an RG image returns alpha = 1)
} pc;
const uint SAT_UNORM16 = 1u;
const uint SAT_TWO_CHANNELS = 2u;

// The quantized moments of texel p of the moment image (RGBA or RG; RG images count as (r, g, 0, 0)).
uvec4 sat_quantized_texel(sampler2D moments, ivec2 p) {
  vec4 q = texelFetch(moments, p, 0);
  if ((pc.flags & SAT_TWO_CHANNELS) != 0u) q = vec4(q.x, q.y, 0.0, 0.0);
  if ((pc.flags & SAT_UNORM16) != 0u) q = msm_sat_unorm16_texel(q);
  return msm_sat_quantize(q, pc.scale);
}
#endif
