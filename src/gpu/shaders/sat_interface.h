// What every summed-area table shader (sat_*.comp, through sat_common.glsl) and
// msm::gpu::SatBuilder (sat_builder.cpp) exchange, declared once for both (shared-header rules:
// include/msm/shared.h): the descriptor bindings and the push constants. std430 in GLSL; the C++
// layout is asserted below.
#ifndef MSM_GPU_SAT_INTERFACE_H
#define MSM_GPU_SAT_INTERFACE_H
#include "msm/shared.h"

// The row passes (sat_rows, sat_block_rows, sat_scan_rows, sat_subgroup_rows): the moment image
// sampled, the table written.
#define MSM_BINDING_SAT_ROWS_MOMENTS 0
#define MSM_BINDING_SAT_ROWS_TABLE 1
// The column passes (sat_columns, sat_block_columns, sat_subgroup_columns): the table, in place.
#define MSM_BINDING_SAT_COLUMNS_TABLE 0
// The copy shaders of msm_sat_timing (sat_copy.glsl).
#define MSM_BINDING_SAT_COPY_SOURCE 0
#define MSM_BINDING_SAT_COPY_DESTINATION 1

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

#endif // MSM_GPU_SAT_INTERFACE_H
