// Integer summed-area tables of moment shadow maps (JCGT 2017 §4.2, §4.4): quantization of a
// texel's moments to 32-bit unsigned integers, rectangle queries that are exact despite
// wrap-around, and the nine-region query of a filter region with fractional borders (Figure 7b).
// Shared by GLSL and C++ (see shared.h). No textures here: the caller fetches the table values
// (the shaders of src/gpu build the tables; a fetch at a coordinate < 0 must read as 0) and
// passes them in.
//
// What a texel holds. Four moments in the 128-bit representation of JCGT §4.2 / App. D.4: the
// moments b = (z, z², z³, z⁴) of depth z in [-1,1], averaged over the texel's samples and mapped
// by Θ4* (quantize.h, msm_theta4_star) into [0,1]^4. Six moments: Θ6* of (z, ..., z⁶), also in
// [0,1]^6, split over two tables (msm_sat_split6 below).
//
// Quantization. With n_t the number of texels of the largest kernel that will ever be queried
// (search region or filter region), every moment q in [0,1] becomes the integer
//     Q = round(q · s),   s = floor((2^32 - 1) / n_t)     (msm_sat_scale),
// so that the sum of n_t texels is at most n_t · s <= 2^32 - 1. JCGT writes the scale as
// (2^32 - 1) / n_t and rounds the product; with that scale a texel at q = 1 (which Θ4* reaches:
// q4 = (b2 + b4) / 2 = 1 at z = ±1) may round up to ceil((2^32 - 1) / n_t), and n_t such texels
// then overflow by up to n_t - 1. The floor costs less than 2^-22 of precision. Precision kept:
// log2 s = log2((2^32 - 1) / n_t) bits, 22.4 bits for n_t = 28² = 784 (JCGT) and 22.5 for 27².
//
// The table. S(x, y) = Σ_{i <= x, j <= y} Q(i, j) mod 2^32 per channel: the running sums wrap
// around (uint arithmetic wraps in C++ and in GLSL), which only drops multiples of 2^32.
//
// Why rectangle queries are exact. The sum over the texels [x0, x1] × [y0, y1] is
//     A - B - C + D,  A = S(x1, y1), B = S(x0 - 1, y1), C = S(x1, y0 - 1), D = S(x0 - 1, y0 - 1),
// an identity of integers that also holds modulo 2^32 (the residues of a sum or difference are
// the sum or difference of the residues). Computed in uint, A - B - C + D is therefore congruent
// to the true sum modulo 2^32. The true sum of at most n_t texels lies in [0, n_t · s] ⊂
// [0, 2^32 - 1], where the residue is the number itself: the uint result IS the true sum, exactly,
// however often the running sums wrapped. A rectangle of more than n_t texels can exceed 2^32 - 1
// and then comes back reduced modulo 2^32 (wrong): callers keep every queried rectangle within
// n_t texels (soft.h clamps the kernel widths so).
//
// Precision of the queried averages: the exact integer sum is converted to float (relative error
// <= 2^-24) and divided by area · s: the average moments carry about 2 float roundings on top of
// the quantization step 1 / s of one texel (1 / (area · s) of the average).
#ifndef MSM_SAT_H
#define MSM_SAT_H
#include "msm/moments.h"
#include "msm/shared.h"

MSM_BEGIN

// s = floor((2^32 - 1) / n_t): the quantization scale for kernels of at most n_t texels.
// Precondition: n_t >= 1 (smaller values are treated as 1).
MSM_FN uint msm_sat_scale(int max_kernel_texels) { return 0xFFFFFFFFu / uint(max(max_kernel_texels, 1)); }

// Round half to even, the same on both sides for every float below 2^32 (GLM's roundEven converts
// to int first, which overflows above 2^31). C++: std::nearbyint in the default rounding mode.
#if MSM_CPP
MSM_FN vec4 msm_sat_round_even(vec4 x) {
  return vec4(std::nearbyint(x[0]), std::nearbyint(x[1]), std::nearbyint(x[2]), std::nearbyint(x[3]));
}
#else
MSM_FN vec4 msm_sat_round_even(vec4 x) { return roundEven(x); }
#endif

// One texel's moments q (Θ4* or half of Θ6*, nominally in [0,1]) to integers Q = round(q s) in
// [0, s]. Out-of-range input is clamped to [0,1] and NaN counts as 0 (msm_saturate), so no texel
// can break the bound of the sums. Bitwise the same in C++ and on any Vulkan device: q · float(s)
// is one correctly rounded multiplication (float(s) is exact for n_t >= 256; below, it is one
// correctly rounded conversion on both sides), rounding to even is exact, and the clamps keep the
// conversion to uint in range (4294967040 is the largest float below 2^32).
MSM_FN uvec4 msm_sat_quantize(vec4 q, uint scale) {
  vec4 unit = vec4(msm_saturate(q[0]), msm_saturate(q[1]), msm_saturate(q[2]), msm_saturate(q[3]));
  vec4 x = min(msm_sat_round_even(unit * float(scale)), vec4(4294967040.0f));
  return min(uvec4(x), uvec4(scale));
}

// A UNORM16 texel as fetched by a shader, re-decoded the way the C++ build decodes it (GLM's
// unpackUnorm: code k times the float nearest 1/65535), so that tables built on any device from
// 16-bit moments are bitwise those of the CPU: Vulkan lets a device's UNORM-to-float conversion
// differ from k / 65535 by some ulp, which would move a few quantized values by one. The fetched
// value is within a few ulp of k / 65535, so k = round(fetched · 65535) recovers the code exactly.
MSM_FN vec4 msm_sat_unorm16_texel(vec4 fetched) {
  return msm_sat_round_even(fetched * 65535.0f) * 1.5259021896696421759365224689097e-5f;
}

// Back to moments in [0,1] (one texel, or a sum of `texels` texels: msm_sat_rect_average).
MSM_FN vec4 msm_sat_dequantize(uvec4 value, uint scale) { return vec4(value) / float(scale); }

// ---- Rectangle queries (4 lookups) ----

// Texels [lo.x, hi.x] × [lo.y, hi.y], both ends inclusive; lo <= hi.
struct SatRect {
  ivec2 lo;
  ivec2 hi;
};

MSM_FN int msm_sat_rect_texels(SatRect r) { return (r.hi.x - r.lo.x + 1) * (r.hi.y - r.lo.y + 1); }

// The exact sum over rect from its four table values (uint arithmetic, modular; exact for rects
// of at most n_t texels, see the top of the file):
//   a = S(hi.x, hi.y), b = S(lo.x - 1, hi.y), c = S(hi.x, lo.y - 1), d = S(lo.x - 1, lo.y - 1),
// where S at a coordinate -1 is 0 (fetch nothing there).
MSM_FN uvec4 msm_sat_rect_sum(uvec4 a, uvec4 b, uvec4 c, uvec4 d) { return a - b - c + d; }

// The average moments (in [0,1]) of a rectangle of `texels` texels from its exact integer sum.
MSM_FN vec4 msm_sat_rect_average(uvec4 sum, int texels, uint scale) {
  return vec4(sum) / (float(texels) * float(scale));
}

// The texels that a continuous region [lo, hi] (texel units: texel i covers [i, i + 1)) touches,
// clamped to a size.x × size.y map, at least one texel: JCGT §4.5 extends the blocker search
// region to the texel grid so that it costs one 4-lookup query instead of the 16 of the
// interpolated query below. A region of width w touches at most ceil(w) + 1 texels per axis.
MSM_FN SatRect msm_sat_grid_rect(vec2 lo, vec2 hi, ivec2 size) {
  ivec2 first = clamp(ivec2(floor(lo)), ivec2(0), size - ivec2(1));
  ivec2 last = clamp(ivec2(ceil(hi)) - ivec2(1), first, size - ivec2(1));
  return SatRect(first, last);
}

// ---- Filter regions with fractional borders: nine regions, 16 lookups (JCGT §4.4, Fig. 7b) ----
//
// Bilinear interpolation of the table at the four corners of a region is wrong (adjacent table
// values differ by unknown multiples of 2^32). Instead, per axis the region [u0, u1] touches
// texel columns a = floor(u0) .. b = ceil(u1) - 1, covered by the fractions
//   left column a:        min(u1, a + 1) - u0,
//   middle columns a+1 .. b-1: 1,
//   right column b:       u1 - b          (when b > a; a one-column region is all "left").
// Three bands per axis make nine rectangles, each a 4-lookup query over at most n_t texels (if the
// whole a..b × c..d block has at most n_t texels), so each is exact; converted to float, weighted
// by its coverage product and summed, they give the integral of the piecewise constant moment map
// over the region: a box filter with fractional coverage at the borders. The table columns read
// are x = (a - 1, a, max(b - 1, a), b) and likewise rows y: 16 lookups (JCGT: 4·4·4·32 = 2048
// bits per query). Bands that are empty (b <= a + 1) read equal columns and sum to exactly 0.
struct SatFilter {
  ivec4 x;    // table columns to read (-1: reads as 0)
  ivec4 y;    // table rows to read
  vec3 wx;    // coverage of the left, each middle and the right column
  vec3 wy;    // coverage of the top, each middle and the bottom row
  float area; // (u1 - u0)(v1 - v0), texels²
};

// Precondition: 0 <= lo < hi <= map size per axis (soft.h's msm_soft_region guarantees it), and
// ceil(hi) - floor(lo) texels per axis make at most n_t texels (width hi - lo <= kernel width - 1
// does, see soft.h).
MSM_FN SatFilter msm_sat_filter(vec2 lo, vec2 hi) {
  ivec2 a = ivec2(floor(lo));
  ivec2 b = max(ivec2(ceil(hi)) - ivec2(1), a);
  vec2 first = min(hi, vec2(a) + vec2(1.0f)) - lo;
  vec2 last = hi - vec2(b);
  return SatFilter(ivec4(a.x - 1, a.x, max(b.x - 1, a.x), b.x), ivec4(a.y - 1, a.y, max(b.y - 1, a.y), b.y),
                   vec3(first.x, 1.0f, last.x), vec3(first.y, 1.0f, last.y), (hi.x - lo.x) * (hi.y - lo.y));
}

// The 16 table values of a filter region: s[4 j + i] = S(f.x[i], f.y[j]) (0 where either
// coordinate is -1). Declare one and assign its elements: `SatSamples16 t; t.s[k] = ...;`.
struct SatSamples16 {
  uvec4 s[16];
};

// The integral of the moments over the region divided by its area: the box-filtered moments
// (in [0,1], the same space as the texels), from the 16 lookups of msm_sat_filter.
MSM_FN vec4 msm_sat_filter_average(SatSamples16 t, SatFilter f, uint scale) {
  vec4 sum = vec4(0.0f);
  for (int j = 0; j < 3; ++j) {
    for (int i = 0; i < 3; ++i) {
      uvec4 region =
          msm_sat_rect_sum(t.s[4 * (j + 1) + i + 1], t.s[4 * (j + 1) + i], t.s[4 * j + i + 1], t.s[4 * j + i]);
      sum += (f.wx[i] * f.wy[j]) * vec4(region);
    }
  }
  return sum / (f.area * float(scale));
}

// ---- Six moments: two tables, the same scheme per channel ----
// Θ6* moments (quantize.h, msm_theta6_star) as two RGBA texels: a = (q1, q3, q5, q2) (odd moments,
// then the first even one), b = (q4, q6, 0, 0); the layout of msm_quantize_unorm16(Moments6).
// Each table is built and queried exactly like the four-moment one.
struct SatTexels6 {
  vec4 a;
  vec4 b;
};
struct SatValues6 {
  uvec4 a;
  uvec4 b;
};

MSM_FN SatTexels6 msm_sat_split6(Moments6 q) {
  return SatTexels6(vec4(q.odd, q.even[0]), vec4(q.even[1], q.even[2], 0.0f, 0.0f));
}
MSM_FN Moments6 msm_sat_join6(vec4 a, vec4 b) { return Moments6(vec3(a[0], a[1], a[2]), vec3(a[3], b[0], b[1])); }

MSM_FN SatValues6 msm_sat_quantize6(Moments6 q, uint scale) {
  SatTexels6 t = msm_sat_split6(q);
  return SatValues6(msm_sat_quantize(t.a, scale), msm_sat_quantize(t.b, scale));
}
MSM_FN SatValues6 msm_sat_rect_sum6(SatValues6 a, SatValues6 b, SatValues6 c, SatValues6 d) {
  return SatValues6(msm_sat_rect_sum(a.a, b.a, c.a, d.a), msm_sat_rect_sum(a.b, b.b, c.b, d.b));
}
MSM_FN Moments6 msm_sat_rect_average6(SatValues6 sum, int texels, uint scale) {
  return msm_sat_join6(msm_sat_rect_average(sum.a, texels, scale), msm_sat_rect_average(sum.b, texels, scale));
}
// Filter regions: msm_sat_filter_average on each table, then msm_sat_join6.

MSM_END

#endif // MSM_SAT_H
