// Copy shaders of msm_sat_timing (docs/results.md "Copy shaders and a buffer scheme
// against the copy bound"): what any shader moving a table of 16 B texels can reach on a device,
// measured beside the summed-area table schemes. Not used by the renderer. Each reads and writes
// every texel of a width × height table once, with nothing else to do:
//   SAT_COPY_IMAGE:  imageLoad of an RGBA32_UINT storage image, imageStore into another;
//   SAT_COPY_BUFFER: a uvec4 of one storage buffer into another (row-major, width × height);
//   SAT_COPY_FETCH:  texelFetch of an RGBA32F sampled image (the row pass's moment fetch, without
//                    the quantization), its bits imageStore'd into an RGBA32_UINT storage image.
// and the walk of the invocations:
//   SAT_COPY_TEXEL:   one texel per invocation; workgroup (x, y) covers 64 neighbouring texels of row y;
//   SAT_COPY_TEXEL4:  four per invocation, texels lane, lane + 64, lane + 128, lane + 192 of the
//                     group's 256 neighbouring texels (each of the four accesses contiguous over the lanes);
//   SAT_COPY_ROW:     one row per invocation, left to right (as sat_rows.glsl walks);
//   SAT_COPY_COLUMN:  one column per invocation, top to bottom (as sat_columns.glsl walks).
// Push constants: SatPush (sat_common.glsl) of which only the size is read.
#include "sat_common.glsl"

layout(local_size_x = 64) in;
#ifdef SAT_COPY_IMAGE
layout(binding = MSM_BINDING_SAT_COPY_SOURCE, rgba32ui) uniform readonly uimage2D src;
layout(binding = MSM_BINDING_SAT_COPY_DESTINATION, rgba32ui) uniform writeonly uimage2D dst;
void copy_texel(int x, int y) { imageStore(dst, ivec2(x, y), imageLoad(src, ivec2(x, y))); }
#elif defined(SAT_COPY_FETCH)
layout(binding = MSM_BINDING_SAT_COPY_SOURCE) uniform sampler2D src;
layout(binding = MSM_BINDING_SAT_COPY_DESTINATION, rgba32ui) uniform writeonly uimage2D dst;
void copy_texel(int x, int y) { imageStore(dst, ivec2(x, y), floatBitsToUint(texelFetch(src, ivec2(x, y), 0))); }
#else
layout(binding = MSM_BINDING_SAT_COPY_SOURCE, std430) readonly buffer Src { uvec4 src[]; };
layout(binding = MSM_BINDING_SAT_COPY_DESTINATION, std430) writeonly buffer Dst { uvec4 dst[]; };
void copy_texel(int x, int y) {
  int i = y * pc.size.x + x;
  dst[i] = src[i];
}
#endif

void main() {
#if defined(SAT_COPY_TEXEL)
  int x = int(gl_GlobalInvocationID.x), y = int(gl_WorkGroupID.y);
  if (x < pc.size.x) copy_texel(x, y);
#elif defined(SAT_COPY_TEXEL4)
  int x0 = int(gl_WorkGroupID.x) * 256 + int(gl_LocalInvocationID.x), y = int(gl_WorkGroupID.y);
  for (int k = 0; k < 4; ++k)
    if (x0 + 64 * k < pc.size.x) copy_texel(x0 + 64 * k, y);
#elif defined(SAT_COPY_ROW)
  int y = int(gl_GlobalInvocationID.x);
  if (y >= pc.size.y) return;
  for (int x = 0; x < pc.size.x; ++x) copy_texel(x, y);
#elif defined(SAT_COPY_COLUMN)
  int x = int(gl_GlobalInvocationID.x);
  if (x >= pc.size.x) return;
  for (int y = 0; y < pc.size.y; ++y) copy_texel(x, y);
#endif
}
