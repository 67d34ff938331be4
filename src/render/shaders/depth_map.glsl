// The shadow pass's depth map as the compute and fragment shaders read it: multisampled, or
// single-sampled where the including file defines MSM_SINGLE_SAMPLE (a sampler2DMS cannot take a
// one-sample image). The including file defines MSM_DEPTH_BINDING, and MSM_DEPTH_LAYERED where it
// reads the whole array (one layer per light; layer `shadow_layer`) instead of one light's layer.
#ifdef MSM_DEPTH_LAYERED
#ifdef MSM_SINGLE_SAMPLE
layout(binding = MSM_DEPTH_BINDING) uniform sampler2DArray depth_map;
#else
layout(binding = MSM_DEPTH_BINDING) uniform sampler2DMSArray depth_map;
#endif
#define MSM_DEPTH_TEXEL(p) ivec3(p, shadow_layer)
#else
#ifdef MSM_SINGLE_SAMPLE
layout(binding = MSM_DEPTH_BINDING) uniform sampler2D depth_map;
#else
layout(binding = MSM_DEPTH_BINDING) uniform sampler2DMS depth_map;
#endif
#define MSM_DEPTH_TEXEL(p) (p)
#endif

// Kneiphof §4.2.3 (FrameConfig::front_back): where the including file defines
// MSM_BACK_DEPTH_BINDING, the back-face depth map of the same layout (the nearest back face of each
// sample) at that binding, averaged with the front's when kFrontBack (its specialization constant).
#ifdef MSM_BACK_DEPTH_BINDING
#ifdef MSM_SINGLE_SAMPLE
layout(binding = MSM_BACK_DEPTH_BINDING) uniform sampler2D back_depth_map;
#else
layout(binding = MSM_BACK_DEPTH_BINDING) uniform sampler2DMS back_depth_map;
#endif
#endif

// Depth of sample s of texel p (sample 0 where single-sampled).
float depth_sample(ivec2 p, int s) {
#ifdef MSM_SINGLE_SAMPLE
  float front = texelFetch(depth_map, MSM_DEPTH_TEXEL(p), 0).x;
#ifdef MSM_BACK_DEPTH_BINDING
  if (kFrontBack) return 0.5f * (front + texelFetch(back_depth_map, MSM_DEPTH_TEXEL(p), 0).x);
#endif
#else
  float front = texelFetch(depth_map, MSM_DEPTH_TEXEL(p), s).x;
#ifdef MSM_BACK_DEPTH_BINDING
  if (kFrontBack) return 0.5f * (front + texelFetch(back_depth_map, MSM_DEPTH_TEXEL(p), s).x);
#endif
#endif
  return front;
}

#ifdef MSM_TECHNIQUES_H
// The technique's channels of every sample of texel p, averaged: the MSAA resolve (a box filter,
// linear like everything before storage). Depths are clamped: NaN never reaches the moments.
// The sample count is the frame's, or MSM_RESOLVE_SAMPLES where the including file defines it (a
// specialization constant: the loop over the samples unrolls, and so can loops around it).
#ifndef MSM_RESOLVE_SAMPLES
#define MSM_RESOLVE_SAMPLES frame.kernel.y
#endif
MsmTexel resolved_texel(ivec2 p) {
  int samples = MSM_RESOLVE_SAMPLES;
  MsmTexel sum = MsmTexel(vec4(0.0f), vec4(0.0f));
  for (int s = 0; s < samples; ++s) {
    MsmTexel t = msm_technique_generate(kTechnique, msm_saturate(depth_sample(p, s)), frame.technique_params);
    sum.a += t.a;
    sum.b += t.b;
  }
  float inv = 1.0f / float(samples);
  return MsmTexel(sum.a * inv, sum.b * inv);
}
#endif
