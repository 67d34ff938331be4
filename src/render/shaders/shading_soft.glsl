// Soft shadows from integer summed-area tables (JCGT §4): blocker search with one query over a
// grid-aligned region, average blocker depth, penumbra of the directional area light, umbra
// early-out, nine-region filter (16 lookups per table), depth bias for the receiver's plane; the
// per-pixel math is include/msm/soft.h (its recipe at the end), shared with the CPU. Three
// techniques, one specialization each: mssm4 (Θ4*, one table), mssm6 (Θ6*, two tables, Kneiphof
// §4.2) and vssm (two moments, naive variance soft shadows: the baseline), and the convolution soft
// shadows cssm8 / cssm16 (cssm.h: CSM tiles stacked in one table).
#include "msm/cssm.h"
#include "msm/soft.h"
layout(binding = 2) uniform usampler2DArray sat_table;
layout(binding = 3) uniform usampler2DArray sat_table1; // six moments: b4, b6; else the first again
#include "shading.glsl"
#include "soft_clamps.glsl"

uvec4 table(int x, int y) { return x < 0 || y < 0 ? uvec4(0u) : texelFetch(sat_table, ivec3(x, y, shadow_layer), 0); }
uvec4 table1(int x, int y) { return x < 0 || y < 0 ? uvec4(0u) : texelFetch(sat_table1, ivec3(x, y, shadow_layer), 0); }

SatValues6 rect_sum6(SatRect r) {
  return SatValues6(msm_sat_rect_sum(table(r.hi.x, r.hi.y), table(r.lo.x - 1, r.hi.y), table(r.hi.x, r.lo.y - 1),
                                     table(r.lo.x - 1, r.lo.y - 1)),
                    msm_sat_rect_sum(table1(r.hi.x, r.hi.y), table1(r.lo.x - 1, r.hi.y), table1(r.hi.x, r.lo.y - 1),
                                     table1(r.lo.x - 1, r.lo.y - 1)));
}

// CSSM (cssm.h): tile `tile` of the table lies `tile` shadow-map heights further along y; its
// row -1 is the previous tile's last row, which the rectangle sums subtract as they should.
uvec4 table_tile(int x, int y, int tile) {
  int row = y + tile * int(frame.shadow_map.x);
  return x < 0 || row < 0 ? uvec4(0u) : texelFetch(sat_table, ivec3(x, row, shadow_layer), 0);
}

// Convolution soft shadows: the blocker search sums every tile over the search region (4 lookups
// per tile), the filter the basis tiles over the penumbra (16 per tile).
float cssm_intensity(ShadowLookup s, ivec2 map, int width, uint scale, vec2 spread) {
  CsmParams p = msm_cssm_params(msm_technique_cssm_frequencies(kTechnique), frame.technique_params);
  int tiles = msm_cssm_tiles(p.terms), basis = msm_cssm_basis_tiles(p.terms);
  float zf = msm_signed_depth(s.z);
  vec2 position = s.t + 0.5f;
  vec2 hs = msm_soft_search_half_width(spread, zf, -1.0f, width);
  SatRect r = msm_soft_search_rect(position, hs, map);
  int texels = msm_sat_rect_texels(r);
  // The receiver's own surface lies at zf: it is kept out of the search by the bias its plane needs
  // over the search region (soft.h), as the filter below keeps it out of the penumbra.
  float zs = zf - msm_soft_depth_bias(hs, 2.0f * s.depth_per_texel, frame.soft.z);
  float xs = msm_csm_ranged_receiver(0.5f * (zs + 1.0f), p);
  vec2 sums = vec2(0.0f);
  for (int tile = 0; tile < tiles; ++tile) {
    uvec4 sum = msm_sat_rect_sum(table_tile(r.hi.x, r.hi.y, tile), table_tile(r.lo.x - 1, r.hi.y, tile),
                                 table_tile(r.hi.x, r.lo.y - 1, tile), table_tile(r.lo.x - 1, r.lo.y - 1, tile));
    sums += msm_cssm_search_terms(msm_sat_rect_average(sum, texels, scale), tile, xs, p);
  }
  BlockerResult blocker = msm_cssm_blocker(sums, 0.5f * (zs + 1.0f), p, frame.technique_params.w);
  count_soft_lookup(blocker.shadow > 0.0f &&
                    msm_soft_penumbra_clamped(spread, zf, msm_signed_depth(blocker.depth), width));
  if (!(blocker.shadow > 0.0f)) return 0.0f;

  vec2 hp = msm_soft_penumbra_half_width(spread, zf, msm_signed_depth(blocker.depth), width);
  SoftRegion region = msm_soft_region(position, hp, map);
  SatFilter f = msm_sat_filter(region.lo, region.hi);
  float zb = zf - msm_soft_depth_bias(hp, 2.0f * s.depth_per_texel, frame.soft.z);
  float xf = msm_csm_ranged_receiver(0.5f * (zb + 1.0f), p);
  float series = 0.0f;
  for (int tile = 0; tile < basis; ++tile) {
    SatSamples16 t;
    for (int j = 0; j < 4; ++j)
      for (int i = 0; i < 4; ++i) t.s[4 * j + i] = table_tile(f.x[i], f.y[j], tile);
    series += msm_csm_texel_terms(msm_csm_from_unorm(msm_sat_filter_average(t, f, scale)), xf, tile, p);
  }
  return msm_csm_resolve(series, p);
}

float shadow_intensity(ShadowLookup s) {
  ivec2 map = ivec2(int(frame.shadow_map.x));
  int width = frame.soft_kernel.x;
  uint scale = uint(frame.soft_kernel.y);
  vec2 spread = vec2(lights[shadow_layer].soft.x, lights[shadow_layer].soft.y);
  if (msm_technique_is_cssm(kTechnique)) return cssm_intensity(s, map, width, scale, spread);
  vec4 params = frame.technique_params;
  float zf = msm_signed_depth(s.z);
  vec2 position = s.t + 0.5f; // texel i covers [i, i + 1) in sat.h / soft.h
  bool six = kTechnique == MSM_TECH_MSSM6, vssm = kTechnique == MSM_TECH_VSSM;

  vec2 hs = msm_soft_search_half_width(spread, zf, -1.0f, width);
  SatRect r = msm_soft_search_rect(position, hs, map);
  int texels = msm_sat_rect_texels(r);
  BlockerResult blocker;
  if (six) {
    blocker = msm_soft_blocker6_select(msm_sat_rect_average6(rect_sum6(r), texels, scale), zf, params, scale);
  } else {
    vec4 q = msm_sat_rect_average(msm_sat_rect_sum(table(r.hi.x, r.hi.y), table(r.lo.x - 1, r.hi.y),
                                                   table(r.hi.x, r.lo.y - 1), table(r.lo.x - 1, r.lo.y - 1)),
                                  texels, scale);
    blocker =
        vssm ? msm_soft_vssm_blocker(vec2(q.x, q.y), s.z, params.w) : msm_soft_blocker4_select(q, zf, params, scale);
  }
  bool umbra = msm_soft_in_umbra(blocker, frame.soft.w);
  count_soft_lookup(!umbra && msm_soft_penumbra_clamped(spread, zf, blocker.depth, width));
  if (umbra) return 1.0f;

  vec2 hp = msm_soft_penumbra_half_width(spread, zf, blocker.depth, width);
  SoftRegion region = msm_soft_region(position, hp, map);
  SatFilter f = msm_sat_filter(region.lo, region.hi);
  SatSamples16 t, t1;
  for (int j = 0; j < 4; ++j)
    for (int i = 0; i < 4; ++i) {
      t.s[4 * j + i] = table(f.x[i], f.y[j]);
      if (six) t1.s[4 * j + i] = table1(f.x[i], f.y[j]);
    }
  // The receiver plane's slope in [-1,1] depth per texel: the least bias that keeps its own plane
  // out of the technique's bound (soft.h).
  float zb = zf - frame.soft.z - msm_soft_plane_bias(hp, 2.0f * s.depth_per_texel, six ? 6 : (vssm ? 2 : 4));
  vec4 q = msm_sat_filter_average(t, f, scale);
  if (six) return msm_soft_shadow6(msm_sat_join6(q, msm_sat_filter_average(t1, f, scale)), zb, frame.soft.w, scale);
  if (vssm) return msm_soft_vssm_shadow(vec2(q.x, q.y), zb, params.w, frame.soft.w);
  return msm_soft_shadow4(q, zb, frame.soft.w, scale);
}
