// Constants of the techniques, each with the reason it has its value and where it comes from.
// Shared by GLSL and C++ (see shared.h). Everything a technique takes as a parameter defaults to
// the value here, and is overridable where the technique is configured.
#ifndef MSM_CONFIG_H
#define MSM_CONFIG_H
#include "msm/shared.h"

MSM_BEGIN

// --- Moment biasing: b' = (1 - alpha) b + alpha b* (2015 §4.2, JCGT §2.5, §4.2, §5.4.3) ---
// 2015: [0,1] depth, b* = E(½δ0 + ½δ1); alpha for float storage (JCGT Fig. 4d).
const float MSM_ALPHA_UNIT_FLOAT = 2.0e-6f;
// 2015: [0,1] depth, 16-bit storage after θ4 needs the stronger bias the paper states.
const float MSM_ALPHA_UNIT_16BIT = 3.0e-5f;
// JCGT: [-1,1] depth in float: worst-case b* = (1,0,0.375,0,0.375) and 3e-7 suffice.
const float MSM_ALPHA_SIGNED_FLOAT = 3.0e-7f;
// JCGT: [-1,1] depth, 16-bit Θ4*: b* = (1,0,0.628,0,0.628) (optimal after Θ4*) with 6e-5.
const float MSM_ALPHA_SIGNED_16BIT = 6.0e-5f;
// JCGT §4.2, App. D.4: 32-bit integer summed-area tables keep ~22.4 bits for 28² kernels: 6e-7,
// towards the b* measured after Θ4* (MSM_BSTAR_SIGNED_16BIT), since the tables store Θ4* moments.
const float MSM_ALPHA_SAT_INT32 = 6.0e-7f;
// JCGT §5.4.3: six moments in 10-bit (64 bits per texel), 16-bit (96) and float (192).
const float MSM_ALPHA6_10BIT = 4.0e-3f;
const float MSM_ALPHA6_16BIT = 8.0e-5f;
const float MSM_ALPHA6_FLOAT = 5.0e-6f;

// 2015 θ4 16-bit storage: its b* = ½δ0 + ½δ1 has D2(b*) = 0, so α protects only the variance,
// and 16-bit rounding moves D2 (the last LDLᵀ pivot of the Hankel matrix) by 2.1e-7 (median) to
// 3e-6 (p99) for one to three depths: 9% of single depths leave the moment space, where the
// bound approached the two-atom limit and read up to 0.83 darker than PCF. bias.h raises D2 of
// that representation to at least this (msm_raise_d2): 0.04 darker at most, for 10% more mean
// error against float storage (edges_test; 1e-7 left 0.15, 1e-6 cost 24%).
const float MSM_MIN_D2_UNIT_16BIT = 5.0e-7f;

// Biasing targets b* (without b0 = 1).
const vec4 MSM_BSTAR_UNIT = vec4(0.5f, 0.5f, 0.5f, 0.5f);             // ½δ0 + ½δ1 on [0,1]
const vec4 MSM_BSTAR_SIGNED_FLOAT = vec4(0.0f, 0.375f, 0.0f, 0.375f); // JCGT §2.5 worst case
const vec4 MSM_BSTAR_SIGNED_16BIT = vec4(0.0f, 0.628f, 0.0f, 0.628f); // JCGT §2.5 after Θ4* (16-bit, SAT)
// JCGT §5.4.3, six moments b* = (1, 0, 0.5566, 0, 0.489, 0, 0.47869382): the odd moments
// (b1, b3, b5) of b* are zero, the even ones (b2, b4, b6) are these.
const vec3 MSM_BSTAR6_EVEN = vec3(0.5566f, 0.489f, 0.47869382f);

// --- Non-linear quantization (HPG 2017 §3) ---
// ξ4 is clamped below at 1.2e-7 so that Ψ4 = ln ln(ξ4·1e7) stays finite (HPG §3.3).
const float MSM_NL_XI4_MIN = 1.2e-7f;
// Upper limit of ξ4 for any depth distribution on [-1,1] (HPG supplementary).
const float MSM_NL_XI4_MAX = 0.25f;
// Clamping y1 = y2, v2 = 0 or 1 away by this tolerance, below 64-bit rounding (HPG §3.4).
const float MSM_NL_TOLERANCE = 1.0e-6f;

// --- Soft shadows ---
// JCGT Eq. (4): weight of the fragment depth in the average blocker depth.
const float MSM_BLOCKER_EPSILON = 1.0e-3f;
// Kneiphof Eq. (19): upper clamp δ2 of the mass at the fragment depth counted into the average
// blocker depth (δ1 = MSM_BLOCKER_EPSILON). The paper gives no value; this one is measured on the
// built-in scenes (ground_truth.soft.*): larger values harden penumbrae where the moments are unsure.
const float MSM_SOFT6_DELTA2 = 0.1f;
// Naive VSSM: minimum variance of (z, z²) of [0,1] depth read from a 32-bit integer table
// (~22.5 bits for a 27² kernel: quantization errors of a few 1e-7 in the variance).
const float MSM_VSSM_MIN_VARIANCE = 1.0e-6f;

// --- Depth bias: subtracted from the fragment's [0,1] shadow-map depth (RenderSettings::depth_bias) ---
// Depth-based techniques: the 16-bit depth map rounds to steps of 1.5e-5; a bias above that keeps
// a receiver from shadowing itself.
const float MSM_DEPTH_BIAS_DEPTH_MAP = 2.0e-5f;
// Linearly filtered moments: they come from the rounded D16 depths while the fragment's depth is a
// float, so a receiver lit straight down is compared against its own texels up to half a step
// (7.6e-6) too far, which the float techniques' tiny moment bias (3e-7) does not absorb
// (msm-hamburger-128 read bare ground as shadowed).
const float MSM_DEPTH_BIAS_FILTERED = 1.0e-5f;
// Non-linearly quantized moments: HPG §5 uses a constant 1e-3 in [-1,1] depth for all results; it
// is half a bin of msm-nl32's 10-bit depths (1/1023), which otherwise shadow a flat receiver facing
// the light wherever its depth rounds towards the light.
const float MSM_DEPTH_BIAS_NONLINEAR = 5.0e-4f;
// Soft shadows of an area light: the 32-bit tables keep ~22 bits of a 27² kernel's moments, plus
// the moment bias: 1e-3 in [-1,1] depth (JCGT §4.4's constant part). PCSS gets the same constant:
// its receiver planes are exact for planar receivers only, and across a 15-texel kernel curved ones
// (the models scene's knots) would shadow themselves (MAE 0.018 at 2e-5, 0.006 at 5e-4).
const float MSM_DEPTH_BIAS_AREA_LIGHT = 5.0e-4f;

// --- Shading ---
// JCGT §2.6: shadow intensity divided by 98% and clamped hides leaking below 2%.
const float MSM_OVERDARKEN_DEFAULT = 0.98f;

// --- Baselines (JCGT Fig. 4, HPG §5.1) ---
const float MSM_EVSM_C_64BIT = 5.54f;      // exponent that 16-bit channels can hold
const float MSM_EVSM_C_POS_128BIT = 40.0f; // c+ at 32-bit float channels
const float MSM_EVSM_C_NEG_128BIT = 5.54f; // c- at 32-bit float channels
const float MSM_ESM_C_DEFAULT = 80.0f;     // ESM exponent for [0,1] depth in float

MSM_END

#endif // MSM_CONFIG_H
