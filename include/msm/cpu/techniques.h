// The technique table: every shadow technique of msm in one place, with what each part of the
// toolkit needs to know of it. The per-texel math behind an id is msm/techniques.h (GLSL + C++);
// this C++ table adds names, storage and the CPU pipeline, and the renderer, the tools and the
// tests all read it (`msm techniques` prints it).
//
// The CPU pipeline runs a technique through the same stages as the GPU: per-sample generation of
// filterable channels, linear filtering (a weighted average, which is what MSAA resolve, Gaussian
// blur, mipmaps and bilinear lookups all are), the storage round trip of the texel format, and the
// reconstruction at the fragment depth. Built entirely on the single-source functions of
// include/msm/*.h. Depth-based and soft techniques (which read depth maps or summed-area tables)
// exist in the renderer only.
#pragma once
#include <array>
#include <span>
#include <string>
#include <string_view>

#include <glm/vec4.hpp>

namespace msm {

namespace cpu {
// Filterable channels of one texel; eight is the most any technique here needs.
using Texel = std::array<float, 8>;
} // namespace cpu

// Storage of one moment image in the renderer (it maps these to Vulkan formats).
enum class TexelFormat {
  none,
  r32_float,
  rg16_unorm,
  rg16_float,
  rg32_float,
  rgba16_unorm,
  rgba16_float,
  rgba32_float,
  r32_uint
};

struct Technique {
  std::string_view name;
  std::string_view description;
  int id;             // MSM_TECH_* of msm/techniques.h; -1 for the techniques only the CPU pipeline has
  int bits_per_texel; // of the filtered shadow map (depth-based: bits per depth sample)
  int channels;       // filterable channels per texel; 0 for the depth-based techniques
  // The renderer's moment images (none, none: depth-based, or not in the renderer).
  std::array<TexelFormat, 2> formats;
  std::string_view parameters; // meaning of the components of the parameter vec4 it uses
  bool rendered;               // the renderer implements it
  // CPU pipeline; null where the technique is renderer-only.
  // Channels for one depth sample; depth is the shadow map's [0,1] depth.
  cpu::Texel (*generate)(float unit_depth);
  // What writing the filtered texel to its storage format and reading it back returns.
  cpu::Texel (*store_load)(const cpu::Texel& filtered);
  // Shadow intensity in [0,1] (1 = fully shadowed) at fragment depth unit_zf in [0,1].
  float (*shade)(const cpu::Texel& stored, float unit_zf);

  bool on_cpu() const { return generate != nullptr; }
  // The papers' parameters (msm_technique_default_params); zero for the CPU-only techniques.
  glm::vec4 default_params() const;
};

// Every technique, in the order of the comparison tables.
std::span<const Technique> techniques();

// Short names for the variant one reaches for first (`msm` = the 64-bit MSM of JCGT 2017),
// accepted wherever a technique name is; outputs are named by the table's name.
struct TechniqueAlias {
  std::string_view alias;
  std::string_view technique;
};
std::span<const TechniqueAlias> technique_aliases();
// The table's name for an alias; any other name unchanged (the lookup reports it if unknown).
std::string_view canonical_technique_name(std::string_view name);
// The aliases of one technique, comma-separated ("" if none).
std::string technique_alias_list(std::string_view technique);
// " (did you mean ...?)" for an unknown name: the nearest of the given names and the aliases.
std::string technique_suggestion(std::string_view unknown, std::span<const std::string_view> names);

// The technique of that name or alias; throws std::invalid_argument listing the valid names (and
// the nearest) if unknown.
const Technique& find_technique(std::string_view name);
// The technique of an MSM_TECH_* id; throws std::invalid_argument if none has it.
const Technique& technique_by_id(int id);

namespace cpu {

// Filtered shadow for a kernel holding 'depths' with 'weights' (non-negative, any sum > 0).
// Precondition: technique.on_cpu(); else std::invalid_argument.
float filtered_shadow(const Technique& technique, std::span<const float> depths, std::span<const float> weights,
                      float unit_zf);

// The exact answer, Z(z < zf): percentage-closer filtering with the same kernel.
float percentage_closer(std::span<const float> depths, std::span<const float> weights, float unit_zf);

} // namespace cpu
} // namespace msm
