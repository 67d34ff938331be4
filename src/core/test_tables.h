// Integer summed-area tables for the CPU tests of sat.h and soft.h, built with sat.h's
// quantization and plain uint arithmetic (wrapping modulo 2^32), independently of msm::gpu's
// build_sat_cpu (which sat_builder_test checks against the device and against 64-bit sums).
#pragma once
#include "msm/sat.h"

#include <cstddef>
#include <vector>

namespace msm::test {

struct Table {
  int width = 0, height = 0;
  std::vector<uvec4> q; // quantized texels, row-major
  std::vector<uvec4> s; // running sums S(x, y) mod 2^32
  // S(x, y); 0 where x or y is -1 (what a shader's fetch must do).
  uvec4 at(int x, int y) const {
    return (x < 0 || y < 0) ? uvec4(0u) : s[std::size_t(y) * std::size_t(width) + std::size_t(x)];
  }
  // The exact sum over texels [x0, x1] × [y0, y1] (sat.h's 4-lookup query).
  uvec4 sum(int x0, int y0, int x1, int y1) const {
    return msm_sat_rect_sum(at(x1, y1), at(x0 - 1, y1), at(x1, y0 - 1), at(x0 - 1, y0 - 1));
  }
  uvec4 sum(SatRect r) const { return sum(r.lo.x, r.lo.y, r.hi.x, r.hi.y); }
  // The 16 lookups of a fractional filter region and its box-filtered average (JCGT Fig. 7b).
  vec4 filter_average(SatFilter f, uint scale) const {
    SatSamples16 t;
    for (int j = 0; j < 4; ++j)
      for (int i = 0; i < 4; ++i) t.s[4 * j + i] = at(f.x[i], f.y[j]);
    return msm_sat_filter_average(t, f, scale);
  }
};

inline Table build(const std::vector<vec4>& map, int width, int height, uint scale) {
  Table t{width, height, std::vector<uvec4>(map.size()), std::vector<uvec4>(map.size())};
  for (std::size_t i = 0; i < map.size(); ++i) t.q[i] = msm_sat_quantize(map[i], scale);
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x)
      t.s[std::size_t(y) * std::size_t(width) + std::size_t(x)] =
          t.q[std::size_t(y) * std::size_t(width) + std::size_t(x)] + t.at(x - 1, y) + t.at(x, y - 1) -
          t.at(x - 1, y - 1);
  return t;
}

} // namespace msm::test
