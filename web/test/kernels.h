// One entry point over the shared functions that the three.js package's shaders call, compiled
// twice: into a WebGL 2 fragment shader (test/math.html, GLSL ES 3.00 through shared.h's GL_ES mode
// and the bundler) and into the C++ tool msm_web_kernels (kernels.cpp), which writes the inputs
// and its own results as JSON for the browser test to compare. A SHARED header: shared.h's rules
// apply. Each function id calls exactly one shared function; arguments are unpacked from KernelIO
// and results packed back, nothing else (no formula lives here).
#ifndef MSM_WEB_KERNELS_H
#define MSM_WEB_KERNELS_H
#include "msm/bias.h"
#include "msm/hamburger4.h"
#include "msm/moments.h"
#include "msm/nonlinear.h"
#include "msm/quantize.h"
#include "msm/shared.h"
#include "msm_three.h"
#include "msm_three_soft.h"

MSM_BEGIN

struct KernelIO {
  vec4 a;
  vec4 b;
  uvec4 u;
};

// Function ids; 'arguments -> results'. nl = NonLinearMoments(a.x, a.y, a.z, a.w).
const int MSM_WK_FMA = 0;                    // a.xyz -> a.x = msm_fma(a.x, a.y, a.z)
const int MSM_WK_MOMENTS4 = 1;               // a.x = unit depth -> a = moments of its signed depth
const int MSM_WK_THETA4_STAR = 2;            // a -> a
const int MSM_WK_THETA4_STAR_INVERSE = 3;    // a -> a
const int MSM_WK_PACK_UNORM16 = 4;           // a -> u.xy
const int MSM_WK_UNPACK_UNORM16 = 5;         // u.xy -> a
const int MSM_WK_APPLY_BIAS = 6;             // a, representation u.x -> a
const int MSM_WK_HAMBURGER4_BOUNDS = 7;      // a = b4, b.x = zf -> a.xy
const int MSM_WK_NL_FROM_MOMENTS = 8;        // a = b4 -> a = nl (Φ)
const int MSM_WK_NL_MOMENTS_FROM = 9;        // a = nl -> a = b4 (Φ⁻¹)
const int MSM_WK_NL_PSI4 = 10;               // a.x = ξ4 -> a.x
const int MSM_WK_NL_PSI4_INVERSE = 11;       // a.x = Ψ4 -> a.x
const int MSM_WK_NL_PACK64 = 12;             // a = nl -> u.xy
const int MSM_WK_NL_UNPACK64 = 13;           // u.xy -> a = nl
const int MSM_WK_NL_PACK32 = 14;             // a = nl -> u.x
const int MSM_WK_NL_UNPACK32 = 15;           // u.x -> a = nl
const int MSM_WK_NL_SHADOW = 16;             // a = nl, b.x = zf -> a.x (HPG Algorithm 3)
const int MSM_WK_THREE_GENERATE = 17;        // a.x = unit depth, u.x = package technique -> a
const int MSM_WK_THREE_SHADOW = 18;          // a = stored texel, b.x = unit zf, u.x = package technique -> a.x
const int MSM_WK_THREE_STORE = 19;           // a = filtered, u.x = package technique -> a
const int MSM_WK_THREE_SAT_TEXEL = 20;       // a.x = unit depth, u.x = kernel width -> u (the table's texel)
const int MSM_WK_THREE_DEPTH_PER_TEXEL = 21; // a.xyz = d/dx, b.xyz = d/dy of (texel, unit depth) -> a.xy
const int MSM_WK_SOFT_BLOCKER4 = 22;         // a = Θ4* average, b.x = zf, u.x = scale -> a.xy = (depth, shadow)
const int MSM_WK_SOFT_SHADOW4 = 23;          // a = Θ4* average, b.x = biased zf, u.x = scale -> a.x
// The package's soft lookup over the test's table (GLSL: the shader's msm_three_sat_fetch; C++:
// msm_web_soft_kernel with a fetch): a = (coord.xyz, tan of the half extent), b = (world per
// depth, world per texel, depth per texel xy), u = (kernel width, table width, table height)
// -> a = (shadow, blocker depth, search shadow, penumbra.x), b.x = penumbra.y.
const int MSM_WK_THREE_SOFT_SHADOW = 24;
const int MSM_WK_OVERDARKEN = 25; // a.x = shadow intensity, a.y = factor -> a.x (the lookups' over-darkening)
// The 64-bit non-linear map's bilinear lookup between two neighbouring texels (msm_nl_pack64's words
// u.xy and u.zw, each row of the lookup the same two): a.x = weight of the second, a.y = unit zf ->
// a.x (msm_three_nl64_bilinear_shadow).
const int MSM_WK_THREE_NL64_BILINEAR = 26;
const int MSM_WK_COUNT = 27;

MSM_FN KernelIO msm_web_kernel_nl(NonLinearMoments m) {
  return KernelIO(vec4(m.y1, m.y2, m.v2, m.xi4), vec4(0.0f), uvec4(0u));
}

MSM_END

#if defined(MSM_SOFT_FLOW)
MSM_BEGIN
MSM_SOFT_FLOW_FN KernelIO msm_web_soft_kernel(MSM_SOFT_FETCH_PARAM KernelIO x) {
  SoftShadow s =
      msm_three_soft_shadow(MSM_SOFT_FETCH_ARG ivec2(int(x.u[1]), int(x.u[2])), vec4(x.a[3], x.b[0], x.b[1], x.b[1]),
                            int(x.u[0]), vec3(x.a[0], x.a[1], x.a[2]), vec2(x.b[2], x.b[3]));
  return KernelIO(vec4(s.shadow, s.blocker_depth, s.search_shadow, s.penumbra[0]),
                  vec4(s.penumbra[1], 0.0f, 0.0f, 0.0f), uvec4(0u));
}
MSM_END
#endif

MSM_BEGIN
MSM_FN KernelIO msm_web_kernel(int function, KernelIO x) {
  KernelIO r = KernelIO(vec4(0.0f), vec4(0.0f), uvec4(0u));
  NonLinearMoments nl = NonLinearMoments(x.a[0], x.a[1], x.a[2], x.a[3]);
  switch (function) {
  case MSM_WK_FMA: r.a[0] = msm_fma(x.a[0], x.a[1], x.a[2]); break;
  case MSM_WK_MOMENTS4: r.a = msm_moments4(msm_signed_depth(x.a[0])); break;
  case MSM_WK_THETA4_STAR: r.a = msm_theta4_star(x.a); break;
  case MSM_WK_THETA4_STAR_INVERSE: r.a = msm_theta4_star_inverse(x.a); break;
  case MSM_WK_PACK_UNORM16: r.u = uvec4(msm_pack_unorm16x4(x.a), 0u, 0u); break;
  case MSM_WK_UNPACK_UNORM16: r.a = msm_unpack_unorm16x4(uvec2(x.u[0], x.u[1])); break;
  case MSM_WK_APPLY_BIAS: r.a = msm_apply_bias(x.a, msm_moment_bias(int(x.u[0]))); break;
  case MSM_WK_HAMBURGER4_BOUNDS: r.a = vec4(msm_hamburger4_bounds(x.a, x.b[0]), 0.0f, 0.0f); break;
  case MSM_WK_NL_FROM_MOMENTS: r = msm_web_kernel_nl(msm_nl_from_moments(x.a)); break;
  case MSM_WK_NL_MOMENTS_FROM: r.a = msm_nl_moments_from(nl); break;
  case MSM_WK_NL_PSI4: r.a[0] = msm_nl_psi4(x.a[0]); break;
  case MSM_WK_NL_PSI4_INVERSE: r.a[0] = msm_nl_psi4_inverse(x.a[0]); break;
  case MSM_WK_NL_PACK64: r.u = uvec4(msm_nl_pack64(nl), 0u, 0u); break;
  case MSM_WK_NL_UNPACK64: r = msm_web_kernel_nl(msm_nl_unpack64(uvec2(x.u[0], x.u[1]))); break;
  case MSM_WK_NL_PACK32: r.u = uvec4(msm_nl_pack32(nl), 0u, 0u, 0u); break;
  case MSM_WK_NL_UNPACK32: r = msm_web_kernel_nl(msm_nl_unpack32(x.u[0])); break;
  case MSM_WK_NL_SHADOW: r.a[0] = msm_nl_shadow(nl, x.b[0]); break;
  case MSM_WK_THREE_GENERATE: r.a = msm_three_generate(int(x.u[0]), x.a[0]); break;
  case MSM_WK_THREE_SHADOW: r.a[0] = msm_three_shadow(int(x.u[0]), x.a, x.b[0]); break;
  case MSM_WK_THREE_STORE: r.a = msm_three_store(int(x.u[0]), x.a); break;
  case MSM_WK_THREE_SAT_TEXEL: r.u = msm_three_sat_texel(x.a[0], int(x.u[0])); break;
  case MSM_WK_THREE_DEPTH_PER_TEXEL:
    r.a = vec4(msm_three_depth_per_texel(vec3(x.a[0], x.a[1], x.a[2]), vec3(x.b[0], x.b[1], x.b[2])), 0.0f, 0.0f);
    break;
  case MSM_WK_SOFT_BLOCKER4: {
    BlockerResult blocker = msm_soft_blocker4(x.a, x.b[0], x.u[0]);
    r.a = vec4(blocker.depth, blocker.shadow, 0.0f, 0.0f);
    break;
  }
  case MSM_WK_SOFT_SHADOW4: r.a[0] = msm_soft_shadow4(x.a, x.b[0], MSM_SOFT_UMBRA_EPSILON, x.u[0]); break;
  case MSM_WK_OVERDARKEN: r.a[0] = msm_overdarken(x.a[0], x.a[1]); break;
  case MSM_WK_THREE_NL64_BILINEAR: {
    vec4 t0 = vec4(unpackUnorm2x16(x.u[0]), unpackUnorm2x16(x.u[1]));
    vec4 t1 = vec4(unpackUnorm2x16(x.u[2]), unpackUnorm2x16(x.u[3]));
    r.a[0] = msm_three_nl64_bilinear_shadow(t0, t1, t0, t1, vec2(x.a[0], 0.0f), x.a[1]);
    break;
  }
#if !MSM_CPP
  case MSM_WK_THREE_SOFT_SHADOW: r = msm_web_soft_kernel(x); break; // C++: msm_web_soft_kernel(fetch, x)
#endif
  default: break;
  }
  return r;
}

MSM_END

#endif // MSM_WEB_KERNELS_H
