// Moment generation: what one shadow-map texel (or one MSAA sample) stores before filtering.
// Four moments travel as vec4 (b1, b2, b3, b4); b0 = 1 is implicit. Six moments travel as
// Moments6, split into odd and even powers because Θ6* (quantize.h) transforms them apart.
#ifndef MSM_MOMENTS_H
#define MSM_MOMENTS_H
#include "msm/shared.h"

MSM_BEGIN

// Six power moments: odd = (b1, b3, b5), even = (b2, b4, b6).
struct Moments6 {
  vec3 odd;
  vec3 even;
};

// Depth conventions. The 2015 paper uses depth in [0,1]; JCGT §2.3 shows [-1,1] is optimal
// (the moment transform gains 10 bits). The shadow depth buffer holds [0,1] either way.
MSM_FN float msm_signed_depth(float unit_depth) { return 2.0f * unit_depth - 1.0f; }
MSM_FN float msm_unit_depth(float signed_depth) { return 0.5f * signed_depth + 0.5f; }

// b(z) = (z, z², z³, z⁴) for any depth convention.
MSM_FN vec4 msm_moments4(float z) {
  float z2 = z * z;
  return vec4(z, z2, z2 * z, z2 * z2);
}

// b(z) = (z, ..., z⁶).
MSM_FN Moments6 msm_moments6(float z) {
  float z2 = z * z;
  float z3 = z2 * z;
  return Moments6(vec3(z, z3, z3 * z2), vec3(z2, z2 * z2, z3 * z3));
}

// Weighted sum of six-moment vectors (resolve, blur, blending all use it).
MSM_FN Moments6 msm_moments6_mix(Moments6 a, Moments6 b, float t) {
  return Moments6(mix(a.odd, b.odd, t), mix(a.even, b.even, t));
}
MSM_FN Moments6 msm_moments6_scale_add(Moments6 acc, Moments6 m, float w) {
  return Moments6(acc.odd + w * m.odd, acc.even + w * m.even);
}

// The trigonometric basis of 2015 Eq. (1) for depth z in [0,1]:
// (sin 2πz, cos 2πz, sin 4πz, cos 4πz).
MSM_FN vec4 msm_trig_moments(float z) {
  float s = sin(2.0f * MSM_PI * z);
  float c = cos(2.0f * MSM_PI * z);
  return vec4(s, c, 2.0f * s * c, c * c - s * s);
}

// Moments of a distribution on [0,1] re-expressed for the same depths mapped to [-1,1]
// (z' = 2z - 1; JCGT Eq. (2) with x = 2, y = -1). Lower triangular, determinant 2^10 = 1024.
MSM_FN vec4 msm_unit_to_signed_moments(vec4 b) {
  float b1 = b[0], b2 = b[1], b3 = b[2], b4 = b[3];
  return vec4(2.0f * b1 - 1.0f, 4.0f * b2 - 4.0f * b1 + 1.0f, 8.0f * b3 - 12.0f * b2 + 6.0f * b1 - 1.0f,
              16.0f * b4 - 32.0f * b3 + 24.0f * b2 - 8.0f * b1 + 1.0f);
}

MSM_END

#endif // MSM_MOMENTS_H
