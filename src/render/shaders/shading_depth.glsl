// Shading with the depth-based techniques: the plain shadow map and PCF. PCF uses exactly the
// kernel the moment techniques get from their pipeline (Gaussian blur, then a bilinear lookup):
// the weight of depth texel i along an axis is (1 - f) g[i - i0 + R] + f g[i - i0 - 1 + R] for
// t = i0 + f, over taps + 1 texels, and every MSAA sample counts 1 / samples.
#include "shading.glsl"
#define MSM_DEPTH_BINDING 2
#include "depth_map.glsl"

vec2 sample_offset(int k) {
  vec4 pair = frame.sample_offsets[k / 2];
  return (k & 1) == 0 ? vec2(pair.x, pair.y) : vec2(pair.z, pair.w);
}

// Fraction of the texel's samples in front of the receiver plane, each compared with the plane's
// depth at its own position (the rasterizer wrote the occluder's depth there).
float texel_occlusion(ivec2 i, ShadowLookup s) {
  int size = int(frame.shadow_map.x), samples = frame.kernel.y;
  ivec2 c = clamp(i, ivec2(0), ivec2(size - 1));
  float plane = s.z + dot(s.depth_per_texel, vec2(i) - s.t);
  float occluded = 0.0f;
  for (int k = 0; k < samples; ++k)
    occluded += depth_sample(c, k) < plane + dot(s.depth_per_texel, sample_offset(k)) ? 1.0f : 0.0f;
  return occluded / float(samples);
}

float shadow_intensity(ShadowLookup s) {
  if (kTechnique == MSM_TECH_PLAIN) return texel_occlusion(ivec2(floor(s.t + 0.5f)), s);
  int taps = frame.kernel.x, radius = frame.kernel.z;
  ivec2 i0 = ivec2(floor(s.t));
  vec2 f = s.t - vec2(i0);
  float shadow = 0.0f;
  for (int y = 0; y <= taps; ++y) {
    float wy = (y < taps ? (1.0f - f.y) * kernel_weight(y) : 0.0f) + (y > 0 ? f.y * kernel_weight(y - 1) : 0.0f);
    for (int x = 0; x <= taps; ++x) {
      float wx = (x < taps ? (1.0f - f.x) * kernel_weight(x) : 0.0f) + (x > 0 ? f.x * kernel_weight(x - 1) : 0.0f);
      shadow += wx * wy * texel_occlusion(i0 + ivec2(x, y) - ivec2(radius), s);
    }
  }
  return shadow;
}
