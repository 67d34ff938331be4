// The smallest and largest depth of the camera's depth buffer over the pixels that show a surface
// (depth below the cleared 1): a 16 x 16 workgroup reduces its pixels in shared memory, then one
// atomicMin and one atomicMax per workgroup on the float's bits as an uint (for floats >= 0 the
// bits order as the values). The result buffer starts at {bits of +inf, 0}: where it stays, no pixel
// showed a surface.
#version 460
#extension GL_GOOGLE_include_directive : require
#include "msm/render/bindings.h"
#include "msm/render/frame.h"

layout(local_size_x = 16, local_size_y = 16) in;
layout(binding = MSM_BINDING_DEPTH_BOUNDS_MAP) uniform sampler2D depth_map;
layout(std430, binding = MSM_BINDING_DEPTH_BOUNDS_RESULT) buffer Bounds { uint bounds[2]; }; // min, max bits
layout(push_constant) uniform Push { ImagePassPush pc; };                                  // size.xy

const uint kGroup = 256u;
const uint kInfinity = 0x7f800000u;
shared uint lowest[kGroup], highest[kGroup];

void main() {
  const ivec2 p = ivec2(gl_GlobalInvocationID.xy);
  const uint i = gl_LocalInvocationIndex;
  uint lo = kInfinity, hi = 0u;
  if (p.x < pc.size.x && p.y < pc.size.y) {
    const float depth = texelFetch(depth_map, p, 0).x;
    if (depth < 1.0f) {
      lo = floatBitsToUint(max(depth, 0.0f));
      hi = lo;
    }
  }
  lowest[i] = lo;
  highest[i] = hi;
  barrier();
  for (uint stride = kGroup / 2u; stride > 0u; stride /= 2u) {
    if (i < stride) {
      lowest[i] = min(lowest[i], lowest[i + stride]);
      highest[i] = max(highest[i], highest[i + stride]);
    }
    barrier();
  }
  if (i == 0u) {
    atomicMin(bounds[0], lowest[0]);
    atomicMax(bounds[1], highest[0]);
  }
}
