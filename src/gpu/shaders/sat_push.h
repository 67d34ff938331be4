// The push constants of every summed-area table shader (sat_*.comp, through sat_common.glsl) and
// of msm::gpu::SatBuilder (sat_builder.cpp), declared once for both (shared-header rules:
// include/msm/shared.h). std430 in GLSL; the C++ layout is asserted below.
#ifndef MSM_GPU_SAT_PUSH_H
#define MSM_GPU_SAT_PUSH_H
#include "msm/shared.h"

MSM_BEGIN

// SatPush::flags.
const uint MSM_SAT_UNORM16 = 1u;      // UNORM16 texels (decoded as the C++ build does), else float
const uint MSM_SAT_TWO_CHANNELS = 2u; // RG texels: z and w are 0 (a fetch from an RG image returns alpha = 1)

struct SatPush {
  ivec2 size; // of the moment image and the table
  uint scale; // msm_sat_scale(max_kernel_texels)
  uint flags; // MSM_SAT_UNORM16 | MSM_SAT_TWO_CHANNELS
};

MSM_END

#if MSM_CPP
#include <cstddef>
static_assert(sizeof(msm::SatPush) == 16 && offsetof(msm::SatPush, scale) == 8 && offsetof(msm::SatPush, flags) == 12,
              "SatPush: the std430 layout of the shaders' push constant block");
#endif

#endif // MSM_GPU_SAT_PUSH_H
