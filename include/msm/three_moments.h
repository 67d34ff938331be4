// Two depths from three moments (JCGT Algorithm 2, signs restored per ERRATA.md; HPG Alg. 2
// steps 1-5): the distribution (1 - w) δ(z1) + w δ(z2) matching b0..b3, which is the limit of the
// canonical representation as zf goes to infinity. Used for filtered resampling (JCGT §5.2) and
// as the first half of the non-linear representation (nonlinear.h).
#ifndef MSM_THREE_MOMENTS_H
#define MSM_THREE_MOMENTS_H
#include "msm/roots.h"
#include "msm/shared.h"

MSM_BEGIN

struct TwoDepths {
  vec2 z; // z.x <= z.y
  vec2 w; // weights, sum 1
};

// Precondition: b = (b1, b2, b3) of a distribution; variance b2 - b1² > 0 for two distinct
// depths. Zero or negative variance (a single depth, or rounding) returns δ(b1) as the paper says.
MSM_FN TwoDepths msm_two_depths_from_three_moments(vec3 b) {
  float b1 = b[0], b2 = b[1], b3 = b[2];
  float q2 = msm_fma(-b1, b1, b2);
  if (!(q2 > 0.0f)) return TwoDepths(vec2(b1, b1), vec2(1.0f, 0.0f));
  float q1 = msm_fma(b1, b2, -b3);
  float q0 = msm_fma(-b1, q1, -b2 * q2);
  vec2 z = msm_solve_quadratic(vec3(q0, q1, q2));
  float w2 = (b1 - z.x) / (z.y - z.x);
  return TwoDepths(z, vec2(1.0f - w2, w2));
}

MSM_END

#endif // MSM_THREE_MOMENTS_H
