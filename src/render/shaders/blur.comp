// One direction of the separable Gaussian blur of a moment image (frame.filter_weights, taps
// frame.kernel.x): horizontal when pc.size.z == 0, vertical otherwise. Clamp-to-edge. A texel
// that is not finite (it cannot come from the resolve, which clamps depths) gets weight zero and
// the others are renormalized, so that one bad texel never spreads over the kernel.
#version 460
#extension GL_GOOGLE_include_directive : require
#include "frame.glsl"

layout(local_size_x = 8, local_size_y = 8) in;

layout(binding = 1) uniform sampler2D source;
layout(binding = 2) writeonly uniform image2D target;

layout(push_constant) uniform Push { ImagePassPush pc; };

bool finite4(vec4 v) { return !any(isnan(v)) && !any(isinf(v)); }

void main() {
  ivec2 p = ivec2(gl_GlobalInvocationID.xy);
  if (p.x >= pc.size.x || p.y >= pc.size.y) return;
  ivec2 step = pc.size.z == 0 ? ivec2(1, 0) : ivec2(0, 1);
  int taps = frame.kernel.x, radius = frame.kernel.z;
  ivec2 last = pc.size.xy - ivec2(1);
  vec4 sum = vec4(0.0f);
  float total = 0.0f;
  for (int k = 0; k < taps; ++k) {
    vec4 v = texelFetch(source, clamp(p + (k - radius) * step, ivec2(0), last), 0);
    if (finite4(v)) {
      float w = kernel_weight(k);
      sum += w * v;
      total += w;
    }
  }
  imageStore(target, p, total > 0.0f ? sum / total : vec4(0.0f));
}
