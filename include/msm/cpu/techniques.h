// Filtered hard shadows on the CPU, technique by technique, through the same stages as the GPU:
// per-sample generation of filterable channels, linear filtering (a weighted average, which is
// what MSAA resolve, Gaussian blur, mipmaps and bilinear lookups all are), the storage round trip
// of the texel format, and the reconstruction at the fragment depth. Built entirely on the
// single-source functions of include/msm/*.h.
#pragma once
#include <array>
#include <span>
#include <string>
#include <string_view>
#include <vector>

namespace msm::cpu {

// Filterable channels of one texel; eight is the most any technique here needs.
using Texel = std::array<float, 8>;

struct Technique {
  std::string_view name;
  std::string_view description;
  int bits_per_texel;
  int channels;
  // The id in the shared technique table (include/msm/techniques.h, MSM_TECH_*), which the
  // renderer uses too; -1 for the techniques only this CPU pipeline has.
  int id;
  // Channels for one depth sample; depth is the shadow map's [0,1] depth.
  Texel (*generate)(float unit_depth);
  // What writing the filtered texel to its storage format and reading it back returns.
  Texel (*store_load)(const Texel& filtered);
  // Shadow intensity in [0,1] (1 = fully shadowed) at fragment depth unit_zf in [0,1].
  float (*shade)(const Texel& stored, float unit_zf);
};

// All techniques, in the order of the comparison tables.
std::span<const Technique> techniques();
// The technique of that name; throws std::invalid_argument listing the valid names if unknown.
const Technique& find_technique(std::string_view name);

// Filtered shadow for a kernel holding 'depths' with 'weights' (non-negative, any sum > 0).
float filtered_shadow(const Technique& technique, std::span<const float> depths, std::span<const float> weights,
                      float unit_zf);

// The exact answer, Z(z < zf): percentage-closer filtering with the same kernel.
float percentage_closer(std::span<const float> depths, std::span<const float> weights, float unit_zf);

} // namespace msm::cpu
