#include "msm/cpu/techniques.h"

#include "msm/msm.h"

#include <stdexcept>

namespace msm::cpu {
namespace {

Texel from(vec4 v) { return {v.x, v.y, v.z, v.w, 0, 0, 0, 0}; }
vec4 to_vec4(const Texel& t) { return vec4(t[0], t[1], t[2], t[3]); }
Texel identity(const Texel& t) { return t; }
Texel unorm16(const Texel& t) { return from(msm_quantize_unorm16(to_vec4(t))); }

// ---- Four power moments ----
Texel moments_unit(float d) { return from(msm_moments4(d)); }
Texel moments_signed(float d) { return from(msm_moments4(msm_signed_depth(d))); }
Texel theta4(float d) { return from(msm_theta4(msm_moments4(d))); }
Texel theta4_star(float d) { return from(msm_theta4_star(msm_moments4(msm_signed_depth(d)))); }

float hamburger_unit_float(const Texel& t, float zf) {
    return msm_hamburger4_lower(msm_apply_bias(to_vec4(t), msm_moment_bias(MSM_REP_UNIT_FLOAT)), zf);
}
float hamburger_signed_float(const Texel& t, float zf) {
    vec4 b = msm_apply_bias(to_vec4(t), msm_moment_bias(MSM_REP_SIGNED_FLOAT));
    return msm_hamburger4_lower(b, msm_signed_depth(zf));
}
float hamburger_theta4(const Texel& t, float zf) {
    vec4 b = msm_apply_bias(msm_theta4_inverse(to_vec4(t)), msm_moment_bias(MSM_REP_UNIT_THETA4));
    return msm_hamburger4_lower(b, zf);
}
float hamburger_theta4_star(const Texel& t, float zf) {
    vec4 b = msm_apply_bias(msm_theta4_star_inverse(to_vec4(t)), msm_moment_bias(MSM_REP_SIGNED_THETA4));
    return msm_hamburger4_lower(b, msm_signed_depth(zf));
}
float hausdorff_unit_float(const Texel& t, float zf) {
    vec4 b = msm_apply_bias(to_vec4(t), msm_moment_bias(MSM_REP_UNIT_FLOAT));
    return msm_hausdorff4_lower(b, zf, 0.0f, 1.0f);
}
float hausdorff_theta4(const Texel& t, float zf) {
    vec4 b = msm_apply_bias(msm_theta4_inverse(to_vec4(t)), msm_moment_bias(MSM_REP_UNIT_THETA4));
    return msm_hausdorff4_lower(b, zf, 0.0f, 1.0f);
}

// ---- Non-linearly quantized MSM (HPG 2017): filtered float moments -> Φ -> 64/32 bits ----
Texel from(NonLinearMoments m) { return {m.y1, m.y2, m.v2, m.xi4, 0, 0, 0, 0}; }
NonLinearMoments to_nl(const Texel& t) { return NonLinearMoments(t[0], t[1], t[2], t[3]); }
Texel nl64_store(const Texel& t) { return from(msm_nl_quantize64(msm_nl_from_filtered(to_vec4(t)))); }
Texel nl32_store(const Texel& t) { return from(msm_nl_quantize32(msm_nl_from_filtered(to_vec4(t)))); }
float nl_shade(const Texel& t, float zf) { return msm_nl_shadow(to_nl(t), msm_signed_depth(zf)); }

// ---- Baselines ----
Texel vsm_theta2(float d) { vec2 q = msm_vsm_moments_theta2(d); return {q.x, q.y, 0, 0, 0, 0, 0, 0}; }
Texel vsm_float(float d) { vec2 q = msm_vsm_moments(d); return {q.x, q.y, 0, 0, 0, 0, 0, 0}; }
Texel unorm16x2(const Texel& t) { vec2 q = msm_quantize_unorm16x2(vec2(t[0], t[1])); return {q.x, q.y, 0, 0, 0, 0, 0, 0}; }
float vsm_theta2_shade(const Texel& t, float zf) {
    return msm_vsm_shadow_theta2(vec2(t[0], t[1]), zf, MSM_VSM_MIN_VARIANCE_UNORM16);
}
float vsm_float_shade(const Texel& t, float zf) { return msm_vsm_shadow(vec2(t[0], t[1]), zf); }
Texel esm(float d) { return {msm_esm_moment(d, MSM_ESM_C_DEFAULT), 0, 0, 0, 0, 0, 0, 0}; }
float esm_shade(const Texel& t, float zf) { return msm_esm_shadow(t[0], zf); }
Texel evsm2_half(float d) { vec2 q = msm_evsm2_moments(msm_signed_depth(d), MSM_EVSM_C_64BIT); return {q.x, q.y, 0, 0, 0, 0, 0, 0}; }
Texel half2(const Texel& t) { vec2 q = msm_quantize_half2(vec2(t[0], t[1])); return {q.x, q.y, 0, 0, 0, 0, 0, 0}; }
float evsm2_half_shade(const Texel& t, float zf) {
    return msm_evsm2_shadow(vec2(t[0], t[1]), msm_signed_depth(zf), MSM_EVSM_C_64BIT, MSM_EVSM_MIN_VARIANCE_HALF);
}
Texel evsm4_half(float d) { return from(msm_evsm4_moments(msm_signed_depth(d), MSM_EVSM_C_64BIT, MSM_EVSM_C_64BIT)); }
Texel half4(const Texel& t) { return from(msm_quantize_half4(to_vec4(t))); }
float evsm4_half_shade(const Texel& t, float zf) {
    return msm_evsm4_shadow(to_vec4(t), msm_signed_depth(zf), MSM_EVSM_C_64BIT, MSM_EVSM_C_64BIT,
                            MSM_EVSM_MIN_VARIANCE_HALF);
}
Texel evsm4_float(float d) {
    return from(msm_evsm4_moments(msm_signed_depth(d), MSM_EVSM_C_POS_128BIT, MSM_EVSM_C_NEG_128BIT));
}
float evsm4_float_shade(const Texel& t, float zf) {
    return msm_evsm4_shadow(to_vec4(t), msm_signed_depth(zf), MSM_EVSM_C_POS_128BIT, MSM_EVSM_C_NEG_128BIT,
                            MSM_EVSM_MIN_VARIANCE_FLOAT);
}
// Convolution shadow map with 4 Fourier terms (8 float channels), damped and scaled to a lower bound.
Texel csm4(float d) {
    vec4 a = msm_csm_basis_texel(d, 0), b = msm_csm_basis_texel(d, 1);
    return {a.x, a.y, a.z, a.w, b.x, b.y, b.z, b.w};
}
float csm4_shade(const Texel& t, float zf) {
    CsmParams p = msm_csm_default_params();
    p.terms = 4;
    float xf = msm_csm_receiver(zf, p);
    float sum = msm_csm_texel_terms(vec4(t[0], t[1], t[2], t[3]), xf, 0, p) +
                msm_csm_texel_terms(vec4(t[4], t[5], t[6], t[7]), xf, 1, p);
    return msm_csm_resolve(sum, p);
}

// ---- Six moments (JCGT §5.4), [-1,1] depth, Θ6* for fixed-point storage ----
Texel from(Moments6 m) { return {m.odd.x, m.odd.y, m.odd.z, m.even.x, m.even.y, m.even.z, 0, 0}; }
Moments6 to_m6(const Texel& t) { return Moments6(vec3(t[0], t[1], t[2]), vec3(t[3], t[4], t[5])); }
Texel m6_float(float d) { return from(msm_moments6(msm_signed_depth(d))); }
Texel m6_theta(float d) { return from(msm_theta6_star(msm_moments6(msm_signed_depth(d)))); }
Texel m6_unorm16(const Texel& t) { return from(msm_quantize_unorm16(to_m6(t))); }
Texel m6_unorm10(const Texel& t) { return from(msm_quantize_unorm10(to_m6(t))); }
float m6_shade(Moments6 b, int representation, float zf) {
    return msm_hamburger6_lower(msm_apply_bias6(b, msm_moment_bias6(representation)), msm_signed_depth(zf));
}
float m6_float_shade(const Texel& t, float zf) { return m6_shade(to_m6(t), MSM_REP6_FLOAT, zf); }
float m6_16_shade(const Texel& t, float zf) { return m6_shade(msm_theta6_star_inverse(to_m6(t)), MSM_REP6_UNORM16, zf); }
float m6_10_shade(const Texel& t, float zf) { return m6_shade(msm_theta6_star_inverse(to_m6(t)), MSM_REP6_UNORM10, zf); }

// ---- Trigonometric MSM (2015), [0,1] depth, 4 x float ----
Texel trig(float d) { return from(msm_trig_moments(d)); }
float trig_shade(const Texel& t, float zf) { return msm_trig_lower(msm_trig_bias(to_vec4(t)), zf); }

constexpr Technique kTechniques[] = {
    {"vsm-32", "VSM, 2 x 16-bit UNORM after θ2, depth in [0,1] (2015)", 32, 2, vsm_theta2, unorm16x2, vsm_theta2_shade},
    {"vsm-64", "VSM, 2 x float", 64, 2, vsm_float, identity, vsm_float_shade},
    {"esm-32", "ESM, 1 x float, c = 80 on [0,1]", 32, 1, esm, identity, esm_shade},
    {"evsm2-32", "EVSM, positive warp, 2 x half, c = 5.54 on [-1,1]", 32, 2, evsm2_half, half2, evsm2_half_shade},
    {"evsm4-64", "EVSM, both warps, 4 x half, c = 5.54 (JCGT Fig. 4a)", 64, 4, evsm4_half, half4, evsm4_half_shade},
    {"evsm4-128", "EVSM, both warps, 4 x float, c+ = 40, c- = 5.54 (JCGT Fig. 4e)", 128, 4, evsm4_float, identity,
     evsm4_float_shade},
    {"csm-4", "Convolution shadow map, 4 Fourier terms in 8 floats, damped", 256, 8, csm4, identity, csm4_shade},
    {"msm-hamburger-128-unit", "Hamburger 4MSM, 4 x float, depth in [0,1] (2015)", 128, 4, moments_unit, identity,
     hamburger_unit_float},
    {"msm-hamburger-128", "Hamburger 4MSM, 4 x float, depth in [-1,1] (JCGT 2017)", 128, 4, moments_signed, identity,
     hamburger_signed_float},
    {"msm-hamburger-64-theta4", "Hamburger 4MSM, 4 x 16-bit UNORM after θ4, depth in [0,1] (2015)", 64, 4, theta4,
     unorm16, hamburger_theta4},
    {"msm-hamburger-64", "Hamburger 4MSM, 4 x 16-bit UNORM after Θ4*, depth in [-1,1] (JCGT 2017)", 64, 4,
     theta4_star, unorm16, hamburger_theta4_star},
    {"msm-hausdorff-128-unit", "Hausdorff 4MSM on [0,1], 4 x float (2015)", 128, 4, moments_unit, identity,
     hausdorff_unit_float},
    {"msm-hausdorff-64-theta4", "Hausdorff 4MSM on [0,1], 4 x 16-bit UNORM after θ4 (2015)", 64, 4, theta4, unorm16,
     hausdorff_theta4},
    {"tmsm-128", "Trigonometric MSM, 4 x float, depth in [0,1] (2015)", 128, 4, trig, identity, trig_shade},
    {"msm6-192", "Hamburger 6MSM, 6 x float, depth in [-1,1] (JCGT §5.4)", 192, 6, m6_float, identity, m6_float_shade},
    {"msm6-96", "Hamburger 6MSM, 6 x 16-bit UNORM after Θ6* (JCGT §5.4.3)", 96, 6, m6_theta, m6_unorm16, m6_16_shade},
    {"msm6-64", "Hamburger 6MSM, 6 x 10-bit UNORM after Θ6* (JCGT §5.4.3)", 64, 6, m6_theta, m6_unorm10, m6_10_shade},
    {"msm-nl64", "Non-linearly quantized 4MSM, 4 x 16-bit (y1, y2, v2, Ψ4(ξ4)) (HPG 2017)", 64, 4, moments_signed,
     nl64_store, nl_shade},
    {"msm-nl32", "Non-linearly quantized 4MSM, 32-bit packed (HPG 2017)", 32, 4, moments_signed, nl32_store, nl_shade},
};

} // namespace

std::span<const Technique> techniques() { return kTechniques; }

const Technique& find_technique(std::string_view name) {
    std::string valid;
    for (const Technique& t : kTechniques) {
        if (t.name == name) return t;
        valid += (valid.empty() ? "" : ", ") + std::string(t.name);
    }
    throw std::invalid_argument("unknown technique '" + std::string(name) + "'; valid: " + valid);
}

float filtered_shadow(const Technique& technique, std::span<const float> depths, std::span<const float> weights,
                      float unit_zf) {
    if (depths.size() != weights.size() || depths.empty())
        throw std::invalid_argument("filtered_shadow: need as many weights as depths, at least one");
    Texel sum{};
    float total = 0.0f;
    for (size_t i = 0; i < depths.size(); ++i) {
        Texel t = technique.generate(depths[i]);
        for (int c = 0; c < technique.channels; ++c) sum[c] += weights[i] * t[c];
        total += weights[i];
    }
    if (!(total > 0.0f)) throw std::invalid_argument("filtered_shadow: weights must have a positive sum");
    for (int c = 0; c < technique.channels; ++c) sum[c] /= total;
    return technique.shade(technique.store_load(sum), unit_zf);
}

float percentage_closer(std::span<const float> depths, std::span<const float> weights, float unit_zf) {
    float shadow = 0.0f, total = 0.0f;
    for (size_t i = 0; i < depths.size(); ++i) {
        if (depths[i] < unit_zf) shadow += weights[i];
        total += weights[i];
    }
    return shadow / total;
}

} // namespace msm::cpu
