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
#include <functional>
#include <map>
#include <span>
#include <string>
#include <string_view>
#include <vector>

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

// Widths W of the soft shadows' kernels (the blocker search and the filter cover up to W x W texels).
inline constexpr int kSatKernelDefault = 27;  // summed-area tables: JCGT §4.5's 27² search region
inline constexpr int kSatKernelMax = 255;     // the tables' widest
inline constexpr int kPcssKernelDefault = 15; // the PCSS baseline's 15² search
inline constexpr int kPcssKernelMax = 63;     // 63² taps per pixel and loop

// A technique's parameter: named, typed, ranged and explained here, set by name everywhere (the
// CLI's --set NAME=VALUE, view files, JSON outputs, the viewer's panel). Its value travels to the
// shaders as one component (`slot`) of the technique's parameter vec4 (msm/techniques.h), which no
// user sees.
enum class ParameterType {
  number,  // a real value in [min, max]
  integer, // a whole number in [min, max]
  flag,    // off (0) or on (1)
  choice   // one of `choices`, by name
};

struct ParameterChoice {
  std::string_view name;
  float value; // what the shader reads
  std::string_view meaning;
};

struct Parameter {
  std::string_view name{}; // empty: no parameter
  ParameterType type = ParameterType::number;
  int slot = 0; // component of the parameter vec4: 0 = x ... 3 = w
  float default_value = 0.0f;
  float min = 0.0f, max = 0.0f; // the range of number and integer parameters
  bool min_open = false;        // min itself excluded
  bool max_open = false;        // max itself excluded
  std::span<const ParameterChoice> choices{};
  std::string_view meaning{}; // one line

  bool declared() const { return !name.empty(); }
  // Whether v is a value of this parameter (finite, in range, whole, a choice's value).
  bool accepts(float v) const;
  // "[0, 1]", "(0, 1]", "integer in [0, 16]", "on or off", "proportional, fixed or adaptive".
  std::string range_text() const;
  // The value as a user writes it: a choice's name, "on"/"off", an integer, a number.
  std::string value_text(float v) const;
  // The value of a text (a choice's name or value, "on"/"off"/"true"/"false"/"1"/"0", a number);
  // std::invalid_argument saying what the parameter takes if it is none or out of range.
  float parse(std::string_view text) const;
};

// How the renderer makes a technique's shadow map (src/render/recipes.cpp).
enum class Recipe {
  cpu_only,           // not in the renderer
  depth_map,          // reads the depth map itself (no filterable channels)
  filtered_moments,   // moments resolved, blurred (or the one-pass filter), mipmapped: linear filtering
  nonlinear_moments,  // the one-pass filter stores Φ of the filtered moments: decoded before interpolation
  summed_area_tables, // moments in integer summed-area tables instead of blur and mips
};

// The shading's fragment shader family (src/render/passes/shading_pass.cpp).
enum class ShadingVariant { none, depth, moments, nl64, nl32, soft };

// Single scattering in the scene's medium after the shading (src/render/passes/scattering_pass.cpp).
enum class Scattering { none, march, prefiltered_moments, prefiltered_csm };

struct Technique {
  std::string_view name;
  std::string_view description;
  int id = -1;            // MSM_TECH_* of msm/techniques.h; -1 for the techniques only the CPU pipeline has
  int bits_per_texel = 0; // of the filtered shadow map (depth-based: bits per depth sample)
  int channels = 0;       // filterable channels per texel; 0 for the depth-based techniques
  // The renderer's moment images (none, none: depth-based, or not in the renderer).
  std::array<TexelFormat, 2> formats = {TexelFormat::none, TexelFormat::none};
  Recipe recipe = Recipe::cpu_only;
  ShadingVariant shading = ShadingVariant::none;
  Scattering scattering = Scattering::none;
  // Categories the renderer asks about.
  bool area_light = false;               // the penumbra follows the light's extent (soft techniques, PCSS)
  bool six_moments = false;              // the texel's b half (msm/techniques.h layout) in a second image
  bool translucency = false;             // blends translucent occluders into its map (JCGT §3)
  bool deferred_shading_default = false; // a per-pixel filter: deferred shading by default
  int default_soft_kernel = 0;           // area-light techniques: the kernel width W when none is given
  int max_soft_kernel = 0;               // and the widest they take
  // Subtracted from the fragment's [0,1] depth unless the settings give one (config.h says why).
  float depth_bias = 0.0f;
  // Named parameters; the techniques without any leave them undeclared. Their defaults are the
  // papers' (msm_technique_default_params, which the shaders' tests read).
  std::array<Parameter, 4> parameters{};
  // CPU pipeline; null where the technique is renderer-only.
  // Channels for one depth sample; depth is the shadow map's [0,1] depth.
  cpu::Texel (*generate)(float unit_depth) = nullptr;
  // What writing the filtered texel to its storage format and reading it back returns.
  cpu::Texel (*store_load)(const cpu::Texel& filtered) = nullptr;
  // Shadow intensity in [0,1] (1 = fully shadowed) at fragment depth unit_zf in [0,1].
  float (*shade)(const cpu::Texel& stored, float unit_zf) = nullptr;

  bool on_cpu() const { return generate != nullptr; }
  bool rendered() const { return recipe != Recipe::cpu_only; }
  bool depth_based() const { return recipe == Recipe::depth_map; }
  bool nonlinear() const { return recipe == Recipe::nonlinear_moments; }
  bool soft() const { return recipe == Recipe::summed_area_tables; } // soft shadows from summed-area tables
  bool one_pass_default() const { return nonlinear(); }              // the one-pass filter unless told otherwise
  bool deferred_shading_supported() const { return depth_based() || soft(); }
  bool mipmapped() const { return recipe == Recipe::filtered_moments; } // a mip chain of the moment images
  bool scatters() const { return scattering != Scattering::none; }
  bool prefiltered_scattering() const {
    return scattering == Scattering::prefiltered_moments || scattering == Scattering::prefiltered_csm;
  }
  // The declared parameters, in slot order.
  std::vector<const Parameter*> parameter_list() const;
  bool has_parameter(std::string_view name) const;
  // The parameter of that name; std::invalid_argument with the names it has (and the nearest).
  const Parameter& parameter(std::string_view name) const;
  // The papers' parameters as the shader's vec4 (msm_technique_default_params); zero for the CPU-only
  // techniques.
  glm::vec4 default_params() const;
};

// Values of a technique's parameters by name; those not given take their defaults.
using ParameterValues = std::map<std::string, float, std::less<>>;

// The shader's parameter vec4 of these values: the defaults with each given one in its slot;
// std::invalid_argument naming the parameter if one is unknown or out of its range.
glm::vec4 parameter_vector(const Technique& technique, const ParameterValues& values);
// The value of one parameter among these (its default if not given).
float parameter_value(const Technique& technique, const ParameterValues& values, std::string_view name);
// Parses NAME=VALUE against the technique's declarations into values (std::invalid_argument naming
// the problem: no '=', an unknown name with the nearest, a value out of range).
void set_parameter(const Technique& technique, ParameterValues& values, std::string_view assignment);

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
