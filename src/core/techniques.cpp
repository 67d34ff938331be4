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

constexpr Technique kTechniques[] = {
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
