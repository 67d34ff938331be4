// Quantization transforms (affine maps chosen so the moments fill [0,1]^m and keep as much
// entropy as fixed-point storage allows) and the fixed-point packings that use them.
//   θ2, θ4  : 2015 §4.3, for depth in [0,1] (θ4 dense 4x4, +12.28 bits; θ2 for VSM, +2 bits)
//   Θ4*     : JCGT Eq. (3), for depth in [-1,1], sparse (odd and even moments apart), +4.21 bits
//   Θ6*     : JCGT §5.4.3 (read with the transposes, see ERRATA.md), +12.51 bits
// Every inverse is the matrix inverse of its transform in double precision, rounded to float.
#ifndef MSM_QUANTIZE_H
#define MSM_QUANTIZE_H
#include "msm/moments.h"
#include "msm/shared.h"

MSM_BEGIN

// ---- 2015 θ4 for [0,1] depth: θ4(b) = M b + (0.0359558848, 0, 0, 0) ----
// mat4 takes columns: each line below is one column of the printed matrix M.
const mat4 MSM_THETA4 =
    mat4(-2.07224649f, 13.7948857f, 0.105877704f, 9.79240621f, 32.2370378f, -59.4683976f, -1.90774663f, -33.76521106f,
         -68.5710746f, 82.035975f, 9.34965551f, 47.9456097f, 39.3703274f, -35.3649032f, -6.65434907f, -23.9728048f);
const mat4 MSM_THETA4_INV =
    mat4(0.222774413998f, 0.154967927412f, 0.145198897079f, 0.16312744626f, 0.077197284885f, 0.139462943721f,
         0.212020217931f, 0.259143229647f, 0.792698660893f, 0.796341590333f, 0.725869458941f, 0.653909265872f,
         0.03194175724f, -0.172282318296f, -0.275801483458f, -0.337613176555f);
const vec4 MSM_THETA4_OFFSET = vec4(0.0359558848f, 0.0f, 0.0f, 0.0f);

MSM_FN vec4 msm_theta4(vec4 b) { return MSM_THETA4 * b + MSM_THETA4_OFFSET; }
// The inverse is written out, in a fixed order and `precise`, so that every device rounds it as the
// CPU build does: a shader's mat4 * vec4 may sum in any order and contract into fma, and the
// one-ulp differences that left in the moments moved Hausdorff 4MSM by up to 0.6 for receivers
// within 1e-4 of the near end, where the bound is that steep (gpu_math_test, technique_shadow4).
MSM_FN vec4 msm_theta4_inverse(vec4 q) {
  vec4 d = q - MSM_THETA4_OFFSET;
  MSM_PRECISE vec4 b =
      ((MSM_THETA4_INV[0] * d[0] + MSM_THETA4_INV[1] * d[1]) + MSM_THETA4_INV[2] * d[2]) + MSM_THETA4_INV[3] * d[3];
  return b;
}

// ---- 2015 θ2 for VSM on [0,1] depth: (b1, 4 b1 - 4 b2) ----
MSM_FN vec2 msm_theta2(vec2 b) { return vec2(b.x, 4.0f * (b.x - b.y)); }
MSM_FN vec2 msm_theta2_inverse(vec2 q) { return vec2(q.x, q.x - 0.25f * q.y); }

// ---- JCGT Θ4* for [-1,1] depth ----
// Odd block (b1, b3) -> (q1, q3): [[3/2, -2], [√3/2, -2√3/9]] + (1/2, 1/2);
// even block (b2, b4) -> (q2, q4): [[4, -4], [1/2, 1/2]].
const float MSM_SQRT3 = 1.7320508075688772f;
MSM_FN vec4 msm_theta4_star(vec4 b) {
  return vec4(1.5f * b[0] - 2.0f * b[2] + 0.5f, 4.0f * b[1] - 4.0f * b[3],
              0.5f * MSM_SQRT3 * b[0] - (2.0f / 9.0f) * MSM_SQRT3 * b[2] + 0.5f, 0.5f * b[1] + 0.5f * b[3]);
}
// Inverse blocks: odd [[-1/3, √3], [-3/4, 3√3/4]], even [[1/8, 1], [-1/8, 1]]; `precise` as
// msm_theta4_inverse, so that devices do not contract the products into fma.
MSM_FN vec4 msm_theta4_star_inverse(vec4 q) {
  float q1 = q[0] - 0.5f, q3 = q[2] - 0.5f;
  MSM_PRECISE vec4 b = vec4(-(1.0f / 3.0f) * q1 + MSM_SQRT3 * q3, 0.125f * q[1] + q[3],
                            -0.75f * q1 + 0.75f * MSM_SQRT3 * q3, -0.125f * q[1] + q[3]);
  return b;
}

// ---- JCGT Θ6* for [-1,1] depth (odd and even moments transformed apart) ----
// mat3 takes columns; the columns of the transposed printed matrix are its printed rows.
const mat3 MSM_THETA6_ODD =
    mat3(2.5f, -1.87499864f, 1.26583039f, -10.0f, 4.20757543f, -1.47644883f, 8.0f, -1.83257679f, 0.71061660f);
const mat3 MSM_THETA6_EVEN = mat3(4.0f, 9.0f, -0.57759806f, -4.0f, -24.0f, 4.61936648f, 0.0f, 16.0f, -3.07953907f);
const vec3 MSM_THETA6_ODD_OFFSET = vec3(0.5f, 0.5f, 0.5f);
const vec3 MSM_THETA6_EVEN_OFFSET = vec3(0.0f, 0.0f, 0.018888946f);
// Their inverses, as columns.
const mat3 MSM_THETA6_ODD_INV =
    mat3(-0.028777890285f, 0.099952358754f, 0.258933539157f, 0.476355509863f, 0.845325814122f, 0.907796170821f,
         1.552428093358f, 1.054725708514f, 0.833273356468f);
const mat3 MSM_THETA6_EVEN_INV =
    mat3(1.25303050231e-05f, -0.249987469695f, -0.374988252839f, 0.1666849411558f, 0.1666849411558f, 0.2187671323336f,
         0.8660254011626f, 0.8660254011626f, 0.81189881359f);

MSM_FN Moments6 msm_theta6_star(Moments6 b) {
  return Moments6(MSM_THETA6_ODD * b.odd + MSM_THETA6_ODD_OFFSET, MSM_THETA6_EVEN * b.even + MSM_THETA6_EVEN_OFFSET);
}
// Written out and `precise` as msm_theta4_inverse: the same rounding on every device.
MSM_FN vec3 msm_theta6_block_inverse(mat3 m, vec3 q) {
  MSM_PRECISE vec3 b = (m[0] * q[0] + m[1] * q[1]) + m[2] * q[2];
  return b;
}
MSM_FN Moments6 msm_theta6_star_inverse(Moments6 q) {
  return Moments6(msm_theta6_block_inverse(MSM_THETA6_ODD_INV, q.odd - MSM_THETA6_ODD_OFFSET),
                  msm_theta6_block_inverse(MSM_THETA6_EVEN_INV, q.even - MSM_THETA6_EVEN_OFFSET));
}

// ---- Fixed-point storage: round to nearest, as Vulkan's UNORM conversion does ----
// At an exact tie (x * 65535 = k + 1/2) GLM rounds away from zero and a device may round to even:
// the two builds can then differ by one step, which the GPU tests accept at ties only.
// NaN is stored as 0, as Vulkan converts NaN to UNORM (and packUnorm's clamp, and the float to
// integer conversion after it, leave NaN undefined in GLSL and in C++): msm_saturate first. Every
// moment representation decodes code 0 to a vector outside the moment space (D1 < 0), which the
// reconstructions read as lit (hamburger4.h), like NaN moments themselves.
// Four values in [0,1] as 16-bit UNORM (RGBA16_UNORM texel = two uints).
MSM_FN uvec2 msm_pack_unorm16x4(vec4 v) {
  return uvec2(packUnorm2x16(vec2(msm_saturate(v[0]), msm_saturate(v[1]))),
               packUnorm2x16(vec2(msm_saturate(v[2]), msm_saturate(v[3]))));
}
MSM_FN vec4 msm_unpack_unorm16x4(uvec2 p) {
  vec2 a = unpackUnorm2x16(p.x);
  vec2 b = unpackUnorm2x16(p.y);
  return vec4(a.x, a.y, b.x, b.y);
}
// Round-trip through 16-bit UNORM storage (what a texture write then read does).
MSM_FN vec4 msm_quantize_unorm16(vec4 v) { return msm_unpack_unorm16x4(msm_pack_unorm16x4(v)); }
MSM_FN vec2 msm_quantize_unorm16x2(vec2 v) {
  return unpackUnorm2x16(packUnorm2x16(vec2(msm_saturate(v[0]), msm_saturate(v[1]))));
}

// Three values in [0,1] as 10-bit UNORM in the RGB channels of A2B10G10R10_UNORM (R lowest).
MSM_FN uint msm_pack_unorm10x3(vec3 v) {
  uvec3 q = uvec3(round(vec3(msm_saturate(v[0]), msm_saturate(v[1]), msm_saturate(v[2])) * 1023.0f));
  return q.x | (q.y << 10u) | (q.z << 20u);
}
MSM_FN vec3 msm_unpack_unorm10x3(uint p) {
  return vec3(float(p & 1023u), float((p >> 10u) & 1023u), float((p >> 20u) & 1023u)) / 1023.0f;
}
MSM_FN Moments6 msm_quantize_unorm10(Moments6 q) {
  return Moments6(msm_unpack_unorm10x3(msm_pack_unorm10x3(q.odd)), msm_unpack_unorm10x3(msm_pack_unorm10x3(q.even)));
}
MSM_FN Moments6 msm_quantize_unorm16(Moments6 q) {
  vec4 a = msm_quantize_unorm16(vec4(q.odd, q.even.x));
  vec4 b = msm_quantize_unorm16(vec4(q.even.y, q.even.z, 0.0f, 0.0f));
  return Moments6(vec3(a.x, a.y, a.z), vec3(a.w, b.x, b.y));
}

MSM_END

#endif // MSM_QUANTIZE_H
