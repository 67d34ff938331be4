// msm::reference: depth-peeled shadow-map stacks by ray tracing (2015 §3.2).
//
// The 2015 paper rendered "a series of shadow maps displaying not only the foremost surface but all
// surfaces" with the stencil buffer. Here the same stack comes from the ray tracer: through the
// centre of every texel of a size x size shadow map, a ray along the light's direction of travel
// from the near plane of the light frustum (scene::Scene::light_view_projection, Vulkan clip
// conventions: texel (x, y) at clip ((x + 0.5) / size * 2 - 1, (y + 0.5) / size * 2 - 1), row 0
// at clip y = -1) to its far plane, and every surface it crosses, front to back. Why rays and not
// rasterized depth peeling: the depths come in double precision (no 16-bit depth buffer and no
// depth-bias tuning between peels, which can lose or repeat coplanar layers), the number of
// layers costs one ray per surface instead of one render pass over the whole scene per layer,
// and it runs where the evaluation runs: on CPU cluster nodes without a GPU.
//
// Each hit is continued just beyond the surface (the offset of reference.h's shadow rays), so a
// closed mesh gives two hits (entry and exit) and k parallel planes give exactly k. Every surface
// counts, translucent or not (the stack is of hard-shadow occluders and receivers).
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

#include <glm/glm.hpp>

#include "msm/scene/scene.h"

namespace msm::reference {

struct LayerHit {
  double depth = 0.0; // light clip depth in [0, 1] (the shadow map's depth)
  // Depth change per texel along the map's x and y on the plane of the hit triangle (its
  // receiver plane; magnitude capped at kMaxDepthGradient for planes parallel to the light).
  glm::dvec2 depth_gradient{0.0};
  // The surface receives light here: the front (counter-clockwise) side of its triangle faces the
  // light, or its material is double-sided. False for the far side of a closed mesh.
  bool faces_light = false;
  std::uint32_t object = 0;
};

inline constexpr int kMaxLayerMapSize = 8192;
inline constexpr int kMaxLayers = 1024;
inline constexpr double kMaxDepthGradient = 1e3;

struct LayerSettings {
  int size = 256;      // texels per side, 1..kMaxLayerMapSize
  int max_layers = 64; // surfaces kept per texel (the nearest), 1..kMaxLayers
  int threads = 0;     // 0: TBB's default; the result does not depend on it
};

struct ShadowLayers {
  int size = 0;
  // Hits of texel (x, y), t = y * size + x, front to back: hits[offsets[t] .. offsets[t + 1]).
  std::vector<std::uint32_t> offsets;
  std::vector<LayerHit> hits;
  std::size_t truncated_texels = 0; // texels with more than max_layers surfaces (the rest dropped)
  std::span<const LayerHit> texel(int x, int y) const {
    const std::size_t t = std::size_t(y) * std::size_t(size) + std::size_t(x);
    return {hits.data() + offsets[t], hits.data() + offsets[t + 1]};
  }
};

// Throws std::invalid_argument for bad settings, a scene with non-finite vertices or without a
// directional light.
ShadowLayers trace_layers(const scene::Scene& scene, const LayerSettings& settings);

} // namespace msm::reference
