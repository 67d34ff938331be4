// Moment biasing b' = (1 - α) b + α b*: pulls moments corrupted by rounding back inside the
// domain where the Hankel matrix is positive definite (2015 §4.2, JCGT §2.5). The pair (α, b*)
// depends on how the moments were stored; msm_moment_bias() picks it by representation.
#ifndef MSM_BIAS_H
#define MSM_BIAS_H
#include "msm/shared.h"
#include "msm/config.h"
#include "msm/moments.h"

MSM_BEGIN

// Storage representations of four moments (GLSL has no enums).
const int MSM_REP_UNIT_FLOAT = 0;    // [0,1] depth, 4 x 32-bit float (2015, JCGT Fig. 4d)
const int MSM_REP_UNIT_THETA4 = 1;   // [0,1] depth, 4 x 16-bit UNORM after θ4 (2015)
const int MSM_REP_SIGNED_FLOAT = 2;  // [-1,1] depth, 4 x 32-bit float (JCGT §2.3)
const int MSM_REP_SIGNED_THETA4 = 3; // [-1,1] depth, 4 x 16-bit UNORM after Θ4* (JCGT §2.4)
const int MSM_REP_SAT_INT32 = 4;     // [-1,1] depth, Θ4*, 32-bit integer summed-area table
// Six moments ([-1,1] depth, Θ6*).
const int MSM_REP6_UNORM10 = 10; // 6 x 10-bit in two RGB10A2 textures (64 bits)
const int MSM_REP6_UNORM16 = 11; // 6 x 16-bit (96 bits)
const int MSM_REP6_FLOAT = 12;   // 6 x 32-bit float (192 bits)

struct MomentBias4 {
    float alpha;
    vec4 bstar; // (b1..b4) of the biasing distribution
};

struct MomentBias6 {
    float alpha;
    Moments6 bstar;
};

MSM_FN MomentBias4 msm_moment_bias(int representation) {
    if (representation == MSM_REP_UNIT_FLOAT) return MomentBias4(MSM_ALPHA_UNIT_FLOAT, MSM_BSTAR_UNIT);
    if (representation == MSM_REP_UNIT_THETA4) return MomentBias4(MSM_ALPHA_UNIT_16BIT, MSM_BSTAR_UNIT);
    if (representation == MSM_REP_SIGNED_FLOAT) return MomentBias4(MSM_ALPHA_SIGNED_FLOAT, MSM_BSTAR_SIGNED_FLOAT);
    if (representation == MSM_REP_SIGNED_THETA4) return MomentBias4(MSM_ALPHA_SIGNED_16BIT, MSM_BSTAR_SIGNED_16BIT);
    // Summed-area tables store Θ4* moments at ~22 bits: the float b* with the stronger α.
    return MomentBias4(MSM_ALPHA_SAT_INT32, MSM_BSTAR_SIGNED_FLOAT);
}

MSM_FN MomentBias6 msm_moment_bias6(int representation) {
    Moments6 bstar = Moments6(vec3(0.0f), MSM_BSTAR6_EVEN);
    if (representation == MSM_REP6_UNORM10) return MomentBias6(MSM_ALPHA6_10BIT, bstar);
    if (representation == MSM_REP6_UNORM16) return MomentBias6(MSM_ALPHA6_16BIT, bstar);
    return MomentBias6(MSM_ALPHA6_FLOAT, bstar);
}

MSM_FN vec4 msm_apply_bias(vec4 b, float alpha, vec4 bstar) { return mix(b, bstar, alpha); }
MSM_FN vec4 msm_apply_bias(vec4 b, MomentBias4 bias) { return mix(b, bias.bstar, bias.alpha); }
MSM_FN Moments6 msm_apply_bias6(Moments6 b, MomentBias6 bias) {
    return msm_moments6_mix(b, bias.bstar, bias.alpha);
}

MSM_END

#endif // MSM_BIAS_H
