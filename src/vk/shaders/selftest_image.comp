// Exercises every Binding type and push constants:
//   result(p) = source(p) * scale + texelFetch(table, p) + offset + vec4(p, layer, 0)
// (values chosen by the test so that every step is exact, whatever the rounding or fusing).
#version 460
#extension GL_GOOGLE_include_directive : require
#include "vk_bindings.h"

layout(local_size_x = 8, local_size_y = 8) in;

layout(binding = MSM_BINDING_SELFTEST_IMAGE_SOURCE, rgba32f) uniform readonly image2D source;
layout(binding = MSM_BINDING_SELFTEST_IMAGE_RESULT, rgba32f) uniform writeonly image2D result;
layout(binding = MSM_BINDING_SELFTEST_IMAGE_TABLE) uniform sampler2D table;
layout(binding = MSM_BINDING_SELFTEST_IMAGE_PARAMS) uniform Params { vec4 offset; } params;
layout(push_constant) uniform Push {
  ivec2 size;
  float scale;
  float layer;
} pc;

void main() {
  ivec2 p = ivec2(gl_GlobalInvocationID.xy);
  if (p.x >= pc.size.x || p.y >= pc.size.y) return;
  vec4 value = imageLoad(source, p) * pc.scale + texelFetch(table, p, 0) + params.offset;
  imageStore(result, p, value + vec4(p.x, p.y, pc.layer, 0.0));
}
