#version 460
// Equirectangular panorama -> cube map (msm::probe::cube_from_equirect's filtering and rotation,
// through the same functions of light_probe.h): one invocation per cube texel, the average of ss²
// bilinear point samples.
#extension GL_GOOGLE_include_directive : require
#include "probe_common.glsl"

layout(local_size_x = 8, local_size_y = 8) in;
layout(binding = MSM_BINDING_PROBE_CUBE_PANORAMA, std430) readonly buffer Panorama { vec4 panorama[]; };
layout(binding = MSM_BINDING_PROBE_CUBE_FACES, std430) writeonly buffer Cube { vec4 cube[]; };

vec3 fetch(ivec2 p) {
  ivec2 q = msm_equirect_texel(p, pc.panorama);
  return panorama[q.y * pc.panorama.x + q.x].xyz;
}

void main() {
  ivec3 id = ivec3(gl_GlobalInvocationID);
  if (id.x >= pc.size || id.y >= pc.size) return;
  int ss = pc.supersampling;
  vec3 sum = vec3(0.0f);
  for (int b = 0; b < ss; ++b)
    for (int a = 0; a < ss; ++a) {
      float u = msm_cube_face_coordinate(id.x, (float(a) + 0.5f) / float(ss), float(pc.size));
      float v = msm_cube_face_coordinate(id.y, (float(b) + 0.5f) / float(ss), float(pc.size));
      vec3 d = msm_probe_lookup_direction(msm_cube_direction(id.z, u, v), pc.cos_sin);
      MsmBilinearTap tap = msm_equirect_tap(msm_equirect_of(d), pc.panorama);
      sum += msm_bilinear(fetch(tap.p0), fetch(tap.p0 + ivec2(1, 0)), fetch(tap.p0 + ivec2(0, 1)),
                          fetch(tap.p0 + ivec2(1, 1)), tap.f);
    }
  cube[(id.z * pc.size + id.y) * pc.size + id.x] = vec4(sum / float(ss * ss), 0.0f);
}
