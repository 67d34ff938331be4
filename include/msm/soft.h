// Moment soft shadow mapping, the per-pixel math (JCGT 2017 §4.3-4.5, App. D.4; Kneiphof et al.
// 2017 §3.2, §4.2): blocker search region, average blocker depth, penumbra (filter) size, umbra
// early-out, depth bias, final shadow intensity; for a directional area light and an
// orthographic shadow map whose summed-area tables are built as in sat.h. Functions only: the
// inputs are values the caller has already fetched, so the CPU and any shader call the same code.
// Shared by GLSL and C++ (see shared.h).
//
// ---- Geometry: how far blockers reach (directional area light, orthographic shadow map) ----
// The light is the set of directions ℓ + a X + b Y, with ℓ the unit vector towards the light, X
// and Y the shadow map's axes and (a, b) in a disc of radius tan(θ/2) (θ the angular diameter) or
// in the rectangle [-tan(θx/2), tan(θx/2)] × [-tan(θy/2), tan(θy/2)]: a planar emitter at infinity,
// the model of msm::reference's soft effect. Depth grows away from the light. From a receiver p at
// depth d_f (world units along ℓ), the ray towards light point (a, b), p + s (ℓ + a X + b Y),
// reaches depth d_f - s at lateral offset s (a, b). So a blocker at depth d_b < d_f can occlude p
// only within lateral distance (d_f - d_b) tan(θ/2) of p's shadow-map position, and for a planar
// blocker at d_b the visible fraction of the light is exactly the unoccluded fraction of that
// disc (or rectangle) on the blocker's plane. In texels, with w_d world units per unit of depth
// (of the depth convention used: the frustum's depth range / 2 for [-1,1] depth) and w_t world
// units per texel (frustum width / resolution, per axis):
//     half-width in texels = spread · (zf - z_b),   spread = tan(θ/2) · w_d / w_t   (per axis).
//  - blocker search (JCGT §4.3, PCSS [Fernando 2005]): blockers can lie anywhere from the near
//    plane z_near (-1 in [-1,1] depth) to zf, the farthest reaching at z_near: half-width
//    spread · (zf - z_near);
//  - filter (penumbra estimation): all blockers assumed at the average blocker depth z_avg:
//    half-width spread · (zf - z_avg). Kneiphof Eq. (5), sz_f = sz_L (d - z_avg) / d, is the
//    same similar triangles for a light of size sz_L at distance d; at infinity sz_L / d becomes
//    2 tan(θ/2) (full width = 2 × half-width).
// The tables give box filters: exact for a rectangular light (JCGT §4.6.3); for a disc light a
// box of the disc's radius covers the disc (pass tan(θ/2)·√π/2 instead for a box of equal area).
//
// ---- Geometry: spot lights (a sphere of radius R, a perspective map of radial depth) ----
// The map looks from the sphere's centre o; its depth is u = r / range (r the distance from o),
// z = 2u - 1 in [-1,1]; its texel coordinates are uniform in the tangent plane at unit distance,
// (x, y) = (tan of the angles off the axis), a texel T = 2 tan(outer half-angle) / N wide. From a
// receiver p at distance r_f, the rays to the sphere's points fill a cone about p → o that is R
// wide at o and 0 at p; it crosses the sphere of radius r_b about o (a blocker's distance) R (r_f -
// r_b) / r_f away from the line p → o, which o sees under the angle R (r_f - r_b) / (r_f r_b)
// = R (1/r_b - 1/r_f) (similar triangles; PCSS's w_light (d_r - d_b) / d_b on the receiver, seen
// from the light). Per unit angle the tangent-plane coordinates move by sqrt((1 + x²)(1 + x² + y²))
// along x and sqrt((1 + y²)(1 + x² + y²)) along y at (x, y) (the gnomonic projection: the extent of
// a small cone's image along each axis; 1 on the axis). So in texels, per axis,
//     half-width = spread · reach,   spread = R / (2 T range) · stretch(x, y),
//     reach = 2 (1/u_b - 1/u_f) = (z_f - z_b) / (u_f u_b),
// the orthographic reach z_f - z_b divided by u_f u_b: the same depth difference reaches farther
// near the light. The blocker search takes the nearest blocker there can be, at the sphere's
// surface (u = R / range: nothing nearer casts a shadow that the sphere's points do not all see
// around), the penumbra the average blocker depth, as above; the kernel limits below apply alike.
//
// ---- Kernel size limits ----
// sat.h's queries are exact for rectangles of at most n_t texels. A region of width L texels
// starting anywhere touches at most floor(L) + 2 texels, and at most L + 1 if L is an integer;
// so half-widths are clamped to (W - 1) / 2 for a kernel of at most W texels per axis
// (n_t = W², e.g. W = 27: JCGT's 27² search region): every query then touches <= W × W texels.
// They are also at least 0.5 texel: a one-texel box with fractional borders is bilinear
// interpolation of the moment map, the hard-shadow limit at contact points.
//
// ---- The widest kernel per technique ----
// W bounds not only the queries but the precision: the tables keep log2((2^32 - 1) / W²) bits per
// moment (sat.h; 22.5 at W = 27, 18.0 at 127, 16.7 at 200, 16.0 at 255), and the moment bias has
// to cover that rounding (msm_soft_alpha4/6 below). Where the bias needed grows past what keeps
// a region of one depth (a plane parallel to the map: the Hankel matrices' worst case) intact —
// a receiver on it lit, blockers on it at its depth within 0.02, a receiver 0.05 behind it in
// umbra, one 0.05 in front lit (soft_test, TableBiasHoldsForSingleDepths) — the technique
// refuses the kernel (RenderSettings::validate): four moments hold up to W = 144, six up to 120
// (measured for every W); the limits keep a margin. With the fixed α of 27² kernels, six moments
// failed from W = 94 (flat planes read shadowed, umbrae lit: rings, black planes) and four from
// W = 37 (umbrae read lit at some depths).
#ifndef MSM_SOFT_H
#define MSM_SOFT_H
#include "msm/baselines.h"
#include "msm/bias.h"
#include "msm/blocker.h"
#include "msm/config.h"
#include "msm/cssm.h"
#include "msm/hamburger4.h"
#include "msm/hamburger6.h"
#include "msm/moments.h"
#include "msm/quantize.h"
#include "msm/sat.h"
#include "msm/shared.h"

MSM_BEGIN

// The widest kernel of the moment soft shadows (see "The widest kernel per technique" above).
const int MSM_SOFT_MAX_KERNEL_WIDTH4 = 127; // mssm4
const int MSM_SOFT_MAX_KERNEL_WIDTH6 = 111; // mssm6

// JCGT §4.5: a blocker search whose shadow intensity exceeds 1 - ε_u means the whole search
// region occludes the fragment (umbra): it returns full shadow without filtering. To match, the
// filtered intensities are over-darkened by 1 / (1 - ε_u) ("division of the shadow intensity by
// 99% or less"), so that the filtered result reaches 1 where the early-out would start.
const float MSM_SOFT_UMBRA_EPSILON = 0.01f;

// Texels of lateral reach per unit of depth difference, per axis (see the top of the file).
// tan_half_extent: tan(θ/2) of a disc light (both components), or of each half angle of a
// rectangular light along the map's x and y; world_per_depth: world units per unit of depth
// (frustum depth range / 2 for [-1,1] depth, / 1 for [0,1]); world_per_texel: frustum width and
// height over the resolution.
MSM_FN vec2 msm_soft_spread(vec2 tan_half_extent, float world_per_depth, vec2 world_per_texel) {
  return tan_half_extent * world_per_depth / world_per_texel;
}

// A spot light's spread (see "Geometry: spot lights" above) at the map coordinate t (texels, texel
// i covers [i, i + 1)) of an N × N map over the tangents [-tan_outer, tan_outer]²: texels of
// reach per unit of msm_soft_reach, per axis.
MSM_FN vec2 msm_spot_soft_spread(float radius, float range, float tan_outer, float size, vec2 t) {
  float texel = 2.0f * tan_outer / size;
  vec2 xy = (t * (2.0f / size) - 1.0f) * tan_outer;
  vec2 sq = xy * xy;
  float radial = 1.0f + sq.x + sq.y;
  vec2 stretch = vec2(sqrt((1.0f + sq.x) * radial), sqrt((1.0f + sq.y) * radial));
  return stretch * (radius / (2.0f * texel * range));
}
// The [-1,1] depth of the nearest blocker a spot light's search has to reach: its sphere's surface
// (at least the map's near plane, 1e-3 range, so that a point light's is finite).
MSM_FN float msm_spot_soft_near_depth(float radius, float range) { return 2.0f * max(radius / range, 1e-3f) - 1.0f; }
// The depth difference that the spread multiplies, from a receiver at [-1,1] depth zf to a blocker
// at zb: zf - zb in an orthographic map; in a spot light's perspective map of radial depth
// (perspective), 2 (1/u_b - 1/u_f) with u = (z + 1) / 2, u_b at least the spot's near depth.
MSM_FN float msm_soft_reach(float zf, float zb, float near_depth, bool perspective) {
  if (!perspective) return zf - zb;
  float uf = max(0.5f * (zf + 1.0f), 1e-6f);
  float ub = max(0.5f * (max(zb, near_depth) + 1.0f), 1e-6f);
  return 2.0f * (1.0f / ub - 1.0f / uf);
}

// spread · depth_distance, clamped to [0.5, (W - 1) / 2] texels with W = max_kernel_width >= 2
// (the queries then touch at most W texels per axis: n_t = W²). Negative distances (a blocker
// depth behind the receiver: not a blocker) give the minimum.
MSM_FN float msm_soft_largest_half_width(int max_kernel_width) { return max(0.5f * float(max_kernel_width - 1), 0.5f); }
MSM_FN vec2 msm_soft_unclamped_half_width(vec2 spread, float depth_distance) {
  return spread * max(depth_distance, 0.0f);
}
MSM_FN vec2 msm_soft_kernel_half_width(vec2 spread, float depth_distance, int max_kernel_width) {
  float largest = msm_soft_largest_half_width(max_kernel_width);
  vec2 h = msm_soft_unclamped_half_width(spread, depth_distance);
  return vec2(min(max(h.x, 0.5f), largest), min(max(h.y, 0.5f), largest));
}

// Whether msm_soft_kernel_half_width cut the region down to the kernel along some axis: the light's
// penumbra (or blocker search region) is then wider than the kernel, and a penumbra there is too
// sharp (a wide area light's penumbra reaches its full width only up to the kernel's).
MSM_FN bool msm_soft_kernel_clamped(vec2 spread, float depth_distance, int max_kernel_width) {
  vec2 h = msm_soft_unclamped_half_width(spread, depth_distance);
  return max(h.x, h.y) > msm_soft_largest_half_width(max_kernel_width);
}

// Blocker search half-width: blockers between the near plane (near_depth; -1 for [-1,1] depth of
// an orthographic map, msm_spot_soft_near_depth for a spot light's) and the fragment depth zf.
MSM_FN vec2 msm_soft_search_half_width(vec2 spread, float zf, float near_depth, bool perspective,
                                       int max_kernel_width) {
  return msm_soft_kernel_half_width(spread, msm_soft_reach(zf, near_depth, near_depth, perspective), max_kernel_width);
}

// Penumbra (filter) half-width for blockers at the average blocker depth.
MSM_FN vec2 msm_soft_penumbra_half_width(vec2 spread, float zf, float blocker_depth, float near_depth, bool perspective,
                                         int max_kernel_width) {
  return msm_soft_kernel_half_width(spread, msm_soft_reach(zf, blocker_depth, near_depth, perspective),
                                    max_kernel_width);
}

// Whether the penumbra region was clamped to the kernel (the renderer counts these lookups and warns
// above a share: RenderResult::soft_kernel_clamps). The blocker search is not counted: it is clamped
// by design (JCGT's fixed 27² search region) for most receivers of any scene.
MSM_FN bool msm_soft_penumbra_clamped(vec2 spread, float zf, float blocker_depth, float near_depth, bool perspective,
                                      int max_kernel_width) {
  return msm_soft_kernel_clamped(spread, msm_soft_reach(zf, blocker_depth, near_depth, perspective), max_kernel_width);
}

// A region [center - h, center + h] in texel units (texel i covers [i, i + 1); a shadow-map
// coordinate uv in [0,1]² is at uv · size), clamped to the map [0, size]: near the edges only the
// part inside is averaged. The center is clamped into the map first, so with h >= 0.5 the region
// keeps a width of at least 0.5 and lo < hi (sat.h's precondition).
struct SoftRegion {
  vec2 lo;
  vec2 hi;
};
MSM_FN SoftRegion msm_soft_region(vec2 center, vec2 half_width, ivec2 size) {
  vec2 extent = vec2(size);
  vec2 c = clamp(center, vec2(0.0f), extent);
  return SoftRegion(max(c - half_width, vec2(0.0f)), min(c + half_width, extent));
}

// The grid-aligned blocker search rectangle (JCGT §4.5): one 4-lookup query (sat.h).
MSM_FN SatRect msm_soft_search_rect(vec2 center, vec2 half_width, ivec2 size) {
  SoftRegion r = msm_soft_region(center, half_width, size);
  return msm_sat_grid_rect(r.lo, r.hi, size);
}

// ---- Moments from the tables ----
// Averages from sat.h are Θ4* (Θ6*) moments in [0,1]; Θ is affine, so the inverse of the average
// is the average of the moments. Biasing (bias.h): four moments with MSM_REP_SAT_INT32 (JCGT §4.2:
// α = 6e-7 at ~22.4 bits, towards the b* measured after Θ4*, (0, 0.628, 0, 0.628), as the
// tables round Θ4* moments: JCGT §2.5, App. D.4). Six moments: no paper gives α for integer
// tables. The tables round each Θ6* moment to a step of 1 / s (s = msm_sat_scale(W²)), as 16-bit
// storage rounds it to 1 / 65535, so α scales with the step: α = α_16 · 65535 / s (α_16 = 8e-5,
// MSM_ALPHA6_16BIT), or float's own 5e-6 (MSM_ALPHA6_FLOAT) where that is larger: the table's
// step is finer than float's rounding up to W = 64 (27²: 8.9e-7 < 5e-6; 4 moments, the same rule
// predicts 6e-5 · 2^-6.4 = 7.1e-7, JCGT's 6e-7). Above W = 64 the float α alone is below the
// quantization of a region of one depth, whose Hankel matrix is then not positive definite (a flat
// receiver at some depths reads up to 0.85 shadow at W = 255). Four moments likewise: JCGT's α at
// 28² (s = msm_sat_scale(784)) scaled by the step, α = 6e-7 · s_784 / s, the same up to W = 28.
// Both hold up to the widths above (MSM_SOFT_MAX_KERNEL_WIDTH4/6).
// scale: the table's msm_sat_scale.
MSM_FN float msm_soft_alpha6(uint scale) {
  return max(MSM_ALPHA6_FLOAT, MSM_ALPHA6_16BIT * (65535.0f / float(max(scale, 1u))));
}
MSM_FN float msm_soft_alpha4(uint scale) {
  return MSM_ALPHA_SAT_INT32 * max(float(msm_sat_scale(28 * 28)) / float(max(scale, 1u)), 1.0f);
}
MSM_FN vec4 msm_soft_moments4(vec4 q, uint scale) {
  MomentBias4 bias = msm_moment_bias(MSM_REP_SAT_INT32);
  bias.alpha = msm_soft_alpha4(scale);
  return msm_apply_bias(msm_theta4_star_inverse(q), bias);
}
MSM_FN Moments6 msm_soft_moments6(Moments6 q, uint scale) {
  MomentBias6 bias = msm_moment_bias6(MSM_REP6_FLOAT);
  bias.alpha = msm_soft_alpha6(scale);
  return msm_apply_bias6(msm_theta6_star_inverse(q), bias);
}

// ---- Average blocker depth (blocker.h: JCGT Eq. (4), Kneiphof Eq. (19)) ----
// q: the search region's average Θ4* / Θ6* moments; zf: the UNBIASED fragment depth ([-1,1]);
// scale (six moments): the tables' msm_sat_scale.
MSM_FN BlockerResult msm_soft_blocker4(vec4 q, float zf, uint scale) {
  return msm_blocker4(msm_soft_moments4(q, scale), zf, MSM_BLOCKER_EPSILON);
}
MSM_FN BlockerResult msm_soft_blocker6(Moments6 q, float zf, uint scale) {
  return msm_blocker6(msm_soft_moments6(q, scale), zf, MSM_BLOCKER_EPSILON);
}
// Kneiphof Eq. (19) with the mass at zf clamped to [delta1, delta2] (0 < delta1 <= delta2):
// between Eq. (4) with ε = delta1 and Eq. (4) with ε = delta2 on the same reconstruction, so never
// farther from the receiver than Eq. (4) with ε = delta1 (harder shadows when in doubt).
MSM_FN BlockerResult msm_soft_blocker6_upper(Moments6 q, float zf, float delta1, float delta2, uint scale) {
  return msm_blocker6_upper(msm_soft_moments6(q, scale), zf, delta1, delta2);
}
MSM_FN BlockerResult msm_soft_blocker4_upper(vec4 q, float zf, float delta1, float delta2, uint scale) {
  return msm_blocker4_upper(msm_soft_moments4(q, scale), zf, delta1, delta2);
}

// The estimator chosen by the technique's parameters (techniques.h: x = δ1, y = δ2, z = 1 for
// Kneiphof Eq. (19), 0 for JCGT Eq. (4) with ε = δ1). An if, not ?: (WebGL allows no ?: on structs).
MSM_FN BlockerResult msm_soft_blocker4_select(vec4 q, float zf, vec4 params, uint scale) {
  if (params.z > 0.5f) return msm_soft_blocker4_upper(q, zf, params.x, params.y, scale);
  return msm_blocker4(msm_soft_moments4(q, scale), zf, params.x);
}
MSM_FN BlockerResult msm_soft_blocker6_select(Moments6 q, float zf, vec4 params, uint scale) {
  if (params.z > 0.5f) return msm_soft_blocker6_upper(q, zf, params.x, params.y, scale);
  return msm_blocker6(msm_soft_moments6(q, scale), zf, params.x);
}

// ---- Naive variance soft shadow mapping (Yang et al. 2010, the baseline of JCGT §4) ----
// Two moments (z, z²) of [0,1] depth in the same integer table. Blocker search: Chebyshev's
// one-sided bound σ² / (σ² + (zf - μ)²) is taken as the lit fraction N of the search region, whose
// texels are assumed at zf; the rest, the blockers, then average (μ - N zf) / (1 - N). With
// zf <= μ the bound says nothing and the fragment is taken as unoccluded. Returns the depth in
// [-1,1] (as the moment estimators, for msm_soft_penumbra_half_width) and 1 - N as the shadow.
// q: the region's average (z, z²); unit_zf: the unbiased fragment depth in [0,1].
MSM_FN BlockerResult msm_soft_vssm_blocker(vec2 q, float unit_zf, float min_variance) {
  // 1 - N is the VSM shadow intensity (baselines.h): 0 where zf <= μ.
  float blocked = msm_vsm_shadow(q, unit_zf, min_variance);
  if (blocked <= 0.0f) return BlockerResult(msm_signed_depth(unit_zf), 0.0f);
  float blocker = clamp((q.x - (1.0f - blocked) * unit_zf) / blocked, 0.0f, unit_zf);
  return BlockerResult(msm_signed_depth(blocker), blocked);
}
// Chebyshev over the filter region, over-darkened like the moment techniques; zf_biased in [-1,1].
MSM_FN float msm_soft_vssm_shadow(vec2 q, float zf_biased, float min_variance, float umbra_epsilon) {
  return msm_overdarken(msm_vsm_shadow(q, msm_unit_depth(zf_biased), min_variance), 1.0f - umbra_epsilon);
}

// ---- Percentage-closer soft shadows [Fernando 2005], the depth-map baseline ----
// The same geometry, with the depth map itself: the blocker search averages the depths of every
// texel (sample) of the grid-aligned search rectangle that lies in front of the receiver plane;
// the filter averages the depth tests over the penumbra region, each texel weighted by its
// overlap with the region (the box filter MSSM applies to moments, applied to test results).
// Overlap of texel i ([i, i + 1)) with [lo, hi] along one axis.
MSM_FN float msm_soft_texel_overlap(int i, float lo, float hi) {
  return max(min(hi, float(i + 1)) - max(lo, float(i)), 0.0f);
}
// Average blocker depth from the sums over the search region: depth_sum and count of the
// samples in front of the receiver, total samples. No blocker: the fragment depth, shadow 0.
MSM_FN BlockerResult msm_soft_pcss_blocker(float depth_sum, float blockers, float samples, float zf) {
  if (blockers <= 0.0f) return BlockerResult(zf, 0.0f);
  return BlockerResult(depth_sum / blockers, blockers / samples);
}

// Umbra early-out (JCGT §4.5): the search region's shadow intensity above 1 - ε_u.
MSM_FN bool msm_soft_in_umbra(BlockerResult blocker, float umbra_epsilon) {
  return blocker.shadow > 1.0f - umbra_epsilon;
}

// ---- Depth bias growing with the filter size (JCGT §4.4, Fig. 11) ----
// A planar receiver whose depth changes by g.x, g.y per texel along the map's axes covers depths
// zf ± (|g.x| h.x + |g.y| h.y) over a filter of half-widths h: up to half the filter region lies
// in front of zf (closer to the light) and would shadow the receiver itself. The texels that the
// region touches hold their own averages, whose centres lie up to h + 1/2 texel from the fragment.
// Testing at
//     zf - bias,   bias = constant_bias + |g.x| (h.x + 1/2) + |g.y| (h.y + 1/2)
// (the fragment moved towards the light, as every depth bias in msm; the constant covers rounding
// and the moment bias) avoids it: no texel of the receiver's own plane is below zf - bias.
// JCGT's choice, proportional to the filter size and not adaptive, is a fixed g = the steepest
// slope to tolerate (tan(angle of incidence) · w_t / w_d per texel; 80° needs 5.67 w_t / w_d);
// passing the receiver plane's own gradient makes it adaptive (Dou et al. 2014). The blocker
// search keeps the unbiased depth (blocker.h). The moment techniques now take the smaller
// msm_soft_plane_bias below; CSSM (cssm.h's series is not a bound) keeps this one.
MSM_FN float msm_soft_depth_bias(vec2 half_width, vec2 depth_per_texel, float constant_bias) {
  return constant_bias + abs(depth_per_texel.x) * (half_width.x + 0.5f) +
         abs(depth_per_texel.y) * (half_width.y + 0.5f);
}

// ---- The least depth bias for a planar receiver, as modelled (the moment techniques) ----
// msm_soft_depth_bias moves zf in front of the nearest texel of the receiver's own plane. A
// moment technique needs less: the sharp lower bound of the shadow from 2n moments (Hamburger:
// depths on the whole real line) is zero exactly while zf lies at or below the smallest node of
// the n-point Gauss rule of the distribution's first 2n - 1 moments (the localizing matrix of
// bias.h's receiver-plane bias is then positive semidefinite; the 2n-th moment is matched by mass
// arbitrarily far behind zf). This is bias.h's argument for the filtered hard shadows, with the
// filter region's exact distribution in place of a kernel's σ (JCGT §4.4 asks for an adaptive
// bias, after Dou et al. 2014). Over a filter region of half-widths h the plane's depths are
// zf + X, X = U(g.x h.x) + U(g.x / 2) + U(g.y h.y) + U(g.y / 2) (the region's offsets plus the
// samples' offsets inside their texel; U(a) uniform on [-a, a]), symmetric about zf, so that node
// is -x with
//   two moments (Chebyshev, the 1-point rule: the mean):   x = 0,
//   four moments (the 2-point rule ±sqrt(m2)):             x² = m2,
//   six moments (the 3-point rule 0, ±sqrt(m4 / m2)):       x² = m4 / m2,
// m_k the central moments of X: m2 = Σ a²/3, m4 = Σ a⁴/5 + 6 Σ_{i<j} a_i² a_j² / 9, i.e. from the
// cumulants a²/3 and -2a⁴/15 of each uniform, which add: m4 = κ4 + 3 κ2² (κ4 < 0, so six
// moments need at most bias.h's Gaussian limit √3 σ, and four exactly its σ). For one uniform that
// is 0.577 (four) and 0.775 (six) of its half-range a; against msm_soft_depth_bias's worst case
// g.x (h.x + ½) + g.y (h.y + ½), for half-widths of 0.5 to 13 texels, 0.29-0.39 (four) and
// 0.47-0.61 (six) with equal slopes along both axes of a square region, 0.41-0.56 and 0.63-0.75
// with the slope along one axis (soft_test checks the bound at this node and below it). The model
// averages over where the fragment lies in its texel; msm_soft_plane_mean_shift adds the largest
// shift of the region's mean that this hides. The constant bias still covers the moment bias and
// rounding.
// It is the least bias of that model, not of a table's region: there the offsets are quantized to
// the texels' samples and a box with fractional borders weights its border texels unevenly (skew),
// which the model omits. Against the least bias of the region's exact distribution (its texels'
// four samples, weighted by coverage; the same Gauss node in double) msm_soft_plane_bias is within
// 1% for half-widths of 8 texels and more, within 5% from 4, 0.89-1.10 of it from 2, but for
// regions of 0.5-2 texels anywhere from 0.66 to 2.4 of it: too small by up to a third. The constant
// bias (1e-3 in the renderer) and the moment bias cover most of that gap: the shading's shadow of
// its own plane reaches 1.0e-3 (four moments; six 1.4e-6) there, up to the slope clamp, and 0 from
// 2 texels on (soft_test, PlaneBiasAgainstTheTablesExactLeastBias).
// msm_soft_plane_spread_bias: that node, x.
MSM_FN float msm_soft_plane_spread_bias(vec2 half_width, vec2 depth_per_texel, int moments) {
  vec2 g = abs(depth_per_texel);
  vec4 a = vec4(g.x * half_width.x, 0.5f * g.x, g.y * half_width.y, 0.5f * g.y);
  float range = a.x + a.y + a.z + a.w;
  if (moments < 4 || !(range > 0.0f)) return 0.0f;
  a /= range; // scale-free: the moments below stay near 1 whatever the slope
  vec4 a2 = a * a;
  float k2 = (a2.x + a2.y + a2.z + a2.w) / 3.0f;
  if (moments < 6) return range * sqrt(k2);
  float m4 = -2.0f / 15.0f * dot(a2, a2) + 3.0f * k2 * k2;
  return range * sqrt(m4 / k2);
}
// The texels' centres quantize the region's offsets, which moves its mean off zf by up to 1/(16 h)
// texel per axis (the sawtooth floor(x) + ½ - x integrates to at most 1/8 over any window, here of
// width 2h; 1/12 at h = 3/4).
MSM_FN float msm_soft_plane_mean_shift(vec2 half_width, vec2 depth_per_texel) {
  vec2 g = abs(depth_per_texel);
  return g.x / (16.0f * max(half_width.x, 0.5f)) + g.y / (16.0f * max(half_width.y, 0.5f));
}
// The bias the shading takes (with the constant one): the node plus the mean's shift.
MSM_FN float msm_soft_plane_bias(vec2 half_width, vec2 depth_per_texel, int moments) {
  return msm_soft_plane_mean_shift(half_width, depth_per_texel) +
         msm_soft_plane_spread_bias(half_width, depth_per_texel, moments);
}

// ---- Shadow intensity from the filtered moments ----
// q: the filter region's average Θ4* (Θ6*) moments (msm_sat_filter_average); zf_biased: the
// fragment depth minus the constant bias and msm_soft_plane_bias. Hamburger lower bound (JCGT App.
// D.4), over-darkened by 1 / (1 - ε_u) to match the umbra early-out.
MSM_FN float msm_soft_shadow4(vec4 q, float zf_biased, float umbra_epsilon, uint scale) {
  return msm_overdarken(msm_hamburger4_lower(msm_soft_moments4(q, scale), zf_biased), 1.0f - umbra_epsilon);
}
MSM_FN float msm_soft_shadow6(Moments6 q, float zf_biased, float umbra_epsilon, uint scale) {
  return msm_overdarken(msm_hamburger6_lower(msm_soft_moments6(q, scale), zf_biased), 1.0f - umbra_epsilon);
}

MSM_END

#endif // MSM_SOFT_H

// ---- The per-pixel flow, composed once over the caller's table fetch ----
// The steps above in their order, for the renderer's shader, the CPU and the device tests alike:
// msm_soft_moment_flow (mssm4, mssm6, vssm) and msm_soft_cssm_flow (cssm8, cssm16). They read the
// summed-area tables through the caller's fetch, uvec4 fetch(int x, int y, int table): S(x, y) of
// table `table` (moments: 0, and 1 for the second table of six moments; CSSM: the tile), 0 where x
// or y is -1 (CSSM: row -1 of tile t > 0 is the last row of tile t - 1, as the stacked table holds
// it, which the rectangle sums subtract as they should). C++ passes the fetch first, a callable;
// GLSL has no function parameters of function type, so the including shader defines the fetch
// and names it with MSM_SOFT_FETCH before including this header (GLSL without MSM_SOFT_FETCH gets
// the steps only). Outside the include guard: a shader may include soft.h earlier for the steps.
// Further functions over the fetch (a test's) are written with the same four macros.
#if (MSM_CPP || defined(MSM_SOFT_FETCH)) && !defined(MSM_SOFT_FLOW)
#define MSM_SOFT_FLOW
#if MSM_CPP
// clang-format off
#define MSM_SOFT_FLOW_FN template <class SoftFetch> inline
// clang-format on
#define MSM_SOFT_FETCH_PARAM SoftFetch fetch,
#define MSM_SOFT_FETCH_ARG fetch,
#define MSM_SOFT_TABLE(x, y, table) fetch(x, y, table)
#else
#define MSM_SOFT_FLOW_FN
#define MSM_SOFT_FETCH_PARAM
#define MSM_SOFT_FETCH_ARG
#define MSM_SOFT_TABLE(x, y, table) MSM_SOFT_FETCH(x, y, table)
#endif

MSM_BEGIN

// What the flow needs of the frame and the light.
struct SoftSetup {
  ivec2 size;          // the shadow map's size in texels (one tile of a CSSM table)
  int kernel_width;    // W: the tables were built for kernels of at most W × W texels
  uint scale;          // msm_sat_scale(W * W)
  vec2 spread;         // msm_soft_spread of the light (a spot light's: msm_spot_soft_spread)
  float near_depth;    // the nearest blocker's [-1,1] depth: -1, a spot's msm_spot_soft_near_depth
  bool perspective;    // a spot light's perspective map of radial depth (msm_soft_reach)
  float constant_bias; // [-1,1] depth, beside the receiver plane's bias
  float umbra_epsilon; // ε_u (MSM_SOFT_UMBRA_EPSILON by default)
  vec4 params;         // the technique's parameters (techniques.h)
};
// The fragment as the shadow map sees it.
struct SoftFragment {
  vec2 position;        // in texels: texel i covers [i, i + 1)
  float depth;          // unbiased, [0,1]
  vec2 depth_per_texel; // the receiver plane's slope in [-1,1] depth per texel along x and y
};
// The flow's result and the intermediate values the tests compare.
struct SoftShadow {
  float shadow;          // the shadow intensity
  float blocker_depth;   // the average blocker depth, [-1,1]
  float search_shadow;   // the blocker search region's shadow intensity
  vec2 penumbra;         // the filter's half-widths in texels; 0 where the search ended the flow
  bool penumbra_clamped; // the penumbra was wider than the kernel (msm_soft_penumbra_clamped)
};

// The sum over a grid rectangle (4 lookups, sat.h).
MSM_SOFT_FLOW_FN uvec4 msm_soft_rect_sum(MSM_SOFT_FETCH_PARAM SatRect r, int table) {
  return msm_sat_rect_sum(MSM_SOFT_TABLE(r.hi.x, r.hi.y, table), MSM_SOFT_TABLE(r.lo.x - 1, r.hi.y, table),
                          MSM_SOFT_TABLE(r.hi.x, r.lo.y - 1, table), MSM_SOFT_TABLE(r.lo.x - 1, r.lo.y - 1, table));
}
// The nine-region box filter's average (16 lookups, sat.h).
MSM_SOFT_FLOW_FN vec4 msm_soft_filter_average(MSM_SOFT_FETCH_PARAM SatFilter box, uint scale, int table) {
  SatSamples16 t;
  for (int j = 0; j < 4; ++j)
    for (int i = 0; i < 4; ++i) t.s[4 * j + i] = MSM_SOFT_TABLE(box.x[i], box.y[j], table);
  return msm_sat_filter_average(t, box, scale);
}

// Moment soft shadows with `moments` = 4 (mssm4: Θ4*, one table), 6 (mssm6: Θ6*, two tables) or 2
// (vssm: (z, z²), one table): blocker search over the grid-aligned region, the technique's blocker
// estimator, umbra early-out, penumbra, nine-region filter, the receiver plane's bias, the bound.
MSM_SOFT_FLOW_FN SoftShadow msm_soft_moment_flow(MSM_SOFT_FETCH_PARAM SoftSetup k, SoftFragment f, int moments) {
  float zf = msm_signed_depth(f.depth);
  vec2 hs = msm_soft_search_half_width(k.spread, zf, k.near_depth, k.perspective, k.kernel_width);
  SatRect r = msm_soft_search_rect(f.position, hs, k.size);
  int texels = msm_sat_rect_texels(r);
  vec4 q = msm_sat_rect_average(msm_soft_rect_sum(MSM_SOFT_FETCH_ARG r, 0), texels, k.scale);
  BlockerResult blocker;
  if (moments == 6) {
    vec4 q1 = msm_sat_rect_average(msm_soft_rect_sum(MSM_SOFT_FETCH_ARG r, 1), texels, k.scale);
    blocker = msm_soft_blocker6_select(msm_sat_join6(q, q1), zf, k.params, k.scale);
  } else if (moments == 2) {
    blocker = msm_soft_vssm_blocker(vec2(q.x, q.y), f.depth, k.params.w);
  } else {
    blocker = msm_soft_blocker4_select(q, zf, k.params, k.scale);
  }
  if (msm_soft_in_umbra(blocker, k.umbra_epsilon))
    return SoftShadow(1.0f, blocker.depth, blocker.shadow, vec2(0.0f), false);

  vec2 hp = msm_soft_penumbra_half_width(k.spread, zf, blocker.depth, k.near_depth, k.perspective, k.kernel_width);
  SoftRegion region = msm_soft_region(f.position, hp, k.size);
  SatFilter box = msm_sat_filter(region.lo, region.hi);
  float zb = zf - k.constant_bias - msm_soft_plane_bias(hp, f.depth_per_texel, moments);
  vec4 t = msm_soft_filter_average(MSM_SOFT_FETCH_ARG box, k.scale, 0);
  float shadow;
  if (moments == 6) {
    vec4 t1 = msm_soft_filter_average(MSM_SOFT_FETCH_ARG box, k.scale, 1);
    shadow = msm_soft_shadow6(msm_sat_join6(t, t1), zb, k.umbra_epsilon, k.scale);
  } else if (moments == 2) {
    shadow = msm_soft_vssm_shadow(vec2(t.x, t.y), zb, k.params.w, k.umbra_epsilon);
  } else {
    shadow = msm_soft_shadow4(t, zb, k.umbra_epsilon, k.scale);
  }
  return SoftShadow(
      shadow, blocker.depth, blocker.shadow, hp,
      msm_soft_penumbra_clamped(k.spread, zf, blocker.depth, k.near_depth, k.perspective, k.kernel_width));
}

// Convolution soft shadows (cssm.h): the blocker search sums every tile over the search region (4
// lookups per tile), the filter the basis tiles over the penumbra (16 per tile). The receiver's own
// surface lies at zf: the bias its plane needs over the search region keeps it out of the search,
// as the bias over the filter region keeps it out of the penumbra (cssm.h's series is not a bound,
// so the worst-case msm_soft_depth_bias). No blocker ends the flow lit.
MSM_SOFT_FLOW_FN SoftShadow msm_soft_cssm_flow(MSM_SOFT_FETCH_PARAM SoftSetup k, SoftFragment f, CsmParams p) {
  int tiles = msm_cssm_tiles(p.terms), basis = msm_cssm_basis_tiles(p.terms);
  float zf = msm_signed_depth(f.depth);
  vec2 hs = msm_soft_search_half_width(k.spread, zf, k.near_depth, k.perspective, k.kernel_width);
  SatRect r = msm_soft_search_rect(f.position, hs, k.size);
  int texels = msm_sat_rect_texels(r);
  float zs = zf - msm_soft_depth_bias(hs, f.depth_per_texel, k.constant_bias);
  float xs = msm_csm_ranged_receiver(0.5f * (zs + 1.0f), p);
  vec2 sums = vec2(0.0f);
  for (int tile = 0; tile < tiles; ++tile)
    sums += msm_cssm_search_terms(msm_sat_rect_average(msm_soft_rect_sum(MSM_SOFT_FETCH_ARG r, tile), texels, k.scale),
                                  tile, xs, p);
  BlockerResult blocker = msm_cssm_blocker(sums, 0.5f * (zs + 1.0f), p, k.params.w);
  float blocker_depth = msm_signed_depth(blocker.depth);
  if (!(blocker.shadow > 0.0f)) return SoftShadow(0.0f, blocker_depth, blocker.shadow, vec2(0.0f), false);

  vec2 hp = msm_soft_penumbra_half_width(k.spread, zf, blocker_depth, k.near_depth, k.perspective, k.kernel_width);
  SoftRegion region = msm_soft_region(f.position, hp, k.size);
  SatFilter box = msm_sat_filter(region.lo, region.hi);
  float zb = zf - msm_soft_depth_bias(hp, f.depth_per_texel, k.constant_bias);
  float xf = msm_csm_ranged_receiver(0.5f * (zb + 1.0f), p);
  float series = 0.0f;
  for (int tile = 0; tile < basis; ++tile)
    series += msm_csm_texel_terms(msm_csm_from_unorm(msm_soft_filter_average(MSM_SOFT_FETCH_ARG box, k.scale, tile)),
                                  xf, tile, p);
  return SoftShadow(
      msm_csm_resolve(series, p), blocker_depth, blocker.shadow, hp,
      msm_soft_penumbra_clamped(k.spread, zf, blocker_depth, k.near_depth, k.perspective, k.kernel_width));
}

MSM_END

#endif // MSM_SOFT_FLOW
