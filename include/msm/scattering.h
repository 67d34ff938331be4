// Single scattering in a homogeneous medium (JCGT 2017 §5.1.1), written once for the renderer's
// shaders, the ray tracer's ground truth and the tests. Radiance reaching the camera through a
// view ray of length s that starts at the camera p and runs along the unit direction ω_p, lit by
// the directional lights l:
//   exp(−σt s) L_s + Σ_l f(ω_l, ω_p) E_l ∫₀ˢ exp(−σt t) V_l(p + t ω_p) dt
// with L_s the surface radiance at the end of the ray, E_l light l's irradiance, V_l its
// visibility and f(ω_l, ω_p) = ρ σt p(cos θ): the scattering coefficient σs = ρ σt (ρ the
// scattering albedo) times a phase function p normalized over the sphere (∫ p dω = 1, units 1/sr).
// θ is the scattering angle between the light's direction of travel and the direction the
// scattered light travels, towards the camera (−ω_p): cos θ = dot(towards_light, ω_p). Henyey–
// Greenstein with g > 0 scatters forwards, so looking into the light is brightest; g = 0 is
// isotropic, 1/(4π). Spot lights' f E varies along the ray (msm_local_light_inscattering; its
// integral over the light's angle ψ, msm_spot_unshadowed_inscattering).
#ifndef MSM_SCATTERING_H
#define MSM_SCATTERING_H
#include "msm/baselines.h"
#include "msm/bias.h"
#include "msm/hamburger4.h"
#include "msm/hamburger6.h"
#include "msm/local_light.h"
#include "msm/quantize.h"
#include "msm/shading.h"
#include "msm/shared.h"

MSM_BEGIN

// Henyey–Greenstein phase function, (1 − g²) / (4π (1 + g² − 2 g cos θ)^(3/2)), of the scattering
// angle given by its versines 1 − cos θ and 1 + cos θ. As |g| → 1 the function peaks at cos θ =
// sign(g), where 1 + g² − 2 g cos θ falls to (1 − |g|)², 1e-8 at |g| = 0.9999: as a difference of
// terms near 1, which float rounds by 6e-8, that is lost. Written as (1 − |g|)² + 2 |g| (1 ∓ cos θ)
// and (1 − g)(1 + g) nothing cancels (1 − |g| is exact for |g| >= ½), given versines without
// cancellation (msm_versines_between). Precondition: −1 < g < 1 (the scene loader refuses others),
// versines in [0, 2].
MSM_FN float msm_phase_henyey_greenstein_versines(float one_minus_cos, float one_plus_cos, float g) {
  const float a = abs(g);
  const float one_minus_a = 1.0f - a;
  const float versine = max(g >= 0.0f ? one_minus_cos : one_plus_cos, 0.0f);
  const float denominator = one_minus_a * one_minus_a + 2.0f * a * versine;
  return (1.0f - g) * (1.0f + g) / (4.0f * MSM_PI * denominator * sqrt(denominator));
}

// The versines (1 − cos θ, 1 + cos θ) of the angle θ between unit vectors u and v, as ½|u − v|²
// and ½|u + v|²: accurate to a few ulp where 1 ∓ dot(u, v) loses every digit (θ below 3e-4 rad,
// where float's cos θ is 1). Vectors of length 1 + ε add (ε_u − ε_v)² / 2 to them (float's
// normalize: ε ~ 1e-7, so ~1e-14).
MSM_FN vec2 msm_versines_between(vec3 u, vec3 v) {
  const vec3 difference = u - v, sum = u + v;
  return vec2(0.5f * dot(difference, difference), 0.5f * dot(sum, sum));
}

// Henyey–Greenstein of cos θ: exact to a few ulp for the float cos θ given (1 ∓ cos θ is exact
// where it is small), but float's cos θ itself cannot tell angles below 3e-4 rad from 0; where
// the directions are at hand, msm_phase_henyey_greenstein_between.
MSM_FN float msm_phase_henyey_greenstein(float cos_theta, float g) {
  return msm_phase_henyey_greenstein_versines(1.0f - cos_theta, 1.0f + cos_theta, g);
}

// Henyey–Greenstein of the angle between unit vectors: the light's towards_light and the view
// direction (from the camera outwards), cos θ = dot(towards_light, view_dir).
MSM_FN float msm_phase_henyey_greenstein_between(vec3 towards_light, vec3 view_dir, float g) {
  const vec2 versines = msm_versines_between(towards_light, view_dir);
  return msm_phase_henyey_greenstein_versines(versines.x, versines.y, g);
}

// f(ω_l, ω_p) of the radiance above: ρ σt p(cos θ), cos θ = dot(towards_light, view_dir) of unit
// vectors (view_dir from the camera outwards).
MSM_FN float msm_scattering_phase_term(float extinction, float albedo, float g, vec3 towards_light, vec3 view_dir) {
  return albedo * extinction * msm_phase_henyey_greenstein_between(towards_light, view_dir, g);
}

// A spot or point light's in-scattering at a point p of a view ray (view_dir from the camera
// outwards): f(ω_l, ω_p) E_l(p), the phase term towards the light's position times the irradiance
// its intensity gives there (msm_local_light_irradiance: inverse square, the spot's cone, nothing
// beyond range). Unlike a directional light's, it varies along the ray, so it is integrated with the
// ray's samples: ∫₀ˢ exp(−σt t) f E V dt, what the ray tracer and the ray marching both estimate.
MSM_FN vec3 msm_local_light_inscattering(vec3 p, vec3 view_dir, vec3 position, vec3 axis, vec3 intensity, float range,
                                         float cos_outer, float cos_inner, float extinction, float albedo, float g) {
  vec3 to_light = position - p;
  float d = length(to_light);
  vec3 towards = d > 0.0f ? to_light / d : -view_dir;
  vec3 e = msm_local_light_irradiance(intensity, d, range, dot(-towards, axis), cos_outer, cos_inner);
  return msm_scattering_phase_term(extinction, albedo, g, towards, view_dir) * e;
}

// ---- A spot light's in-scattering by its angle at the light (rectification.h's spot section) ----
// In the triangle of the light L, the camera p (d = |L − p|) and a point of a view ray, ψ the angle
// at L from the direction L→p and γ the angle at p from p→L, the law of sines gives (t, r): the
// point at t from p along the view ray γ and at r from L along the light ray ψ; (−1, −1) where the
// rays do not meet (ψ + γ >= π).
MSM_FN vec2 msm_spot_ray_distances(float d, float psi, float gamma) {
  float s = sin(psi + gamma);
  return s > 0.0f && psi + gamma < MSM_PI ? (d / s) * vec2(sin(psi), sin(gamma)) : vec2(-1.0f);
}
// dt/dψ along the view ray γ: d sin γ / sin²(ψ + γ), which is r² / h with h = d sin γ (the light's
// distance from the view ray): dt / r² = dψ / h. Precondition: 0 < ψ + γ < π.
MSM_FN float msm_spot_dt_dpsi(float d, float psi, float gamma) {
  float s = sin(psi + gamma);
  return d * sin(gamma) / (s * s);
}

// The angle between two vectors, accurate at 0 and π alike; 0 where one is zero (GLSL's atan(0, 0)
// is undefined).
MSM_FN float msm_angle_between(vec3 a, vec3 b) {
  float sine = length(cross(a, b)), cosine = dot(a, b);
  return sine == 0.0f && cosine == 0.0f ? 0.0f : atan(sine, cosine);
}

// Samples of msm_spot_unshadowed_inscattering in the renderer's prefiltered scattering.
const int MSM_SPOT_INSCATTERING_SAMPLES = 32;

// A spot light's unshadowed in-scattering along the view ray of length s from `camera` along the
// unit view_dir: ∫₀ˢ exp(−σt t) f E dt with f E = msm_local_light_inscattering, by the midpoint rule
// in ψ with `samples` points over the part of [0, ψ(end)] that the spot's outer cone can reach
// (|ψ − β| <= its half-angle, β the axis's angle from the direction light → camera), dt =
// (dt/dψ) dψ: the inverse square of E cancels against dt/dψ = r² / h, so the integrand is smooth
// where one in t peaks as 1/r² near the light (only the range's end and the cone's edges are not).
// 0 for a ray of no length, through the light or outside the cone.
MSM_FN vec3 msm_spot_unshadowed_inscattering(vec3 camera, vec3 view_dir, float s, vec3 position, vec3 axis,
                                             vec3 intensity, float range, float cos_outer, float cos_inner,
                                             float extinction, float albedo, float g, int samples) {
  vec3 to_light = position - camera;
  float d = length(to_light);
  if (!(d > 0.0f) || !(s > 0.0f)) return vec3(0.0f);
  float gamma = msm_angle_between(view_dir, to_light);
  float psi_end = msm_angle_between(-to_light, camera + s * view_dir - position);
  // Only the light rays of the outer cone carry light: ψ within its half-angle of the axis's angle.
  float beta = msm_angle_between(-to_light, axis), outer = acos(clamp(cos_outer, -1.0f, 1.0f));
  float psi_lo = max(beta - outer, 0.0f), psi_hi = min(beta + outer, psi_end);
  if (!(sin(gamma) > 0.0f) || !(psi_hi > psi_lo)) return vec3(0.0f);
  float step = (psi_hi - psi_lo) / float(samples);
  vec3 sum = vec3(0.0f);
  for (int k = 0; k < samples; ++k) {
    float psi = psi_lo + (float(k) + 0.5f) * step;
    float t = msm_spot_ray_distances(d, psi, gamma).x;
    if (!(t >= 0.0f)) continue;
    vec3 fe = msm_local_light_inscattering(camera + t * view_dir, view_dir, position, axis, intensity, range, cos_outer,
                                           cos_inner, extinction, albedo, g);
    sum += (exp(-extinction * t) * msm_spot_dt_dpsi(d, psi, gamma) * step) * fe;
  }
  return sum;
}

// (1 − exp(−x)) / x for x >= 0 without the cancellation of 1 − exp(−x) at small x (GLSL has no
// expm1): a Taylor series below 1e-2 (its first dropped term, x⁴/120, is below float rounding).
MSM_FN float msm_one_minus_exp_over_x(float x) {
  if (x < 1e-2f) return 1.0f - x * (0.5f - x * (1.0f / 6.0f - x * (1.0f / 24.0f)));
  return (1.0f - exp(-x)) / x;
}

// ∫_a^b exp(−σt t) dt = [−exp(−σt t) / σt]_a^b for 0 <= a <= b: the transmittance-weighted length
// of a segment of a view ray (the weights w(u, v) of §5.1.1 and the maximal scattering of a ray).
// Precondition: σt > 0.
MSM_FN float msm_transmittance_integral(float extinction, float a, float b) {
  const float segment = max(b - a, 0.0f);
  return exp(-extinction * a) * segment * msm_one_minus_exp_over_x(extinction * segment);
}

// The radiance at the camera of a ray of length s ending on a surface of radiance L_s, given the
// visible fraction of its in-scattering (1 everywhere lit, 0 everywhere shadowed):
//   exp(−σt s) L_s + f E_l visible_fraction ∫₀ˢ exp(−σt t) dt.
MSM_FN vec3 msm_scattered_radiance(vec3 surface_radiance, vec3 irradiance, float extinction, float phase_term, float s,
                                   float visible_fraction) {
  return exp(-extinction * s) * surface_radiance +
         (phase_term * visible_fraction * msm_transmittance_integral(extinction, 0.0f, s)) * irradiance;
}

// ---- Several lights: the sum over l of the radiance above ----
// Each light's in-scattering is msm_scattered_radiance's second term with its own phase term and
// visible fraction; the surface's attenuated radiance is counted once. The ray's visible fraction
// over all lights is the mean of the lights' visible fractions weighted by what each scatters into
// an unshadowed ray, the luminance of f(ω_l, ω_p) E_l (the factor ∫₀ˢ exp(−σt t) dt is common):
// the in-scattered luminance is this fraction times the unshadowed one. With one light it is that
// light's visible fraction (up to a rounding of w V / w); with no light that scatters (every
// weight 0) it is 1, as for a ray of length 0.
struct ScatteringSum {
  vec3 inscattered;       // Σ_l f_l E_l V_l ∫₀ˢ exp(−σt t) dt
  float weighted_visible; // Σ_l w_l V_l, w_l = luminance(f_l E_l)
  float weight;           // Σ_l w_l
};

MSM_FN ScatteringSum msm_scattering_sum_none() { return ScatteringSum(vec3(0.0f), 0.0f, 0.0f); }

// Light l's weight w_l in the visible fraction of several lights: the luminance of f_l E_l.
MSM_FN float msm_scattering_light_weight(vec3 irradiance, float phase_term) {
  return phase_term * msm_luminance(irradiance);
}

// Adds light l (irradiance E_l, phase term f_l, the ray's visible fraction V_l) to the sum.
MSM_FN ScatteringSum msm_scattering_add_light(ScatteringSum sum, vec3 irradiance, float extinction, float phase_term,
                                              float s, float visible_fraction) {
  const float w = msm_scattering_light_weight(irradiance, phase_term);
  return ScatteringSum(sum.inscattered +
                           msm_scattered_radiance(vec3(0.0f), irradiance, extinction, phase_term, s, visible_fraction),
                       sum.weighted_visible + w * visible_fraction, sum.weight + w);
}

// The ray's visible fraction over the lights of the sum (see above).
MSM_FN float msm_scattering_sum_visible(ScatteringSum sum) {
  return sum.weight > 0.0f ? msm_saturate(sum.weighted_visible / sum.weight) : 1.0f;
}

// The radiance at the camera: the surface's radiance attenuated plus every light's in-scattering.
MSM_FN vec3 msm_scattering_sum_radiance(vec3 surface_radiance, float extinction, float s, ScatteringSum sum) {
  return exp(-extinction * s) * surface_radiance + sum.inscattered;
}

// ---- Prefiltered single scattering (JCGT §5.3-5.4): the visible fraction of a view ray ----
// Every function below turns one bilinear lookup in the prefix-summed rectified map
// (rectification.h: msm_rectified_view_lookup) into the transmittance-weighted visible fraction
// of the ray, for msm_scattered_radiance's visible_fraction. zf is the ray's rectified depth in
// SIGNED [-1, 1] (msm_signed_depth of the lookup's depth) for moments, in [0,1] for CSM.
//
// β (§5.3.1) weighs the canonical atom at zf (weight w0) in the VISIBILITY: the paper's
// v0 = β, v_l = 1 for atoms at or behind zf. So visibility = 1 − (lower + (1 − β) w0):
// β = 0 is the sharp lower bound of the visibility (the upper bound of the shadow, i.e. scattering
// underestimated), β = 1 the sharp upper bound (overestimated), β = ½ the worst-case optimum.
const float MSM_SCATTERING_BETA_DEFAULT = 0.5f;

// Adaptive overestimation (§5.3.1): β = (1 + ω_lᵀ ω_p) / 2, with ω_l towards the light and ω_p
// from the scattering point towards the camera, i.e. −view_dir for view_dir from the camera
// outwards. Looking into the light (view_dir = towards_light, the epipole, where leaking is
// worst) gives β = 0; looking away from it (the anti-epipole, where no occluder can lie behind
// the ray and underestimation would remove all scattering) gives β = 1.
MSM_FN float msm_scattering_beta_adaptive(vec3 towards_light, vec3 view_dir) {
  return msm_adaptive_overestimation_beta(towards_light, -view_dir);
}

// The scattering techniques' choice of β, from their parameter z (techniques.cpp): 1 a fixed β
// (the parameter y), 2 §5.3.1's adaptive β, anything else the proportional β below.
const int MSM_SCATTERING_BETA_PROPORTIONAL = 0;
const int MSM_SCATTERING_BETA_FIXED = 1;
const int MSM_SCATTERING_BETA_ADAPTIVE = 2;
MSM_FN int msm_scattering_beta_mode(float z) {
  return z == 1.0f   ? MSM_SCATTERING_BETA_FIXED
         : z == 2.0f ? MSM_SCATTERING_BETA_ADAPTIVE
                     : MSM_SCATTERING_BETA_PROPORTIONAL;
}

// ---- The proportional β (msm's default; docs/techniques.md, "The proportional β") ----
// The bounds leave one weight undecided: w0, the canonical atom at the ray's own depth zf. Of the
// rest, the lower bound of the shadow s0 is surely in shadow and 1 − s1 (s1 the upper bound) surely
// lit. The proportional β gives w0 to both in that ratio, β = (1 − s1) / ((1 − s1) + s0): a ray
// that is mostly lit (trees, a bunny in haze) is overestimated, one that is mostly shadowed (a room
// behind thin walls) underestimated, where §5.3.1's β, a function of the view direction alone,
// underestimates whatever the scene when the camera looks towards the light. ½ where nothing is
// decided (a decided mass below 1e-6 blends towards it), without a branch. Then, as §5.3.1 wants,
// towards the epipole it falls to 0 (msm_scattering_epipole_ramp: no occluder can lie in front of
// the ray there, so the bounds leak): β = min(ratio, ramp).
// Measured against the ground truth on the four scenes (rows +adaptive of scattering.*) and the
// bunny: 6–61% less error than §5.3.1's β, the epipole's leaking within 2% of it.
MSM_FN float msm_scattering_beta_mass_ratio(vec2 shadow_bounds) {
  float lit = 1.0f - msm_saturate(shadow_bounds.y), shadowed = msm_saturate(shadow_bounds.x);
  float decided = lit + shadowed;
  return mix(0.5f, lit / max(decided, 1e-6f), msm_saturate(decided * 1e6f));
}

// §5.3.1's β a = (1 + ω_lᵀω_p) / 2 eased to 1 outside the cone a < MSM_SCATTERING_EPIPOLE_CONE
// about the epipole ((a / c)(2 − a / c): 0 at the epipole, 1 with zero slope at the cone's edge).
// c = 0.1 is the cone of ω_lᵀω_p < −0.8, 36.9° about the epipole; of 0.1, 0.25 and 0.5 it had the
// least error on all four built-in scenes, the epipole's leaking within 2% of §5.3.1's.
const float MSM_SCATTERING_EPIPOLE_CONE = 0.1f;
MSM_FN float msm_scattering_epipole_ramp(float adaptive_beta) {
  float x = msm_saturate(adaptive_beta * (1.0f / MSM_SCATTERING_EPIPOLE_CONE));
  return x * (2.0f - x);
}

// The proportional β of a ray with the shadow's sharp bounds (lower, upper) and §5.3.1's β
// (msm_scattering_beta_adaptive of its view and light directions).
MSM_FN float msm_scattering_beta_proportional(vec2 shadow_bounds, float adaptive_beta) {
  return min(msm_scattering_beta_mass_ratio(shadow_bounds), msm_scattering_epipole_ramp(adaptive_beta));
}

// The visible fraction between the bounds: the shadow's (lower, upper) blended with the atom's
// share 1 − β in the shadow, clamped.
MSM_FN float msm_scattering_visibility_between(vec2 shadow_bounds, float beta) {
  return 1.0f - msm_saturate(mix(shadow_bounds.x, shadow_bounds.y, 1.0f - beta));
}

// β of a ray by the technique's choice (msm_scattering_beta_mode): the fixed β, §5.3.1's adaptive
// β, or the proportional β of the shadow's bounds.
MSM_FN float msm_scattering_beta(int mode, vec2 shadow_bounds, float fixed_beta, float adaptive_beta) {
  if (mode == MSM_SCATTERING_BETA_FIXED) return msm_saturate(fixed_beta);
  if (mode == MSM_SCATTERING_BETA_ADAPTIVE) return adaptive_beta;
  return msm_scattering_beta_proportional(shadow_bounds, adaptive_beta);
}

// Four moments. stored: the prefix-summed texel as sampled; representation MSM_REP_SIGNED_THETA4
// (Θ4* in 4 x 16-bit UNORM, 64 bits, α = 6e-5: the 64-bit Θ4*) or MSM_REP_SIGNED_FLOAT
// (canonical moments in 4 x 32-bit float, α = 3e-7). Sharp lower and upper bounds of
// Hamburger 4MSM (hamburger4.h), blended by β.
// msm_scattering_shadow_bounds4: the shadow's sharp (lower, upper) bounds, for a β that depends
// on them (msm_scattering_beta_proportional).
MSM_FN vec2 msm_scattering_shadow_bounds4(vec4 stored, int representation, float zf) {
  vec4 b = representation == MSM_REP_SIGNED_THETA4 ? msm_theta4_star_inverse(stored) : stored;
  b = msm_apply_bias(b, msm_moment_bias(representation));
  return msm_hamburger4_bounds(b, zf);
}
MSM_FN float msm_scattering_visibility4(vec4 stored, int representation, float zf, float beta) {
  return msm_scattering_visibility_between(msm_scattering_shadow_bounds4(stored, representation, zf), beta);
}

// Six moments (§5.4): stored holds Θ6* moments (quantize.h) in the representation
// MSM_REP6_UNORM10 (6 x 10 bits, α = 4e-3), MSM_REP6_UNORM16 (2 + 4 x 16 bits, α = 8e-5) or
// MSM_REP6_FLOAT (6 x 32-bit float, α = 5e-6), biased towards the b* of §5.4.3 (config.h).
// Blinn's cubic and the divided-difference weights of §5.4.2 are hamburger6.h's.
// msm_scattering_shadow_bounds6: the shadow's sharp (lower, upper) bounds, as for four moments.
MSM_FN vec2 msm_scattering_shadow_bounds6(Moments6 stored, int representation, float zf) {
  Moments6 b = msm_apply_bias6(msm_theta6_star_inverse(stored), msm_moment_bias6(representation));
  return msm_hamburger6_bounds(b, zf);
}
MSM_FN float msm_scattering_visibility6(Moments6 stored, int representation, float zf, float beta) {
  return msm_scattering_visibility_between(msm_scattering_shadow_bounds6(stored, representation, zf), beta);
}

// Klehm et al. 2014: a convolution shadow map of 32 coefficients (16 sin/cos terms) at 8 bits.
// Its reconstruction has no bounds to blend; the scaled expansion of surface shadows (scale 2,
// which biases towards a lower bound of the shadow, baselines.h) would remove the scattering of
// every ray as long as the ray's own depth is reconstructed as half-shadowed, so scattering uses
// scale 1 (the plain estimate, ½ at an occluder's depth: the analogue of β = ½) and the default
// damping against ringing. Depth on [0,1].
MSM_FN CsmParams msm_csm_scattering_params() {
  return CsmParams(MSM_CSM_MAX_TERMS, MSM_CSM_DAMPING_DEFAULT, 1.0f, 0.0f);
}
// m: the prefix-summed texels decoded to [-1,1] (msm_csm_from_unorm per texel).
MSM_FN float msm_scattering_visibility_csm(CsmMoments m, float zf, CsmParams p) {
  return 1.0f - msm_csm_shadow(m, zf, p);
}

// ---- Ray marching (the baseline; Tóth and Umenhoffer 2009) ----
// n equidistant segments of a ray of length s; sample i (0-based) at distance (i + jitter) s / n
// with jitter in [0, 1) (the same for all samples of a pixel: blue noise per pixel), weighted by
// the segment's transmittance integral. visible_fraction = Σ weight_i V_i / ∫_0^s exp(−σt t) dt,
// exactly 1 when every sample is lit.
MSM_FN float msm_ray_march_distance(float s, int n, int i, float jitter) { return (float(i) + jitter) * s / float(n); }
MSM_FN float msm_ray_march_weight(float extinction, float s, int n, int i) {
  return msm_transmittance_integral(extinction, float(i) * s / float(n), float(i + 1) * s / float(n));
}

MSM_END

#endif // MSM_SCATTERING_H
