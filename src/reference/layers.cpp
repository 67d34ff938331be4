// Depth-peeled shadow-map stacks by ray tracing (layers.h).
#include "msm/reference/layers.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include <fmt/format.h>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include "internal.h"

namespace msm::reference {
namespace {

using namespace detail;

ShadowLayers trace(const scene::Scene& scene, const LayerSettings& settings) {
  const Tracer tracer(scene);
  const int size = settings.size;
  const glm::dmat4 view_projection(scene.light_view_projection());
  const glm::dmat4 inverse = glm::inverse(view_projection);
  const auto unproject = [&](double x, double y, double depth) {
    const glm::dvec4 q = inverse * glm::dvec4(x, y, depth, 1.0);
    return glm::dvec3(q) / q.w;
  };
  // Orthographic: depth is affine in the world position, with gradient g.
  const glm::dvec3 depth_gradient(view_projection[0][2], view_projection[1][2], view_projection[2][2]);
  const auto depth_of = [&](const glm::dvec3& p) {
    const glm::dvec4 q = view_projection * glm::dvec4(p, 1.0);
    return q.z / q.w;
  };
  const scene::LightFrame frame = scene.light_frame();
  const glm::dvec3 texel_x = frame.x_axis * (frame.extent.x / size), texel_y = frame.y_axis * (frame.extent.y / size);
  const glm::dvec3 towards_light = frame.towards_light;

  const auto rows_total = static_cast<std::size_t>(size);
  std::vector<std::vector<LayerHit>> rows(rows_total);
  std::vector<std::vector<std::uint32_t>> row_counts(rows_total);
  std::vector<std::size_t> row_truncated(rows_total, 0);
  tbb::parallel_for(tbb::blocked_range<int>(0, size, 1), [&](const tbb::blocked_range<int>& range) {
    for (int y = range.begin(); y != range.end(); ++y) {
      std::vector<LayerHit>& hits = rows[y];
      std::vector<std::uint32_t>& counts = row_counts[y];
      for (int x = 0; x < size; ++x) {
        const double cx = (x + 0.5) / size * 2.0 - 1.0, cy = (y + 0.5) / size * 2.0 - 1.0;
        const glm::dvec3 near = unproject(cx, cy, 0.0), far = unproject(cx, cy, 1.0);
        const double length = glm::length(far - near);
        const glm::dvec3 dir = (far - near) / length;
        glm::dvec3 origin = near;
        std::uint32_t count = 0;
        SurfaceHit hit;
        while (tracer.closest(origin, dir, length - glm::length(origin - near), hit)) {
          if (int(count) == settings.max_layers) {
            ++row_truncated[y];
            break;
          }
          LayerHit h;
          h.depth = std::clamp(depth_of(hit.p), 0.0, 1.0);
          h.object = hit.object;
          h.faces_light = glm::dot(hit.normal, towards_light) > 0.0 || tracer.material(hit).double_sided;
          // On the plane: a step o_world across the map moves along the ray by s with
          // dot(n, o_world + s dir) = 0, which changes the depth by s dot(g, dir).
          const double along = glm::dot(hit.normal, dir);
          const auto gradient = [&](const glm::dvec3& step) {
            if (std::fabs(along) < 1e-12) return kMaxDepthGradient;
            const double s = -glm::dot(hit.normal, step) / along;
            return std::clamp(s * glm::dot(depth_gradient, dir), -kMaxDepthGradient, kMaxDepthGradient);
          };
          h.depth_gradient = {gradient(texel_x), gradient(texel_y)};
          hits.push_back(h);
          ++count;
          origin = offset_origin(hit.p, hit.normal, hit.scale, dir);
        }
        counts.push_back(count);
      }
    }
  });

  ShadowLayers layers;
  layers.size = size;
  layers.offsets.reserve(std::size_t(size) * size + 1);
  layers.offsets.push_back(0);
  for (int y = 0; y < size; ++y) {
    for (std::uint32_t count : row_counts[y]) layers.offsets.push_back(layers.offsets.back() + count);
    layers.hits.insert(layers.hits.end(), rows[y].begin(), rows[y].end());
    layers.truncated_texels += row_truncated[y];
  }
  return layers;
}

} // namespace

ShadowLayers trace_layers(const scene::Scene& scene, const LayerSettings& settings) {
  if (settings.size < 1 || settings.size > kMaxLayerMapSize)
    throw std::invalid_argument(
        fmt::format("shadow map size {} is out of range [1, {}]", settings.size, kMaxLayerMapSize));
  if (settings.max_layers < 1 || settings.max_layers > kMaxLayers)
    throw std::invalid_argument(fmt::format("max layers {} is out of range [1, {}]", settings.max_layers, kMaxLayers));
  if (settings.threads < 0 || settings.threads > kMaxThreads)
    throw std::invalid_argument(fmt::format("threads {} is out of range [0, {}]", settings.threads, kMaxThreads));
  if (scene.lights.empty())
    throw std::invalid_argument("shadow layers are traced along the scene's first directional light; the scene has "
                                "none (spot and point lights only)");
  if (settings.threads == 0) return trace(scene, settings);
  tbb::task_arena arena(settings.threads);
  return arena.execute([&] { return trace(scene, settings); });
}

} // namespace msm::reference
