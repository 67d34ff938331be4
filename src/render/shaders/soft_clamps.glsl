// How many soft-shadow lookups had their penumbra clamped to the kernel (soft.h,
// msm_soft_penumbra_clamped): counts[1], and how many were not: counts[0]. The renderer zeroes them
// before the frame and reads them back after it (RenderResult::soft_kernel_clamps). One atomic per
// lookup; helper invocations write nothing.
#include "msm/render/bindings.h"
layout(std430, binding = MSM_BINDING_SHADING_SOFT_CLAMPS) buffer SoftClampBlock { uint soft_clamp_counts[2]; };

void count_soft_lookup(bool clamped) { atomicAdd(soft_clamp_counts[clamped ? 1 : 0], 1u); }
