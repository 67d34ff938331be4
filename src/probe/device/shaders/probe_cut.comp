#version 460
// The median cut in one workgroup (Kneiphof §5), region for region the CPU's msm::probe::median_cut
// on the same fixed-point tables, then the area light of every region (msm_area_light_from_region).
// Invocation t holds region t, from the six faces (or, with the horizon split, the ten regions of
// msm_first_region). Each step: a tree reduction finds the splittable region of the
// largest energy (ties: the lowest index, the CPU's "first"), then invocation 0 splits it at the
// energy median by a binary search through the tables; the first part replaces it, the second
// part is appended — the CPU's order. Below six regions, invocation 0 merges the six face regions
// pairwise instead (median_cut's rule: the least energy together among groups sharing a cube edge),
// and a group's light adds its faces' lights (msm_merged_sums_add, msm_area_light_from_merged).
#extension GL_GOOGLE_include_directive : require
#include "probe_common.glsl"
#include "msm/median_cut.h"

const int MAX_REGIONS = MSM_PROBE_MAX_REGIONS;
layout(local_size_x = 256) in;
layout(binding = MSM_BINDING_PROBE_CUT_TABLES, std430) readonly buffer Tables { uint64_t tables[]; };

layout(binding = MSM_BINDING_PROBE_CUT_RESULT, std430) writeonly buffer Result { ProbeCutResult result; };

shared ivec4 s_rect[MAX_REGIONS];
shared int s_face[MAX_REGIONS];
shared uint64_t s_energy[MAX_REGIONS];
shared uint s_faces[MAX_REGIONS];
shared uint64_t s_key[MAX_REGIONS];
shared uint s_index[MAX_REGIONS];

// The sum over texels [0, x) x [0, y) of table k (the tables are inclusive).
uint64_t corner(int face, int k, int x, int y) {
  if (x == 0 || y == 0) return 0ul;
  return tables[probe_table_index(face, k, x - 1, y - 1)];
}
uint64_t rect_sum(int face, int k, ivec4 r) {
  return corner(face, k, r.z, r.w) - corner(face, k, r.x, r.w) - corner(face, k, r.z, r.y) + corner(face, k, r.x, r.y);
}

// The first part of r cut at `cut` along x or y.
ivec4 first_part(ivec4 r, bool along_x, int cut) {
  return along_x ? ivec4(r.x, r.y, cut, r.w) : ivec4(r.x, r.y, r.z, cut);
}
// 2 E(first part) − E(r): E < 2^62, so it fits in int64.
int64_t twice_minus_whole(int face, ivec4 r, uint64_t energy, bool along_x, int cut) {
  return int64_t(2ul * rect_sum(face, 1, first_part(r, along_x, cut))) - int64_t(energy);
}
int64_t abs64(int64_t a) { return a < 0l ? -a : a; }

// The sums of a rectangle of a face (ProbeTables::sums): converted to float after the integer
// differences; the first moments are stored shifted by the energy.
MsmRegionSums region_sums(int face, ivec4 r) {
  uint64_t y = rect_sum(face, 1, r);
  vec3 xyz = vec3(float(rect_sum(face, 0, r)), float(y), float(rect_sum(face, 2, r)));
  vec2 first =
      vec2(float(int64_t(rect_sum(face, 3, r)) - int64_t(y)), float(int64_t(rect_sum(face, 4, r)) - int64_t(y)));
  vec2 second = vec2(float(rect_sum(face, 5, r)), float(rect_sum(face, 6, r)));
  return msm_region_sums_from_fixed(xyz, first, second, pc.inv_scale);
}

uint face_mask(int k) { return s_faces[k] != 0u ? s_faces[k] : (1u << uint(s_face[k])); }
// Some face of group a shares a cube edge with some face of group b (not opposite faces).
bool share_an_edge(uint a, uint b) {
  for (int f = 0; f < 6; ++f)
    for (int g = 0; g < 6; ++g)
      if ((a & (1u << uint(f))) != 0u && (b & (1u << uint(g))) != 0u && f / 2 != g / 2) return true;
  return false;
}
// Invocation 0, count < 6: the six face regions merged down to count (the CPU's merge_faces).
void merge_faces(int count) {
  int n = 6;
  while (n > count) {
    int bi = -1, bj = -1;
    uint64_t best = 0ul;
    for (int i = 0; i < n; ++i)
      for (int j = i + 1; j < n; ++j) {
        if (!share_an_edge(face_mask(i), face_mask(j))) continue;
        uint64_t e = s_energy[i] + s_energy[j]; // six faces < 4π 2^60 < 2^64
        if (bi < 0 || e < best) {
          bi = i;
          bj = j;
          best = e;
        }
      }
    s_faces[bi] = face_mask(bi) | face_mask(bj);
    s_energy[bi] = best;
    for (int k = bj; k + 1 < n; ++k) {
      s_rect[k] = s_rect[k + 1];
      s_face[k] = s_face[k + 1];
      s_energy[k] = s_energy[k + 1];
      s_faces[k] = s_faces[k + 1];
    }
    --n;
  }
}

void split(uint best, int n) {
  ivec4 r = s_rect[best];
  int face = s_face[best];
  uint64_t energy = s_energy[best];
  bool along_x = (r.z - r.x) >= (r.w - r.y);
  int lo = along_x ? r.x : r.y, hi = along_x ? r.z : r.w;
  int a = lo + 1, b = hi - 1;
  while (a < b) {
    int mid = (a + b) / 2;
    if (twice_minus_whole(face, r, energy, along_x, mid) < 0l)
      a = mid + 1;
    else
      b = mid;
  }
  int cut = a;
  if (cut - 1 > lo && abs64(twice_minus_whole(face, r, energy, along_x, cut - 1)) <=
                          abs64(twice_minus_whole(face, r, energy, along_x, cut)))
    cut -= 1;
  ivec4 first = first_part(r, along_x, cut);
  ivec4 second = along_x ? ivec4(cut, r.y, r.z, r.w) : ivec4(r.x, cut, r.z, r.w);
  s_rect[best] = first;
  s_energy[best] = rect_sum(face, 1, first);
  s_rect[n] = second;
  s_face[n] = face;
  s_faces[n] = 0u;
  s_energy[n] = rect_sum(face, 1, second);
}

void main() {
  uint t = gl_LocalInvocationID.x;
  int m = pc.size;
  bool horizon_split = pc.horizon_split != 0;
  int n = msm_first_region_count(horizon_split); // the host checked count >= n with the split
  if (t < uint(n)) {
    MsmFirstRegion first = msm_first_region(int(t), m, horizon_split);
    s_rect[t] = first.rect;
    s_face[t] = first.face;
    s_energy[t] = rect_sum(first.face, 1, first.rect);
  }
  s_faces[t] = 0u;
  barrier();
  int count = clamp(pc.count, 1, MAX_REGIONS);
  if (count < 6 && !horizon_split) {
    if (t == 0u) merge_faces(count);
    barrier();
    n = count;
  }
  while (n < count) {
    // Splittable regions (more than one texel) have key energy + 1, the others 0.
    uint64_t key = 0ul;
    if (t < uint(n)) {
      ivec4 r = s_rect[t];
      if (r.z - r.x >= 2 || r.w - r.y >= 2) key = s_energy[t] + 1ul;
    }
    s_key[t] = key;
    s_index[t] = t;
    barrier();
    for (uint stride = uint(MAX_REGIONS) / 2u; stride > 0u; stride >>= 1u) {
      if (t < stride) {
        uint64_t ka = s_key[t], kb = s_key[t + stride];
        uint ia = s_index[t], ib = s_index[t + stride];
        if (kb > ka || (kb == ka && ib < ia)) {
          s_key[t] = kb;
          s_index[t] = ib;
        }
      }
      barrier();
    }
    uint64_t best_key = s_key[0];
    uint best = s_index[0];
    if (best_key == 0ul) break; // every region is one texel (the same in every invocation)
    if (t == 0u) split(best, n);
    barrier();
    ++n;
  }

  if (t < uint(n)) {
    ivec4 r = s_rect[t];
    int face = s_face[t];
    uint faces = s_faces[t];
    bool lit;
    MsmAreaLight l;
    if (faces != 0u) { // a group of whole faces, in increasing face order (the CPU's area_lights)
      MsmMergedSums merged = msm_merged_sums_empty();
      for (int f = 0; f < 6; ++f)
        if ((faces & (1u << uint(f))) != 0u) merged = msm_merged_sums_add(merged, f, region_sums(f, ivec4(0, 0, m, m)));
      lit = merged.xyz.y > 0.0f;
      if (lit) l = msm_area_light_from_merged(merged);
    } else {
      MsmRegionSums sums = region_sums(face, r);
      lit = sums.xyz.y > 0.0f;
      if (lit) l = msm_area_light_from_region(face, sums);
    }
    result.regions[t] = ProbeCutRegion(r, face, lit ? 1u : 0u, s_energy[t], faces, 0u, 0u, 0u);
    if (lit)
      result.lights[t] = ProbeCutLight(vec4(l.direction, l.cone_half_angle), vec4(l.x_axis, l.half_extent.x),
                                  vec4(l.y_axis, l.half_extent.y), vec4(l.irradiance, 0.0f));
  }
  if (t == 0u) result.region_count = uint(n);
}
