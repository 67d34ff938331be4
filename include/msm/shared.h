// The bridge between GLSL 4.60 and C++20: every header in include/msm/ is valid in both
// languages once this file has been included. Shaders include it through glslc -I<include>;
// C++ includes it normally and gets the same functions in namespace msm, in single precision,
// on top of GLM. A third mode, GLSL ES 3.00 (WebGL 2; the preprocessor defines GL_ES), serves the
// three.js package in web/, whose build bundles the headers a shader needs into JavaScript strings
// (web/scripts/bundle-headers.mjs resolves the #include lines that WebGL lacks).
//
// Rules for the shared headers (each keeps the two builds identical):
//  - functions are declared `MSM_FN type name(...)`; no references, pointers, out/inout
//    parameters or array parameters: several results come back in a struct;
//  - structs are constructed with their type name, `Bounds(lo, hi)` (C++20 aggregates);
//  - float literals carry the f suffix (`0.5f`): GLM's operators take no double scalar;
//  - no swizzles (`v.xy`): write `vec2(v.x, v.y)` or index with `v[i]`;
//  - no `?:` choosing between structs (WebGL rejects it): an `if` instead;
//  - no names that GLSL reserves (`filter`, `sample`, `input`, `output`, `common`, `active`);
//  - constants are `const float NAME = ...;` at file scope, inside MSM_BEGIN/MSM_END;
//  - include guards, not #pragma once.
#ifndef MSM_SHARED_H
#define MSM_SHARED_H

#ifdef __cplusplus
#include <cmath>
#include <cstdint>
#include <glm/glm.hpp>
#include <glm/gtc/packing.hpp>
#include <glm/integer.hpp>
#include <glm/packing.hpp>

namespace msm {
using namespace glm;
using uint = std::uint32_t;
} // namespace msm

#define MSM_FN inline
#define MSM_BEGIN namespace msm {
#define MSM_END }
#define MSM_CPP 1
#else
#define MSM_FN
#define MSM_BEGIN
#define MSM_END
#define MSM_CPP 0
#endif

// `precise` (SPIR-V NoContraction): no contraction into fma and no reassociation of the operation
// whose result it qualifies. Nothing in C++, whose build has -ffp-contract=off instead. GLSL ES
// 3.00 has no `precise` (ES 3.20 and EXT_gpu_shader5 do, WebGL 2 has neither): there the error-free
// transformations are exact only where the compiler neither contracts nor reassociates, which the
// web package's browser test measures (web/test/math.html, on ANGLE's SwiftShader).
#if MSM_CPP
#define MSM_PRECISE
#elif defined(GL_ES)
#define MSM_PRECISE
#else
#define MSM_PRECISE precise
#endif

// GLSL ES: every float and integer at full precision; the shared math assumes IEEE single
// precision and 32-bit integers (floatBitsToInt, packUnorm2x16, the 32-bit packings).
#if !MSM_CPP && defined(GL_ES)
precision highp float;
precision highp int;
#endif

// The error-free transformations (TwoSum, TwoProduct, double-float) that msm_fma's emulation and
// trigonometric.h build on; they need only the macros above.
#include "msm/eft.h"

MSM_BEGIN

const float MSM_PI = 3.14159265358979323846f;
const float MSM_TWO_PI = 6.28318530717958647692f;

// a * b + c with one rounding: exact differences such as b2 - b1² in nearly singular Hankel
// matrices. GLM's fma is an unfused a * b + c, so the C++ side calls std::fma (correctly rounded).
// GLSL's fma() need not be fused either (GLSL 4.60 §8.3 and SPIR-V's GLSL.std.450 Fma promise no
// single rounding, `precise` or not; Mesa's lavapipe computes a * b and then + c), so on the device
// msm_fma is the native fma() only where msm::vk found it fused, and the exact emulation below
// elsewhere: msm::vk::Context probes each device's fma() at creation (src/vk/shaders/fma_probe.comp)
// and every pipeline it creates sets the specialization constant msm_fused_fma (id
// MSM_SPEC_FUSED_FMA_ID) to the verdict; the driver then compiles only one of the two branches.
// Pipelines built outside msm::vk::create_program must set it too (msm::vk::SharedSpecialization);
// left at its default (true), msm_fma is the native fma(), as before.
//
// MSM_SPEC_FUSED_FMA_ID: the constant_id, a fixed number that C++ (which sets it) and GLSL share.
// Ids 2000-2047 are reserved for the shared headers (glslang accepts constant_id <= 2047); shaders
// keep their own constant_ids below 2000.
#define MSM_SPEC_FUSED_FMA_ID 2000

// a * b + c correctly rounded (to nearest, ties to even: what std::fma and a fused fma() give)
// from float additions and multiplications, each rounded once: Boldo & Melquiond's emulated FMA
// ("Emulation of FMA and correctly rounded sums: proved algorithms using rounding to odd", IEEE
// Trans. Computers 57(4), 2008, Algorithm 5.1):
//   p + e = a * b exactly (Dekker's TwoProduct, Veltkamp's split by 2^12 + 1 into 12 + 12 bits),
//   s + t = c + p exactly (Knuth's TwoSum),
//   v = t + e rounded to odd (TwoSum, then one step to the odd neighbor if inexact and even),
//   result = s + v rounded to nearest, which is then a * b + c rounded to nearest.
// 30 flops (split 8, product 9, two TwoSums 12, final sum 1) plus 5 integer/compare/select
// operations, against one fma. Every intermediate is `precise`, so no compiler may contract or
// reassociate it. Preconditions: no overflow or underflow in the intermediates: finite inputs with
// |a|, |b| < 2^100 and |a * b|, |c| each 0 or >= 2^-100 (GPUs flush subnormals). Checked against
// std::fma (gpu_math_test.cpp: EmulatedFmaIsCorrectlyRounded; vk_test.cpp: on the device).
// Its C++ build is exact only without contraction (-ffp-contract=off): C++ code calls msm_fma.
MSM_FN float msm_fma_emulated(float a, float b, float c) {
  vec2 pe = msm_two_product(a, b);   // p + e = a * b
  vec2 st = msm_two_sum(c, pe.x);    // s + t = c + p
  vec2 vw = msm_two_sum(st.y, pe.y); // v + w = t + e
  int bits = floatBitsToInt(vw.x);
  // Rounded to odd: an inexact v with an even last bit moves to its neighbor on w's side (v != 0
  // here: t + e rounds to 0 only if it is 0). Sign-magnitude: +1 is away from zero.
  if (vw.y != 0.0f && (bits & 1) == 0) bits += (vw.y > 0.0f) == (vw.x > 0.0f) ? 1 : -1;
  MSM_PRECISE float r = st.x + intBitsToFloat(bits);
  return r;
}

#if MSM_CPP
MSM_FN float msm_fma(float a, float b, float c) { return std::fma(a, b, c); }
#elif defined(GL_ES)
// GLSL ES 3.00 has no fma(): always the emulation (exact where the compiler keeps the operations
// apart, see MSM_PRECISE).
MSM_FN float msm_fma(float a, float b, float c) { return msm_fma_emulated(a, b, c); }
#else
#ifdef VULKAN
layout(constant_id = MSM_SPEC_FUSED_FMA_ID) const bool msm_fused_fma = true;
#else
const bool msm_fused_fma = true; // OpenGL: no specialization constants
#endif
MSM_FN float msm_fma(float a, float b, float c) {
  if (msm_fused_fma) return fma(a, b, c);
  return msm_fma_emulated(a, b, c);
}
#endif

// clamp(x, 0, 1), the HLSL saturate that GLSL lacks; NaN goes to 0 (GLSL's clamp leaves NaN
// undefined and GLM's returns it), so a degenerate texel shows as lit, never as garbage.
MSM_FN float msm_saturate(float x) { return x > 0.0f ? min(x, 1.0f) : 0.0f; }

// A unit vector orthogonal to the unit vector v: v crossed with the world axis x, or y where v is
// within 26° of x (tangent frames whose orientation does not matter: footprint.h, light_probe.h).
MSM_FN vec3 msm_perpendicular(vec3 v) {
  return normalize(cross(v, abs(v.x) < 0.9f ? vec3(1.0f, 0.0f, 0.0f) : vec3(0.0f, 1.0f, 0.0f)));
}

MSM_END

#endif // MSM_SHARED_H
