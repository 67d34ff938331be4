#version 460
#extension GL_GOOGLE_include_directive : require
#include "msm/msm.h"
layout(local_size_x = 64) in;
layout(std430, binding = 0) buffer Moments { vec4 moments[]; };
layout(std430, binding = 1) buffer Shadows { float shadows[]; };
void main() {
    uint i = gl_GlobalInvocationID.x;
    vec4 b = msm_apply_bias(msm_theta4_star_inverse(moments[i]), msm_moment_bias(MSM_REP_SIGNED_THETA4));
    shadows[i] = msm_hamburger4_lower(b, 0.0f);
}
