// Convolution soft shadow maps (Annen et al., "Real-Time, All-Frequency Shadows in Dynamic Scenes",
// 2008), the baseline of Kneiphof's comparison: a CSM (baselines.h, the Fourier basis of the
// shadow test, single source) whose basis images are prefiltered (here: the soft techniques'
// integer summed-area tables, sat.h), plus the basis multiplied by depth and the depth itself, so
// that the average blocker depth is a prefiltered quotient too:
//   f(z) = 1/2 + Σ_k term_k(sin c_k z, cos c_k z)   (CSM's S_M: the share of depths in front of zf)
//   z_avg = E[z f(z)] / E[f(z)] = (E[z] / 2 + Σ_k term_k(E[z sin c_k z], E[z cos c_k z])) / E[f(z)]
// over the blocker search region, both linear in the stored values (term_k is msm_csm_term, linear
// in its first argument). Then the penumbra of soft.h for blockers at z_avg and CSM's
// reconstruction over it. Depth convention [0,1] (CSM's).
//
// Storage: "CSSM m" (Kneiphof: m the values of the CSM, 2m + 1 in all) is a CSM of m / 2
// frequencies: m basis values, m depth-weighted ones and the depth, as RGBA tiles of the shadow
// map's size stacked along y in one image (one summed-area table; a rectangle inside a tile is
// summed exactly, the tiles above cancel): tiles [0, m/4) hold msm_csm_basis_texel, tiles
// [m/4, m/2) the same times z, tile m/2 (z, 0, 0, 0). Every value is mapped to [0,1]
// (msm_csm_to_unorm) for the table. cssm8: 5 tiles (17 values), cssm16: 9 tiles (33 values).
//
// The basis sees depth scaled by MSM_CSM_BASIS_RANGE (baselines.h, msm_csm_basis_depth; shared
// with the hard CSM technique): E[z f] and the depth tile keep z itself. On the unscaled basis a
// receiver on the fitted map's far plane behind a blocker on its near plane got no shadow at all
// (CSM's square wave falls back through 1/2 at a depth difference of 1); scaled by 3/4 the shadow
// of a blocker a whole depth range away is that of one a quarter range away on the unscaled basis
// (cssm8 0.90, cssm16 0.97), for a ramp near contact 4/3 as wide in depth.
#ifndef MSM_CSSM_H
#define MSM_CSSM_H
#include "msm/baselines.h"
#include "msm/blocker.h"

MSM_BEGIN

const int MSM_CSSM_MAX_TILES = 9;

// Frequencies (CsmParams::terms) of "CSSM m", and its tiles.
MSM_FN int msm_cssm_frequencies(int values) { return values / 2; }
MSM_FN int msm_cssm_tiles(int frequencies) { return frequencies + 1; }
MSM_FN int msm_cssm_basis_tiles(int frequencies) { return frequencies / 2; }

// Tile `tile` of one depth sample z in [0,1], in [0,1] for the table.
MSM_FN vec4 msm_cssm_generate(float z, int tile, int frequencies) {
  int half_tiles = msm_cssm_basis_tiles(frequencies);
  float u = msm_csm_basis_depth(z);
  if (tile < half_tiles) return msm_csm_to_unorm(msm_csm_basis_texel(u, tile));
  if (tile < 2 * half_tiles) return msm_csm_to_unorm(z * msm_csm_basis_texel(u, tile - half_tiles));
  return vec4(z, 0.0f, 0.0f, 0.0f);
}

// The contribution of averaged tile `tile` (as the table returns it, in [0,1]) to the sums of the
// blocker search: x the series E[f] (basis tiles), y the series E[z f] (depth-weighted tiles and
// the depth tile), both without their constant parts (msm_cssm_blocker adds them); xf the
// receiver as msm_csm_ranged_receiver gives it.
MSM_FN vec2 msm_cssm_search_terms(vec4 average, int tile, float xf, CsmParams p) {
  int half_tiles = msm_cssm_basis_tiles(p.terms);
  if (tile < half_tiles) return vec2(msm_csm_texel_terms(msm_csm_from_unorm(average), xf, tile, p), 0.0f);
  if (tile < 2 * half_tiles)
    return vec2(0.0f, msm_csm_texel_terms(msm_csm_from_unorm(average), xf, tile - half_tiles, p));
  return vec2(0.0f, 0.5f * average.x);
}

// Average blocker depth from the search sums (msm_cssm_search_terms summed over the tiles) and the
// receiver depth zf in [0,1]: E[z f] / E[f] with E[f] = 1/2 + sums.x, clamped to [0, zf]. `shadow`
// is the blockers' share E[f] rescaled like CSM's (msm_csm_resolve): below `min_share` the region
// holds no blocker (the receiver's own depth counts 1/2 in the series) and the fragment is lit.
// The default min_share: a region whose rescaled share stays below 1% holds no blocker, as the
// damped series' ringing around a lone receiver stays below it.
const float MSM_CSSM_MIN_BLOCKER_SHARE = 0.01f;
MSM_FN BlockerResult msm_cssm_blocker(vec2 sums, float zf, CsmParams p, float min_share) {
  float share = 0.5f + sums.x;
  float shadow = msm_csm_resolve(sums.x, p);
  if (!(shadow > min_share) || !(share > 0.0f)) return BlockerResult(zf, 0.0f);
  float depth = clamp(sums.y / share, 0.0f, zf);
  return BlockerResult(depth, shadow);
}

// The parameters of a CSSM technique from its vec4 (x damping, y scale, z offset; techniques.h).
MSM_FN CsmParams msm_cssm_params(int frequencies, vec4 params) {
  return CsmParams(frequencies, params.x, params.y, params.z);
}

MSM_END

#endif // MSM_CSSM_H
