// Shading with the non-linearly quantized maps (HPG 2017): decode, then Algorithm 3. Their
// texels cannot be interpolated as stored: nearest and dithered lookups decode one texel; the
// true bilinear lookup decodes four, converts each back to moments (Eq. 4), interpolates those
// and applies Φ again (msm_nl_bilinear, about the interpolated mean depth).
#include "msm/render/bindings.h"
#ifdef MSM_NL32
layout(binding = MSM_BINDING_SHADING_SHADOW_MAP) uniform usampler2DArray moments0;
#else
layout(binding = MSM_BINDING_SHADING_SHADOW_MAP) uniform sampler2DArray moments0;
#endif
layout(binding = MSM_BINDING_SHADING_SHADOW_MAP1) uniform sampler2DArray unused_second_image; // the shading layout of every filtered technique
#include "shading.glsl"
#include "lookup.glsl"

// The lookup compiled in (kLookup, frame.glsl): llvmpipe executes both sides of a branch on a
// uniform under a mask, so with the branch the nearest and dithered lookups paid for the four
// decodes and Φ of the bilinear one (1416 instructions per pixel of NL64 shading instead of 645,
// scripts/callgrind-passes.sh).
const bool kBilinearLookup = kLookup == MSM_LOOKUP_BILINEAR;

NonLinearMoments decode(ivec2 i) {
#ifdef MSM_NL32
  return msm_nl_unpack32(texelFetch(moments0, ivec3(i, shadow_layer), 0).x);
#else
  return msm_nl64_decode(texelFetch(moments0, ivec3(i, shadow_layer), 0));
#endif
}

float shadow_intensity(ShadowLookup s) {
  s.z -= receiver_plane_bias(s, 0.0f); // the maps have no mips
  float zf = msm_signed_depth(s.z);
  if (!kBilinearLookup) {
    ivec2 i = lookup_texel(s.t);
    return msm_nl_shadow(decode(i), msm_signed_depth(receiver_depth_at(s, i)));
  }
  Bilinear b = bilinear_texels(s.t);
  NonLinearMoments m = msm_nl_bilinear(decode(b.i0), decode(ivec2(b.i1.x, b.i0.y)), decode(ivec2(b.i0.x, b.i1.y)),
                                       decode(b.i1), b.f);
  return msm_nl_shadow(m, zf);
}
