// One entry point over the shared math, compiled twice: into the compute shader kernels.comp
// (GLSL, on the Vulkan device) and into gpu_math_test.cpp (C++, on the CPU). The test feeds both
// the same KernelIO[] and compares. A SHARED header: shared.h's rules apply (no `in`/`out`
// names, constructors by type name, f-suffixed literals, no swizzles).
//
// Each function id calls exactly one shared function; its arguments are unpacked from KernelIO
// and its results packed back, nothing else (no formula lives here). Argument layout per id:
// x.a/x.b are floats, x.u integers (packed storage words, representations, term counts, and the
// float parameters of CSM as bits). Unused outputs stay 0. The std430 layout of KernelIO (three
// 16-byte members, stride 48) matches the C++ struct.
#ifndef MSM_GPU_KERNELS_H
#define MSM_GPU_KERNELS_H
#include "msm/baselines.h"
#include "msm/bias.h"
#include "msm/blocker.h"
#include "msm/config.h"
#include "msm/hamburger4.h"
#include "msm/hamburger6.h"
#include "msm/hausdorff4.h"
#include "msm/moments.h"
#include "msm/nonlinear.h"
#include "msm/quantize.h"
#include "msm/rectification.h"
#include "msm/roots.h"
#include "msm/scattering.h"
#include "msm/shared.h"
#include "msm/soft.h"
#include "msm/techniques.h"
#include "msm/three_moments.h"
#include "msm/trigonometric.h"

// kernels.comp's storage buffers: KernelIO[] in and out.
#define MSM_BINDING_KERNELS_INPUTS 0
#define MSM_BINDING_KERNELS_OUTPUTS 1

MSM_BEGIN

struct KernelIO {
  vec4 a;
  vec4 b;
  uvec4 u;
};

// Function ids; 'arguments -> results' in KernelIO terms. b4 = four moments, b6 = Moments6(a.xyz,
// b.xyz), nl = NonLinearMoments(a.x, a.y, a.z, a.w).
// shared.h
const int MSM_K_FMA = 0;      // a.xyz -> a.x = msm_fma(a.x, a.y, a.z)
const int MSM_K_SATURATE = 1; // a.x -> a.x
// moments.h
const int MSM_K_MOMENTS4 = 2;       // a.x = z -> a
const int MSM_K_MOMENTS6 = 3;       // a.x = z -> a.xyz odd, b.xyz even
const int MSM_K_TRIG_MOMENTS = 4;   // a.x = z -> a
const int MSM_K_UNIT_TO_SIGNED = 5; // a -> a
// quantize.h
const int MSM_K_THETA4 = 6;               // a -> a
const int MSM_K_THETA4_INVERSE = 7;       // a -> a
const int MSM_K_THETA4_STAR = 8;          // a -> a
const int MSM_K_THETA4_STAR_INVERSE = 9;  // a -> a
const int MSM_K_THETA6_STAR = 10;         // b6 -> a.xyz, b.xyz
const int MSM_K_THETA6_STAR_INVERSE = 11; // b6 -> a.xyz, b.xyz
const int MSM_K_THETA2 = 12;              // a.xy -> a.xy
const int MSM_K_THETA2_INVERSE = 13;      // a.xy -> a.xy
const int MSM_K_PACK_UNORM16 = 14;        // a -> u.xy
const int MSM_K_UNPACK_UNORM16 = 15;      // u.xy -> a
const int MSM_K_PACK_UNORM10 = 16;        // a.xyz -> u.x
const int MSM_K_UNPACK_UNORM10 = 17;      // u.x -> a.xyz
const int MSM_K_QUANTIZE6_UNORM16 = 18;   // b6 -> a.xyz, b.xyz (round trip)
const int MSM_K_QUANTIZE6_UNORM10 = 19;   // b6 -> a.xyz, b.xyz (round trip)
// bias.h
const int MSM_K_APPLY_BIAS = 20;  // a, representation u.x -> a
const int MSM_K_APPLY_BIAS6 = 21; // b6, representation u.x -> a.xyz, b.xyz
// roots.h, hamburger6.h
const int MSM_K_SOLVE_QUADRATIC = 22; // a.xyz = c -> a.xy
const int MSM_K_CUBIC_ROOTS = 23;     // a = q -> a.xyz
// hamburger4.h, hausdorff4.h, three_moments.h
const int MSM_K_HAMBURGER4_BOUNDS = 24;    // a = b4, b.x = zf -> a.xy
const int MSM_K_HAMBURGER4_CANONICAL = 25; // a = b4, b.x = zf -> a.xyz nodes, b.xyz weights
const int MSM_K_HAUSDORFF4 = 26;           // a = b4, b.xyz = (zf, lo, hi) -> a.x
const int MSM_K_TWO_DEPTHS = 27;           // a.xyz = (b1, b2, b3) -> a = (z, w)
// hamburger6.h
const int MSM_K_HAMBURGER6_BOUNDS = 28;    // b6, a.w = zf -> a.xy
const int MSM_K_HAMBURGER6_BLEND = 29;     // b6, a.w = zf, b.w = beta -> a.x
const int MSM_K_HAMBURGER6_CANONICAL = 30; // b6, a.w = zf -> a nodes, b weights
// blocker.h
const int MSM_K_BLOCKER4 = 31;       // a = b4, b.x = zf -> a.xy = (depth, shadow)
const int MSM_K_BLOCKER4_UPPER = 32; // a = b4, b.xyz = (zf, delta1, delta2) -> a.xy
const int MSM_K_BLOCKER6 = 33;       // b6, a.w = zf -> a.xy
const int MSM_K_BLOCKER6_UPPER = 34; // b6, a.w = zf, u.xy = bits of (delta1, delta2) -> a.xy
// trigonometric.h
const int MSM_K_TRIG_BOUNDS = 35; // a = trigonometric moments, b.x = zf -> a.xy
// nonlinear.h
const int MSM_K_NL_FROM_MOMENTS = 36; // a = b4 -> a = nl (Φ)
const int MSM_K_NL_MOMENTS_FROM = 37; // a = nl -> a = b4 (Φ⁻¹)
const int MSM_K_NL_PSI4 = 38;         // a.x = ξ4 -> a.x = Ψ4
const int MSM_K_NL_PSI4_INVERSE = 39; // a.x = Ψ4 -> a.x = ξ4
const int MSM_K_NL_PACK64 = 40;       // a = nl -> u.xy
const int MSM_K_NL_UNPACK64 = 41;     // u.xy -> a = nl
const int MSM_K_NL_PACK32 = 42;       // a = nl -> u.x
const int MSM_K_NL_UNPACK32 = 43;     // u.x -> a = nl
const int MSM_K_NL_SHADOW = 44;       // a = nl, b.x = zf -> a.x (HPG Algorithm 3)
// baselines.h
const int MSM_K_VSM_SHADOW = 45;        // a.xy = b, a.z = zf -> a.x
const int MSM_K_VSM_SHADOW_THETA2 = 46; // a.xy = q, a.z = zf -> a.x
const int MSM_K_ESM_MOMENT = 47;        // a.xy = (z, c) -> a.x
const int MSM_K_ESM_SHADOW = 48;        // a.xyz = (b, zf, c) -> a.x
const int MSM_K_ESM_LOG_MIX = 49;       // a.xyz = (la, lb, t) -> a.x
const int MSM_K_EVSM2_MOMENTS = 50;     // a.xy = (z, c+) -> a.xy
const int MSM_K_EVSM2_SHADOW = 51;      // a.xy = b, b.xyz = (zf, c+, min variance) -> a.x
const int MSM_K_EVSM4_MOMENTS = 52;     // a.xyz = (z, c+, c-) -> a
const int MSM_K_EVSM4_SHADOW = 53;      // a = b, b = (zf, c+, c-, min variance) -> a.x
const int MSM_K_CSM_BASIS = 54;         // a.x = z, u.x = texel -> a
const int MSM_K_CSM_SHADOW = 55;        // a, b = texels 0, 1 (terms 1..4); u = (terms, bits of damping,
                                        // scale, zf); offset 0 -> a.x
const int MSM_K_OVERDARKEN = 56;        // a.xy = (shadow, factor) -> a.x
// techniques.h, soft.h, bias.h: whole reconstructions from stored texels (the edge classes)
const int MSM_K_TECHNIQUE_SHADOW4 = 57; // a = stored texel, b.x = unit zf, u.x = technique id -> a.x
const int MSM_K_SOFT4 = 58;    // a = Θ4* average, b.xy = (zf, depth bias), u.x = 1 for Eq. (19), u.y = the table's
                               // scale -> a.xyz = (depth, blocker shadow, shadow)
const int MSM_K_SOFT6 = 59;    // a.xyz, b.xyz = Θ6* average (odd, even), a.w = zf, b.w = depth bias, u.x as above,
                               // u.y = the tables' scale -> a.xyz
const int MSM_K_RAISE_D2 = 60; // a = b4, b.x = min D2 -> a
// scattering.h: the visible fraction of a view ray from a prefix-summed rectified texel
const int MSM_K_SCATTERING4 = 61; // a = stored texel, b.xy = (zf, beta), u.x = representation -> a.x
const int MSM_K_SCATTERING6 = 62; // a.xyz, b.xyz = stored Θ6* (odd, even), a.w = zf, b.w = beta, u.x = rep -> a.x
// rectification.h: the mip level of the filtered resampling (§5.2)
const int MSM_K_RESAMPLING_LOD = 63; // a = (r, φ, r step, φ step), b = (map_per_x, map_per_y) -> a.x
// rectification.h: the transmittance layers
const int MSM_K_TRANSMITTANCE_LAYERS = 64; // a = (Δ_lo, Δ_hi, delta, K) -> a.xy = (k0 + t, Δ_(K/2) / Δ_lo)
// rectification.h: the prefix sums' mip level of a pixel (App. D.5)
const int MSM_K_PREFIX_SUM_LOD = 65; // a = (du/dx, du/dy, dv/dx, dv/dy), b = (width, height, full circle) -> a.x
// scattering.h: the proportional β from the shadow's bounds and the view and light directions
const int MSM_K_SCATTERING_BETA = 66; // a = (lower, upper, view.xy), b = (view.z, towards_light) -> a.x
// scattering.h: the Henyey–Greenstein phase function of a light and a view direction
const int MSM_K_SCATTERING_PHASE = 67; // a = (towards_light, g), b.xyz = view direction -> a.x
// scattering.h: a spot light's unshadowed in-scattering by its angle ψ (the light at (0, 2, 0)
// shining down, cones 30° / 25°, 10 W/sr, range 6, σt 0.2, albedo 1)
const int MSM_K_SPOT_INSCATTERING = 68; // a = (camera, s), b = (view direction, g) -> a.x
// rectification.h: a spot light's prefix-sum weight of a light ray ψ in a row weighed at γ
const int MSM_K_SPOT_PREFIX_WEIGHT = 69; // a = (d, ψ, γ, σt), b.xy = (g, cone) -> a.x
const int MSM_K_COUNT = 70;

// Structs as results: six moments (odd in a.xyz, even in b.xyz), non-linear moments, blockers.
MSM_FN KernelIO msm_kernel_result6(Moments6 m) { return KernelIO(vec4(m.odd, 0.0f), vec4(m.even, 0.0f), uvec4(0u)); }
MSM_FN KernelIO msm_kernel_result_nl(NonLinearMoments m) {
  return KernelIO(vec4(m.y1, m.y2, m.v2, m.xi4), vec4(0.0f), uvec4(0u));
}
MSM_FN KernelIO msm_kernel_result_blocker(BlockerResult o) {
  return KernelIO(vec4(o.depth, o.shadow, 0.0f, 0.0f), vec4(0.0f), uvec4(0u));
}

// The dispatcher that the compute shader and the C++ build both run. Long on purpose: one case per
// function of the shared headers, a flat switch (GLSL has no function pointers).
MSM_FN KernelIO msm_test_kernel(int function, KernelIO x) {
  KernelIO r = KernelIO(vec4(0.0f), vec4(0.0f), uvec4(0u));
  Moments6 b6 = Moments6(vec3(x.a), vec3(x.b));
  NonLinearMoments nl = NonLinearMoments(x.a[0], x.a[1], x.a[2], x.a[3]);
  switch (function) {
  case MSM_K_FMA: r.a[0] = msm_fma(x.a[0], x.a[1], x.a[2]); break;
  case MSM_K_SATURATE: r.a[0] = msm_saturate(x.a[0]); break;
  case MSM_K_MOMENTS4: r.a = msm_moments4(x.a[0]); break;
  case MSM_K_MOMENTS6: r = msm_kernel_result6(msm_moments6(x.a[0])); break;
  case MSM_K_TRIG_MOMENTS: r.a = msm_trig_moments(x.a[0]); break;
  case MSM_K_UNIT_TO_SIGNED: r.a = msm_unit_to_signed_moments(x.a); break;
  case MSM_K_THETA4: r.a = msm_theta4(x.a); break;
  case MSM_K_THETA4_INVERSE: r.a = msm_theta4_inverse(x.a); break;
  case MSM_K_THETA4_STAR: r.a = msm_theta4_star(x.a); break;
  case MSM_K_THETA4_STAR_INVERSE: r.a = msm_theta4_star_inverse(x.a); break;
  case MSM_K_THETA6_STAR: r = msm_kernel_result6(msm_theta6_star(b6)); break;
  case MSM_K_THETA6_STAR_INVERSE: r = msm_kernel_result6(msm_theta6_star_inverse(b6)); break;
  case MSM_K_THETA2: r.a = vec4(msm_theta2(vec2(x.a)), 0.0f, 0.0f); break;
  case MSM_K_THETA2_INVERSE: r.a = vec4(msm_theta2_inverse(vec2(x.a)), 0.0f, 0.0f); break;
  case MSM_K_PACK_UNORM16: r.u = uvec4(msm_pack_unorm16x4(x.a), 0u, 0u); break;
  case MSM_K_UNPACK_UNORM16: r.a = msm_unpack_unorm16x4(uvec2(x.u)); break;
  case MSM_K_PACK_UNORM10: r.u = uvec4(msm_pack_unorm10x3(vec3(x.a)), 0u, 0u, 0u); break;
  case MSM_K_UNPACK_UNORM10: r.a = vec4(msm_unpack_unorm10x3(x.u[0]), 0.0f); break;
  case MSM_K_QUANTIZE6_UNORM16: r = msm_kernel_result6(msm_quantize_unorm16(b6)); break;
  case MSM_K_QUANTIZE6_UNORM10: r = msm_kernel_result6(msm_quantize_unorm10(b6)); break;
  case MSM_K_APPLY_BIAS: r.a = msm_apply_bias(x.a, msm_moment_bias(int(x.u[0]))); break;
  case MSM_K_APPLY_BIAS6: r = msm_kernel_result6(msm_apply_bias6(b6, msm_moment_bias6(int(x.u[0])))); break;
  case MSM_K_SOLVE_QUADRATIC: r.a = vec4(msm_solve_quadratic(vec3(x.a)), 0.0f, 0.0f); break;
  case MSM_K_CUBIC_ROOTS: r.a = vec4(msm_cubic_roots(x.a), 0.0f); break;
  case MSM_K_HAMBURGER4_BOUNDS: r.a = vec4(msm_hamburger4_bounds(x.a, x.b[0]), 0.0f, 0.0f); break;
  case MSM_K_HAMBURGER4_CANONICAL: {
    Canonical4 c = msm_hamburger4_canonical(x.a, x.b[0]);
    r.a = vec4(c.z, 0.0f);
    r.b = vec4(c.w, 0.0f);
    break;
  }
  case MSM_K_HAUSDORFF4: r.a[0] = msm_hausdorff4_lower(x.a, x.b[0], x.b[1], x.b[2]); break;
  case MSM_K_TWO_DEPTHS: {
    TwoDepths t = msm_two_depths_from_three_moments(vec3(x.a));
    r.a = vec4(t.z, t.w);
    break;
  }
  case MSM_K_HAMBURGER6_BOUNDS: r.a = vec4(msm_hamburger6_bounds(b6, x.a[3]), 0.0f, 0.0f); break;
  case MSM_K_HAMBURGER6_BLEND: r.a[0] = msm_hamburger6_blend(b6, x.a[3], x.b[3]); break;
  case MSM_K_HAMBURGER6_CANONICAL: {
    Canonical6 c = msm_hamburger6_canonical(b6, x.a[3]);
    r.a = c.z;
    r.b = c.w;
    break;
  }
  case MSM_K_BLOCKER4: r = msm_kernel_result_blocker(msm_blocker4(x.a, x.b[0])); break;
  case MSM_K_BLOCKER4_UPPER: r = msm_kernel_result_blocker(msm_blocker4_upper(x.a, x.b[0], x.b[1], x.b[2])); break;
  case MSM_K_BLOCKER6: r = msm_kernel_result_blocker(msm_blocker6(b6, x.a[3])); break;
  case MSM_K_BLOCKER6_UPPER:
    r = msm_kernel_result_blocker(msm_blocker6_upper(b6, x.a[3], uintBitsToFloat(x.u[0]), uintBitsToFloat(x.u[1])));
    break;
  case MSM_K_TRIG_BOUNDS: r.a = vec4(msm_trig_bounds(x.a, x.b[0]), 0.0f, 0.0f); break;
  case MSM_K_NL_FROM_MOMENTS: r = msm_kernel_result_nl(msm_nl_from_moments(x.a)); break;
  case MSM_K_NL_MOMENTS_FROM: r.a = msm_nl_moments_from(nl); break;
  case MSM_K_NL_PSI4: r.a[0] = msm_nl_psi4(x.a[0]); break;
  case MSM_K_NL_PSI4_INVERSE: r.a[0] = msm_nl_psi4_inverse(x.a[0]); break;
  case MSM_K_NL_PACK64: r.u = uvec4(msm_nl_pack64(nl), 0u, 0u); break;
  case MSM_K_NL_UNPACK64: r = msm_kernel_result_nl(msm_nl_unpack64(uvec2(x.u))); break;
  case MSM_K_NL_PACK32: r.u = uvec4(msm_nl_pack32(nl), 0u, 0u, 0u); break;
  case MSM_K_NL_UNPACK32: r = msm_kernel_result_nl(msm_nl_unpack32(x.u[0])); break;
  case MSM_K_NL_SHADOW: r.a[0] = msm_nl_shadow(nl, x.b[0]); break;
  case MSM_K_VSM_SHADOW: r.a[0] = msm_vsm_shadow(vec2(x.a), x.a[2]); break;
  case MSM_K_VSM_SHADOW_THETA2: r.a[0] = msm_vsm_shadow_theta2(vec2(x.a), x.a[2]); break;
  case MSM_K_ESM_MOMENT: r.a[0] = msm_esm_moment(x.a[0], x.a[1]); break;
  case MSM_K_ESM_SHADOW: r.a[0] = msm_esm_shadow(x.a[0], x.a[1], x.a[2]); break;
  case MSM_K_ESM_LOG_MIX: r.a[0] = msm_esm_log_mix(x.a[0], x.a[1], x.a[2]); break;
  case MSM_K_EVSM2_MOMENTS: r.a = vec4(msm_evsm2_moments(x.a[0], x.a[1]), 0.0f, 0.0f); break;
  case MSM_K_EVSM2_SHADOW: r.a[0] = msm_evsm2_shadow(vec2(x.a), x.b[0], x.b[1], x.b[2]); break;
  case MSM_K_EVSM4_MOMENTS: r.a = msm_evsm4_moments(x.a[0], x.a[1], x.a[2]); break;
  case MSM_K_EVSM4_SHADOW: r.a[0] = msm_evsm4_shadow(x.a, x.b[0], x.b[1], x.b[2], x.b[3]); break;
  case MSM_K_CSM_BASIS: r.a = msm_csm_basis_texel(x.a[0], int(x.u[0])); break;
  case MSM_K_CSM_SHADOW: {
    CsmParams p = CsmParams(int(x.u[0]), uintBitsToFloat(x.u[1]), uintBitsToFloat(x.u[2]), 0.0f);
    CsmMoments m = CsmMoments(mat4(x.a, x.b, vec4(0.0f), vec4(0.0f)), mat4(0.0f));
    r.a[0] = msm_csm_shadow(m, uintBitsToFloat(x.u[3]), p);
    break;
  }
  case MSM_K_OVERDARKEN: r.a[0] = msm_overdarken(x.a[0], x.a[1]); break;
  case MSM_K_TECHNIQUE_SHADOW4: {
    int t = int(x.u[0]);
    r.a[0] = msm_technique_shadow(t, MsmTexel(x.a, vec4(0.0f)), x.b[0], msm_technique_default_params(t));
    break;
  }
  case MSM_K_SOFT4: {
    vec4 params = msm_technique_default_params(x.u[0] == 1u ? MSM_TECH_MSSM6 : MSM_TECH_MSSM4);
    BlockerResult o = msm_soft_blocker4_select(x.a, x.b[0], params, x.u[1]);
    r.a = vec4(o.depth, o.shadow, msm_soft_shadow4(x.a, x.b[0] - x.b[1], MSM_SOFT_UMBRA_EPSILON, x.u[1]), 0.0f);
    break;
  }
  case MSM_K_SOFT6: {
    vec4 params = msm_technique_default_params(x.u[0] == 1u ? MSM_TECH_MSSM6 : MSM_TECH_MSSM4);
    BlockerResult o = msm_soft_blocker6_select(b6, x.a[3], params, x.u[1]);
    r.a = vec4(o.depth, o.shadow, msm_soft_shadow6(b6, x.a[3] - x.b[3], MSM_SOFT_UMBRA_EPSILON, x.u[1]), 0.0f);
    break;
  }
  case MSM_K_RAISE_D2: r.a = msm_raise_d2(x.a, x.b[0]); break;
  case MSM_K_SCATTERING4: r.a[0] = msm_scattering_visibility4(x.a, int(x.u[0]), x.b[0], x.b[1]); break;
  case MSM_K_SCATTERING6: r.a[0] = msm_scattering_visibility6(b6, int(x.u[0]), x.a[3], x.b[3]); break;
  case MSM_K_RESAMPLING_LOD:
    r.a[0] = msm_rectified_resampling_lod(vec2(x.a[0], x.a[1]), vec2(x.a[2], x.a[3]), vec2(x.b[0], x.b[1]),
                                          vec2(x.b[2], x.b[3]));
    break;
  case MSM_K_SCATTERING_BETA:
    r.a[0] = msm_scattering_beta_proportional(
        vec2(x.a[0], x.a[1]), msm_scattering_beta_adaptive(vec3(x.b[1], x.b[2], x.b[3]), vec3(x.a[2], x.a[3], x.b[0])));
    break;
  case MSM_K_SCATTERING_PHASE:
    r.a[0] = msm_phase_henyey_greenstein_between(vec3(x.a[0], x.a[1], x.a[2]), vec3(x.b[0], x.b[1], x.b[2]), x.a[3]);
    break;
  case MSM_K_PREFIX_SUM_LOD:
    r.a[0] = msm_prefix_sum_lod(vec2(x.a[0], x.a[1]), vec2(x.a[2], x.a[3]), vec2(x.b[0], x.b[1]), x.b[2] != 0.0f);
    break;
  case MSM_K_TRANSMITTANCE_LAYERS: {
    vec2 k = msm_transmittance_layer_lookup(vec2(x.a[0], x.a[1]), x.a[2], x.a[3]);
    r.a[0] = k.x + k.y;
    r.a[1] = msm_transmittance_layer_step(vec2(x.a[0], x.a[1]), floor(0.5f * x.a[3]), x.a[3]) / x.a[0];
    break;
  }
  case MSM_K_SPOT_INSCATTERING:
    r.a[0] = msm_spot_unshadowed_inscattering(vec3(x.a), vec3(x.b), x.a[3], vec3(0.0f, 2.0f, 0.0f),
                                              vec3(0.0f, -1.0f, 0.0f), vec3(10.0f), 6.0f, 0.8660254f, 0.9063078f, 0.2f,
                                              1.0f, x.b[3], MSM_SPOT_INSCATTERING_SAMPLES)
                 .x;
    break;
  case MSM_K_SPOT_PREFIX_WEIGHT:
    r.a[0] = msm_spot_prefix_sum_weight(x.a[0], x.a[1], x.a[2], x.a[3], x.b[0], x.b[1]);
    break;
  default: break;
  }
  return r;
}

MSM_END

#endif // MSM_GPU_KERNELS_H
