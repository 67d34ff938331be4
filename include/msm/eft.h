// Error-free transformations of floats (Knuth's TwoSum, Dekker's TwoProduct with Veltkamp's
// split) and the double-float arithmetic built on them, for the shared headers: msm_fma's
// emulation (shared.h) and the nearly singular factorizations of trigonometric.h. Each result is
// a vec2(hi, lo) whose exact sum is the exact result (for the products: no overflow or underflow;
// |a|, |b| < 2^100).
//
// Every operation must round once, as IEEE float: MSM_PRECISE (GLSL `precise`: no contraction
// into fma, no reassociation); the C++ build compiles with -ffp-contract=off and no -ffast-math.
// Included by shared.h after its macros; include shared.h, not this file.
#ifndef MSM_EFT_H
#define MSM_EFT_H
#include "msm/shared.h"

MSM_BEGIN

// s + e = a + b exactly (Knuth's TwoSum: any order of magnitudes).
MSM_FN vec2 msm_two_sum(float a, float b) {
  MSM_PRECISE float s = a + b;
  MSM_PRECISE float v = s - a;
  MSM_PRECISE float e = (a - (s - v)) + (b - v);
  return vec2(s, e);
}

// s + e = a + b exactly, for |a| >= |b| (Dekker's FastTwoSum).
MSM_FN vec2 msm_quick_two_sum(float a, float b) {
  MSM_PRECISE float s = a + b;
  MSM_PRECISE float e = b - (s - a);
  return vec2(s, e);
}

// hi + lo = a with 12 significant bits each (Veltkamp's split by 2^12 + 1).
MSM_FN vec2 msm_split(float a) {
  MSM_PRECISE float c = 4097.0f * a;
  MSM_PRECISE float hi = c - (c - a);
  MSM_PRECISE float lo = a - hi;
  return vec2(hi, lo);
}

// p + e = a * b exactly (Dekker's TwoProduct, without an fma).
MSM_FN vec2 msm_two_product(float a, float b) {
  vec2 sa = msm_split(a), sb = msm_split(b);
  MSM_PRECISE float p = a * b;
  MSM_PRECISE float e = ((sa.x * sb.x - p) + sa.x * sb.y + sa.y * sb.x) + sa.y * sb.y;
  return vec2(p, e);
}

// Double-float sum and product (about 44 significant bits).
MSM_FN vec2 msm_df_add(vec2 a, vec2 b) {
  vec2 s = msm_two_sum(a.x, b.x);
  MSM_PRECISE float lo = s.y + (a.y + b.y);
  return msm_quick_two_sum(s.x, lo);
}
MSM_FN vec2 msm_df_mul(vec2 a, vec2 b) {
  vec2 p = msm_two_product(a.x, b.x);
  MSM_PRECISE float lo = p.y + (a.x * b.y + a.y * b.x);
  return msm_quick_two_sum(p.x, lo);
}
// a + b c + d e for floats, in double-float.
MSM_FN vec2 msm_df_sum_prod2(float a, float b, float c, float d, float e) {
  return msm_df_add(msm_df_add(vec2(a, 0.0f), msm_two_product(b, c)), msm_two_product(d, e));
}

MSM_END

#endif // MSM_EFT_H
