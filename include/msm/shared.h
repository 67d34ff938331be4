// The bridge between GLSL 4.60 and C++20: every header in include/msm/ is valid in both
// languages once this file has been included. Shaders include it through glslc -I<include>;
// C++ includes it normally and gets the same functions in namespace msm, in single precision,
// on top of GLM.
//
// Rules for the shared headers (each keeps the two builds identical):
//  - functions are declared `MSM_FN type name(...)`; no references, pointers, out/inout
//    parameters or array parameters: several results come back in a struct;
//  - structs are constructed with their type name, `Bounds(lo, hi)` (C++20 aggregates);
//  - float literals carry the f suffix (`0.5f`): GLM's operators take no double scalar;
//  - no swizzles (`v.xy`): write `vec2(v.x, v.y)` or index with `v[i]`;
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

MSM_BEGIN

const float MSM_PI = 3.14159265358979323846f;

// a * b + c with one rounding: exact differences such as b2 - b1² in nearly singular Hankel
// matrices. GLSL's fma is the GPU's fused multiply-add; GLM's fma is an unfused a * b + c, so the
// C++ side calls std::fma (correctly rounded).
#if MSM_CPP
MSM_FN float msm_fma(float a, float b, float c) { return std::fma(a, b, c); }
#else
MSM_FN float msm_fma(float a, float b, float c) { return fma(a, b, c); }
#endif

// clamp(x, 0, 1), the HLSL saturate that GLSL lacks; NaN goes to 0 (GLSL's clamp leaves NaN
// undefined and GLM's returns it), so a degenerate texel shows as lit, never as garbage.
MSM_FN float msm_saturate(float x) { return x > 0.0f ? min(x, 1.0f) : 0.0f; }

MSM_END

#endif // MSM_SHARED_H
