// The per-texel steps of the three.js package's techniques, from the shared headers: what a
// shadow-map texel holds for one depth (generate), what its blurred value is stored as (store), and
// the shadow intensity at a receiver from the stored, bilinearly fetched texel (shadow). These
// are the steps of the renderer's techniques (techniques.h) of the same name, which this header
// cannot include (techniques.h reaches headers that GLSL ES 3.00 does not compile); the browser
// test compares them with msm_technique_generate and msm_technique_shadow of the C++ library
// (web/test/kernels.cpp). A SHARED header: shared.h's rules apply.
// Depths: unit_depth and unit_zf are shadow-map depths in [0,1] (three.js's shadow coordinates).
#ifndef MSM_THREE_H
#define MSM_THREE_H
#include "msm/baselines.h" // msm_overdarken: the lookups' over-darkening, as the renderer's shading
#include "msm/bias.h"
#include "msm/cube_face.h"
#include "msm/filter.h"
#include "msm/hamburger4.h"
#include "msm/local_light.h"
#include "msm/moments.h"
#include "msm/nonlinear.h"
#include "msm/quantize.h"
#include "msm/shared.h"

MSM_BEGIN

// The package's techniques (web/src/index.js names them).
const int MSM_THREE_HAMBURGER_64 = 0;  // 4 x 16 bits after Θ4*, [-1,1] depth (JCGT): msm-hamburger-64
const int MSM_THREE_HAMBURGER_128 = 1; // 4 x float, [-1,1] depth (JCGT): msm-hamburger-128
const int MSM_THREE_NL64 = 2;          // Φ of the float moments in 4 x 16 bits (HPG 2017): msm-nl-64
const int MSM_THREE_NL32 = 3;          // Φ of the float moments in 32 bits (HPG 2017 §3.5): msm-nl-32
const int MSM_THREE_MSSM4 = 4; // Θ4* in a 32-bit integer summed-area table (JCGT §4): msm-mssm4 (msm_three_soft.h)

MSM_FN bool msm_three_is_nonlinear(int t) { return t == MSM_THREE_NL64 || t == MSM_THREE_NL32; }

// A 32-bit word as the four bytes of an RGBA8 texel (byte k holds bits 8k..8k+7, stored as the
// UNORM8 value byte / 255, which the texture holds exactly), and back: WebGL 2 binds no integer
// texture where three.js's lookup expects a float one.
MSM_FN vec4 msm_three_rgba8_from_word(uint p) {
  return vec4(float(p & 255u), float((p >> 8u) & 255u), float((p >> 16u) & 255u), float(p >> 24u)) / 255.0f;
}
MSM_FN uint msm_three_word_from_rgba8(vec4 texel) {
  uvec4 b = uvec4(round(texel * 255.0f));
  return b.x | (b.y << 8u) | (b.z << 16u) | (b.w << 24u);
}

// The filterable channels of one depth, already in the storage basis (Θ4* commutes with the blur).
MSM_FN vec4 msm_three_generate(int t, float unit_depth) {
  vec4 b = msm_moments4(msm_signed_depth(unit_depth));
  if (t == MSM_THREE_HAMBURGER_64 || t == MSM_THREE_MSSM4) return msm_theta4_star(b);
  return b;
}

// What the shadow map stores of the blurred channels: 16-bit rounding (UNORM16 storage; the
// package keeps the rounded values in a float texture, which filters them as UNORM16 would).
// The non-linear map stores Φ's four UNORM16 values as floats k / 65535 (techniques.h's
// msm_nl64_encode); the 32-bit map its word as an RGBA8 texel (msm_nl32_encode).
MSM_FN vec4 msm_three_store(int t, vec4 filtered) {
  if (t == MSM_THREE_NL32) return msm_three_rgba8_from_word(msm_nl_pack32(msm_nl_from_filtered(filtered)));
  if (t == MSM_THREE_HAMBURGER_64) return msm_quantize_unorm16(filtered);
  if (t == MSM_THREE_NL64) {
    uvec2 p = msm_nl_pack64(msm_nl_from_filtered(filtered));
    return vec4(unpackUnorm2x16(p.x), unpackUnorm2x16(p.y));
  }
  return filtered;
}

// The depth bias of the technique's maps (config.h), in the shadow map's [0,1] depth.
MSM_FN float msm_three_depth_bias(int t) {
  return msm_three_is_nonlinear(t) ? MSM_DEPTH_BIAS_NONLINEAR : MSM_DEPTH_BIAS_FILTERED;
}

// A 64-bit non-linear texel as msm_three_store stores it, decoded (techniques.h's msm_nl64_decode).
MSM_FN NonLinearMoments msm_three_nl64_decode(vec4 texel) {
  return msm_nl_unpack64(uvec2(packUnorm2x16(vec2(texel.x, texel.y)), packUnorm2x16(vec2(texel.z, texel.w))));
}
// The bilinear lookup of the 64-bit non-linear map, as the renderer's shading_nonlinear.glsl reads
// it: four stored texels (t10 the next along x, t01 along y), f the weights, msm_nl_bilinear's Φ of
// the interpolated distributions, Algorithm 3 at receiver depth unit_zf.
MSM_FN float msm_three_nl64_bilinear_shadow(vec4 t00, vec4 t10, vec4 t01, vec4 t11, vec2 f, float unit_zf) {
  NonLinearMoments m = msm_nl_bilinear(msm_three_nl64_decode(t00), msm_three_nl64_decode(t10),
                                       msm_three_nl64_decode(t01), msm_three_nl64_decode(t11), f);
  return msm_nl_shadow(m, msm_signed_depth(unit_zf));
}

// A point light's cube map as WebGL 2 samples it (the major-axis table of the OpenGL ES 3.0
// specification, 3.8.10): faces +x, -x, +y, -y, +z, -z (msm_cube_face picks them, in that order),
// each with face coordinates st in [-1, 1], st = 2 (s, t) - 1 of its texture coordinates (texel
// (i, j)'s centre at s = (i + 1/2) / size). The direction a face's st stands for:
MSM_FN vec3 msm_three_cube_direction(int face, vec2 st) {
  if (face == 0) return vec3(1.0f, -st.y, -st.x);
  if (face == 1) return vec3(-1.0f, -st.y, st.x);
  if (face == 2) return vec3(st.x, 1.0f, st.y);
  if (face == 3) return vec3(st.x, -1.0f, -st.y);
  if (face == 4) return vec3(st.x, -st.y, 1.0f);
  return vec3(-st.x, -st.y, -1.0f);
}

// Its inverse: direction d's face coordinates on `face` (in [-1, 1] on msm_cube_face(d)).
MSM_FN vec2 msm_three_cube_face_coordinates(vec3 d, int face) {
  vec3 a = abs(d);
  if (face == 0) return vec2(-d.z, -d.y) / a.x;
  if (face == 1) return vec2(d.z, -d.y) / a.x;
  if (face == 2) return vec2(d.x, d.z) / a.y;
  if (face == 3) return vec2(d.x, -d.z) / a.y;
  if (face == 4) return vec2(d.x, -d.y) / a.z;
  return vec2(-d.x, -d.y) / a.z;
}

// Direction d in texel-centre coordinates of its face (size texels per side): texel (i, j)'s centre
// at (i, j); a bilinear lookup's texels are floor of it and one more, its weights the fraction.
MSM_FN vec2 msm_three_cube_texel_coordinates(vec3 d, float size) {
  return (msm_three_cube_face_coordinates(d, msm_cube_face(d)) + 1.0f) * (0.5f * size) - 0.5f;
}

// The direction of the centre of texel floor(t + offset) of d's face, t its texel-centre
// coordinates: offset (0, 0), (1, 0), (0, 1), (1, 1) give a bilinear lookup's four texels, a blue
// noise offset in [0, 1) the dithered lookup's one. A texel past the face's edge is a direction off
// the face, which a nearest-filtered cube lookup finds in the neighbouring face: the lookup reads
// across the seams as the blur does.
MSM_FN vec3 msm_three_cube_texel_direction(vec3 d, float size, vec2 offset) {
  vec2 texel = floor(msm_three_cube_texel_coordinates(d, size) + offset);
  return msm_three_cube_direction(msm_cube_face(d), (texel + 0.5f) * (2.0f / size) - 1.0f);
}

// Shadow intensity in [0,1] (1 = fully shadowed) at receiver depth unit_zf: Hamburger 4MSM on the
// biased moments (the representation's α and b*).
MSM_FN float msm_three_shadow(int t, vec4 stored, float unit_zf) {
  if (t == MSM_THREE_NL64) return msm_nl_shadow(msm_three_nl64_decode(stored), msm_signed_depth(unit_zf)); // one texel
  if (t == MSM_THREE_NL32)
    return msm_nl_shadow(msm_nl_unpack32(msm_three_word_from_rgba8(stored)), msm_signed_depth(unit_zf));
  float zf = msm_signed_depth(unit_zf);
  if (t == MSM_THREE_HAMBURGER_64)
    return msm_hamburger4_lower(msm_apply_bias(msm_theta4_star_inverse(stored), msm_moment_bias(MSM_REP_SIGNED_THETA4)),
                                zf);
  return msm_hamburger4_lower(msm_apply_bias(stored, msm_moment_bias(MSM_REP_SIGNED_FLOAT)), zf);
}

MSM_END

#endif // MSM_THREE_H
