// A point light's shadow map: six perspective faces about the axes, in the order of Vulkan's cube
// maps (+x, -x, +y, -y, +z, -z), each a layer of the frame's shadow-map arrays. The face a direction
// from the light falls on, its coordinates there and the face's axes, one definition for the
// shading's lookup (shading.glsl) and the renderer's face matrices (its look-at from these axes).
//
// Each face's map is drawn with a field of view a little wider than 90 degrees (a guard band of
// texels on every side, msm_cube_face_half_width): the blur and the lookup's filter near an edge of
// the face read the texels that the neighbouring face also holds, rendered, rather than a clamped
// edge, so the filtered map has no seam. The lookup still picks the face by the major axis, so it
// reads no further than the guard band from the 90-degree part.
#ifndef MSM_CUBE_FACE_H
#define MSM_CUBE_FACE_H
#include "msm/shared.h"

MSM_BEGIN

// The face whose 90-degree part holds direction d (any length, not 0): the axis of d's largest
// component, its sign; ties go to x before y before z, and to the positive face at 0.
MSM_FN int msm_cube_face(vec3 d) {
  vec3 a = abs(d);
  if (a.x >= a.y && a.x >= a.z) return d.x >= 0.0f ? 0 : 1;
  if (a.y >= a.z) return d.y >= 0.0f ? 2 : 3;
  return d.z >= 0.0f ? 4 : 5;
}

// The unit direction the face looks along (its axis).
MSM_FN vec3 msm_cube_face_forward(int face) {
  vec3 f = vec3(0.0f);
  f[face / 2] = face % 2 == 0 ? 1.0f : -1.0f;
  return f;
}

// The face's up direction: +y for the side faces, +z for the two faces along y.
MSM_FN vec3 msm_cube_face_up(int face) { return face / 2 == 1 ? vec3(0.0f, 0.0f, 1.0f) : vec3(0.0f, 1.0f, 0.0f); }

// The face's right direction: forward × up (a look-at's x axis).
MSM_FN vec3 msm_cube_face_right(int face) { return cross(msm_cube_face_forward(face), msm_cube_face_up(face)); }

// Direction d's coordinates on the face, as tangents of the angles off its axis along right and
// up: in [-1, 1] on the face that msm_cube_face picks for d.
MSM_FN vec2 msm_cube_face_uv(vec3 d, int face) {
  float along = dot(d, msm_cube_face_forward(face));
  return vec2(dot(d, msm_cube_face_right(face)), dot(d, msm_cube_face_up(face))) / along;
}

// The tangent of half the field of view of a face's map of `size` texels per side whose 90-degree
// part has `guard_texels` more texels beyond it on each side: the map spans [-g, g] in tangents,
// 2g / size per texel, so g = 1 + guard_texels · 2g / size.
MSM_FN float msm_cube_face_half_width(float guard_texels, float size) {
  return 1.0f / (1.0f - 2.0f * guard_texels / size);
}

// How many texels of a face's map of `size` texels spanning [-g, g] lie between uv and the nearest
// edge of the face's 90-degree part (a seam with a neighbouring face): 0 on the seam.
MSM_FN float msm_cube_face_seam_texels(vec2 uv, float g, float size) {
  return (1.0f - max(abs(uv.x), abs(uv.y))) * size / (2.0f * g);
}

// The coarsest mip level a bilinear lookup at t (texel-centre coordinates of a face's map of `size`
// texels per side) may read and stay on real data: the texels within `blur_radius` of the map's
// edge were blurred with clamped neighbours, and a bilinear fetch at level k reaches up to 2^(k+1)
// texels of level 0 from t. Near a seam this holds the lookup to the levels its guard band covers;
// far from the map's edges it allows every level.
MSM_FN float msm_cube_face_max_lod(vec2 t, float size, float blur_radius) {
  float to_edge = min(min(t.x, t.y), min(size - 1.0f - t.x, size - 1.0f - t.y)) + 0.5f;
  return log2(max(to_edge - blur_radius, 1.0f)) - 1.0f;
}

MSM_END

#endif
