// Copies every sample of a multisampled depth image into a buffer (tests compare the resolve
// with the CPU on exactly these depths): samples[(y * width + x) * samples + s].
#version 460
#extension GL_GOOGLE_include_directive : require
#include "msm/render/frame.h"

layout(local_size_x = 8, local_size_y = 8) in;
layout(binding = MSM_BINDING_DEPTH_SAMPLES_MAP) uniform sampler2DMS depth_map;
layout(std430, binding = MSM_BINDING_DEPTH_SAMPLES_BUFFER) writeonly buffer Samples { float samples[]; };
layout(push_constant) uniform Push { ImagePassPush pc; }; // size.xy, size.z = samples

void main() {
  ivec2 p = ivec2(gl_GlobalInvocationID.xy);
  if (p.x >= pc.size.x || p.y >= pc.size.y) return;
  for (int s = 0; s < pc.size.z; ++s) samples[(p.y * pc.size.x + p.x) * pc.size.z + s] = texelFetch(depth_map, p, s).x;
}
