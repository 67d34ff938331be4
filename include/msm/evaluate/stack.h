// The fragments of a depth-peeled shadow-map stack and their filter kernels: the data of the 2015
// error term (2015 §3.2), built once per scene and shared by every candidate.
//
// Definitions (docs/techniques.md, "msm evaluate"):
//  - depth grid: n points z_i = i / (n - 1) on [0, 1]. The shadow map stores each depth rounded to
//    the nearest grid point (a depth buffer with n levels), so every kernel's distribution lives on
//    the grid and the LP on the grid holds it exactly; empty texels hold the far plane, z = 1.
//  - fragment: one surface of the stack (msm::reference::trace_layers) at one texel: every layer,
//    not only the first.
//  - its distribution Z: the first surfaces' (grid) depths in the filter kernel around its texel,
//    weighted by the Gaussian of msm/filter.h (taps x taps, sigma; 2015: 9 x 9, sigma 2.4 texels),
//    renormalized in double; texels beyond the map's edge repeat the edge (clamp to edge).
//  - its receiver depth zf = depth - bias with the receiver-plane bias
//      bias = min(kernel radius * (|dz/dx| + |dz/dy|) + 2 / (n - 1), max_bias),
//    the depth change of its own plane across the kernel plus two grid steps: PCF on a planar
//    receiver then never shadows the receiver itself (the "sophisticated biasing" of the 2015
//    reference, here made exact). Not capped by default (max_bias = 1): a cap brings back the
//    receiver's self-shadowing on steep receivers (a ground plane seen at an angle changes its depth
//    by 1/size per texel when it spans the depth range, so the bias is 8/size), into the
//    reference and every technique alike.
//  - cutoff: the number of grid points below zf; PCF = Z(z < zf) = the weight of the kernel's
//    grid points below the cutoff. Every technique is compared at the same zf.
//  - counted: the surface receives light (LayerHit::faces_light). Each fragment covers one texel of
//    the map, and under a directional light the power a surface receives is proportional to its
//    area in the map (2015 §3.2), so the mean of |shadow - PCF| over the counted fragments is the
//    L1 error of the irradiance over the total radiant power. The far sides of closed meshes get no
//    light and are not counted (they stay in the stack: they are surfaces).
#pragma once

#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "msm/evaluate/grid_lp.h"
#include "msm/reference/layers.h"
#include "msm/scene/scene.h"

namespace msm::evaluate {

inline constexpr int kMaxGridPoints = 1 << 16;

struct StackSettings {
  int size = 128;      // shadow map texels per side
  int grid = 1025;     // depth grid points n, 2..kMaxGridPoints
  int filter_taps = 9; // msm/filter.h
  float filter_sigma = 2.4f;
  int max_layers = 64;   // surfaces kept per texel
  double max_bias = 1.0; // cap of the receiver-plane bias, depth units (1: none)
  int threads = 0;       // ray tracing threads (0: all); no effect on the result
};
// Throws std::invalid_argument naming the bad setting.
void validate(const StackSettings& settings);

struct Fragment {
  std::int32_t texel = 0; // y * size + x
  std::int32_t layer = 0; // 0 = the first surface
  std::int32_t cutoff = 0;
  double receiver = 0.0; // zf in [0,1] depth (after the bias)
  double pcf = 0.0;      // Z(z < zf)
  bool counted = false;
};

struct StackStats {
  std::int64_t texels = 0, covered_texels = 0, fragments = 0, counted = 0, lit = 0, bias_capped = 0;
  std::int64_t truncated_texels = 0, max_layers = 0;
};

struct Stack {
  std::string name; // the scene's name as given
  StackSettings settings;
  // The kernel distribution of texel t: atoms[kernel_offsets[t] .. kernel_offsets[t + 1]), by
  // ascending grid index, one atom per index.
  std::vector<std::uint32_t> kernel_offsets;
  std::vector<GridAtom> atoms;
  std::vector<Fragment> fragments; // by texel, then front to back
  StackStats stats;

  std::span<const GridAtom> kernel(std::int32_t texel) const {
    return {atoms.data() + kernel_offsets[texel], atoms.data() + kernel_offsets[texel + 1]};
  }
  double grid_depth(std::int32_t index) const { return double(index) / double(settings.grid - 1); }
  // 64-bit FNV-1a of the serialized stack: what a checkpoint was computed from.
  std::uint64_t fingerprint() const;
  std::vector<char> serialize() const;
  static Stack deserialize(std::span<const char> bytes); // throws std::runtime_error if malformed
};

// The stack of already traced layers (the tests build layers by hand).
Stack make_stack(std::string name, const reference::ShadowLayers& layers, const StackSettings& settings);
// Traces the scene's layers (reference::trace_layers) and builds the stack.
Stack build_stack(std::string name, const scene::Scene& scene, const StackSettings& settings);

// The kernel's normalized 2D weights (taps x taps, row-major), from msm/filter.h in double.
std::vector<double> kernel_weights(int taps, float sigma);

} // namespace msm::evaluate
