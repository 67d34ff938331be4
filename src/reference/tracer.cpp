// The Embree scene of a msm::scene::Scene: one triangle geometry per object (geometry ID = object
// index), robust traversal, back faces intersected.
#include <cmath>
#include <limits>
#include <mutex>
#include <stdexcept>
#include <string>

#include <embree3/rtcore.h>
#include <fmt/format.h>

#include "internal.h"
#include "msm/image/image.h"

namespace msm::reference::detail {

struct Tracer::Impl {
  RTCDevice device = nullptr;
  RTCScene scene = nullptr;
  struct Masked { // user data of an alpha-tested geometry's filter function
    const Tracer* tracer;
    std::uint32_t object;
  };
  std::vector<Masked> masked; // reserved up front: the geometries keep pointers into it
  std::mutex error_mutex;
  std::string error;

  ~Impl() {
    if (scene) rtcReleaseScene(scene);
    if (device) rtcReleaseDevice(device);
  }
  void check(const char* what) {
    if (rtcGetDeviceError(device) == RTC_ERROR_NONE) return;
    std::lock_guard lock(error_mutex);
    throw std::runtime_error(fmt::format("Embree: {} failed: {}", what, error.empty() ? "unknown error" : error));
  }
};

namespace {

void on_embree_error(void* user, RTCError code, const char* message) {
  auto* impl = static_cast<Tracer::Impl*>(user);
  std::lock_guard lock(impl->error_mutex);
  impl->error = fmt::format("{} (code {})", message ? message : "", int(code));
}

const scene::Material& material_of(const scene::Scene& scene, std::size_t object) {
  const std::uint32_t m = scene.objects[object].material;
  return scene.materials.at(m < scene.materials.size() ? m : 0);
}

RTCRay make_ray(const glm::dvec3& origin, const glm::dvec3& dir, double tfar) {
  RTCRay ray{};
  ray.org_x = float(origin.x);
  ray.org_y = float(origin.y);
  ray.org_z = float(origin.z);
  ray.tnear = 0.0f;
  ray.dir_x = float(dir.x);
  ray.dir_y = float(dir.y);
  ray.dir_z = float(dir.z);
  ray.time = 0.0f;
  ray.tfar = std::isfinite(tfar) ? float(tfar) : std::numeric_limits<float>::infinity();
  ray.mask = 0xFFFFFFFFu;
  ray.id = 0;
  ray.flags = 0;
  return ray;
}

// Alpha testing: hits on the holes of an alpha-tested object are rejected (for closest hits and
// occlusion alike).
void mask_filter(const RTCFilterFunctionNArguments* args) {
  const auto* masked = static_cast<const Tracer::Impl::Masked*>(args->geometryUserPtr);
  for (unsigned i = 0; i < args->N; ++i) {
    if (args->valid[i] != -1) continue;
    const unsigned triangle = RTCHitN_primID(args->hit, args->N, i);
    const float u = RTCHitN_u(args->hit, args->N, i), v = RTCHitN_v(args->hit, args->N, i);
    if (!masked->tracer->solid(masked->object, triangle, u, v)) args->valid[i] = 0;
  }
}

} // namespace

Tracer::Tracer(const scene::Scene& scene) : scene_(scene), impl_(std::make_unique<Impl>()) {
  for (const scene::Material& m : scene.materials) {
    opacity_images_.push_back(scene::opacity_image(m));
    const scene::Image texels = scene::albedo_image(m);
    LinearImage& albedo = albedo_images_.emplace_back();
    albedo.width = texels.width;
    albedo.height = texels.height;
    for (std::size_t i = 0; i + 3 < texels.rgba.size(); i += 4)
      albedo.texels.emplace_back(image::srgb_to_linear(texels.rgba[i] / 255.0f),
                                 image::srgb_to_linear(texels.rgba[i + 1] / 255.0f),
                                 image::srgb_to_linear(texels.rgba[i + 2] / 255.0f));
  }
  // Refuse non-finite vertices (possible in scenes not built by the loader).
  for (const scene::Object& o : scene.objects)
    for (std::size_t i = 0; i < o.mesh.positions.size(); ++i) {
      const glm::vec3& p = o.mesh.positions[i];
      if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z))
        throw std::invalid_argument(fmt::format("object '{}': vertex {} has a NaN or infinite position", o.name, i));
    }
  if (scene.objects.size() >= std::size_t(RTC_INVALID_GEOMETRY_ID)) throw std::invalid_argument("too many objects");

  impl_->device = rtcNewDevice("verbose=0");
  if (!impl_->device)
    throw std::runtime_error(fmt::format("Embree: cannot create a device (error {})", int(rtcGetDeviceError(nullptr))));
  rtcSetDeviceErrorFunction(impl_->device, on_embree_error, impl_.get());
  if (rtcGetDeviceProperty(impl_->device, RTC_DEVICE_PROPERTY_BACKFACE_CULLING_ENABLED))
    throw std::runtime_error("Embree was built with back-face culling; the reference needs both sides");
  impl_->scene = rtcNewScene(impl_->device);
  rtcSetSceneFlags(impl_->scene, RTC_SCENE_FLAG_ROBUST);
  rtcSetSceneBuildQuality(impl_->scene, RTC_BUILD_QUALITY_HIGH);
  impl_->check("scene creation");
  impl_->masked.reserve(scene.objects.size());

  for (std::size_t id = 0; id < scene.objects.size(); ++id) {
    const scene::Mesh& mesh = scene.objects[id].mesh;
    if (mesh.triangle_count() == 0) continue;
    for (std::uint32_t index : mesh.indices)
      if (index >= mesh.positions.size())
        throw std::invalid_argument(
            fmt::format("object '{}': vertex index {} out of range", scene.objects[id].name, index));
    RTCGeometry geom = rtcNewGeometry(impl_->device, RTC_GEOMETRY_TYPE_TRIANGLE);
    auto* vertices = static_cast<float*>(rtcSetNewGeometryBuffer(geom, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3,
                                                                 3 * sizeof(float), mesh.positions.size()));
    auto* indices = static_cast<unsigned*>(rtcSetNewGeometryBuffer(geom, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3,
                                                                   3 * sizeof(unsigned), mesh.triangle_count()));
    if (!vertices || !indices) {
      rtcReleaseGeometry(geom);
      impl_->check("geometry buffers");
      throw std::runtime_error("Embree: cannot allocate geometry buffers");
    }
    for (std::size_t i = 0; i < mesh.positions.size(); ++i) {
      vertices[3 * i + 0] = mesh.positions[i].x;
      vertices[3 * i + 1] = mesh.positions[i].y;
      vertices[3 * i + 2] = mesh.positions[i].z;
    }
    for (std::size_t i = 0; i < mesh.indices.size(); ++i) indices[i] = mesh.indices[i];
    if (material_of(scene, id).masked()) {
      impl_->masked.push_back({this, std::uint32_t(id)});
      rtcSetGeometryUserData(geom, &impl_->masked.back());
      rtcSetGeometryIntersectFilterFunction(geom, mask_filter);
      rtcSetGeometryOccludedFilterFunction(geom, mask_filter);
    }
    rtcCommitGeometry(geom);
    rtcAttachGeometryByID(impl_->scene, geom, unsigned(id));
    rtcReleaseGeometry(geom);
    impl_->check("geometry");
  }
  rtcCommitScene(impl_->scene);
  impl_->check("scene build");
}

Tracer::~Tracer() = default;

bool Tracer::closest(const glm::dvec3& origin, const glm::dvec3& dir, double tfar, SurfaceHit& hit) const {
  RTCRayHit rh{};
  rh.ray = make_ray(origin, dir, tfar);
  rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
  rh.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
  RTCIntersectContext context;
  rtcInitIntersectContext(&context);
  rtcIntersect1(impl_->scene, &context, &rh);
  if (rh.hit.geomID == RTC_INVALID_GEOMETRY_ID) return false;

  hit.object = rh.hit.geomID;
  hit.incoming = dir;
  hit.triangle = rh.hit.primID;
  hit.u = rh.hit.u;
  hit.v = rh.hit.v;
  const scene::Mesh& mesh = scene_.objects[hit.object].mesh;
  const std::uint32_t* tri = &mesh.indices[3 * std::size_t(hit.triangle)];
  const glm::dvec3 v0(mesh.positions[tri[0]]), v1(mesh.positions[tri[1]]), v2(mesh.positions[tri[2]]);
  glm::dvec3 n = glm::cross(v1 - v0, v2 - v0);
  const double len = glm::length(n);
  hit.normal = len > 0.0 ? n / len : glm::dvec3(rh.hit.Ng_x, rh.hit.Ng_y, rh.hit.Ng_z);
  if (len == 0.0) hit.normal = glm::normalize(hit.normal);
  // The point: the double-precision ray meets the triangle's plane (exactly on both, up to
  // rounding); barycentric interpolation where the ray grazes the plane.
  const double cosine = glm::dot(hit.normal, dir);
  const double t = std::abs(cosine) > 1e-9 ? glm::dot(hit.normal, v0 - origin) / cosine : -1.0;
  if (std::isfinite(t) && t >= 0.0)
    hit.p = origin + t * dir;
  else
    hit.p = v0 + double(hit.u) * (v1 - v0) + double(hit.v) * (v2 - v0);
  hit.scale = std::max({point_scale(hit.p), point_scale(v0), point_scale(v1), point_scale(v2)});
  return true;
}

bool Tracer::occluded(const glm::dvec3& origin, const glm::dvec3& dir) const {
  return occluded(origin, dir, std::numeric_limits<double>::infinity());
}

bool Tracer::occluded(const glm::dvec3& origin, const glm::dvec3& dir, double tfar) const {
  RTCRay ray = make_ray(origin, dir, tfar);
  RTCIntersectContext context;
  rtcInitIntersectContext(&context);
  rtcOccluded1(impl_->scene, &context, &ray);
  return ray.tfar < 0.0f; // set to -inf on a hit
}

void Tracer::occluded(const glm::dvec3* origins, const glm::dvec3* dirs, int n, bool* blocked) const {
  for (int first = 0; first < n; first += 8) {
    const int m = std::min(8, n - first);
    alignas(32) int valid[8];
    alignas(32) RTCRay8 rays{};
    for (int j = 0; j < 8; ++j) {
      valid[j] = j < m ? -1 : 0;
      const RTCRay r = make_ray(origins[first + std::min(j, m - 1)], dirs[first + std::min(j, m - 1)],
                                std::numeric_limits<double>::infinity());
      rays.org_x[j] = r.org_x;
      rays.org_y[j] = r.org_y;
      rays.org_z[j] = r.org_z;
      rays.tnear[j] = r.tnear;
      rays.dir_x[j] = r.dir_x;
      rays.dir_y[j] = r.dir_y;
      rays.dir_z[j] = r.dir_z;
      rays.time[j] = r.time;
      rays.tfar[j] = r.tfar;
      rays.mask[j] = r.mask;
      rays.id[j] = r.id;
      rays.flags[j] = r.flags;
    }
    RTCIntersectContext context;
    rtcInitIntersectContext(&context);
    context.flags = RTC_INTERSECT_CONTEXT_FLAG_COHERENT;
    rtcOccluded8(valid, impl_->scene, &context, &rays);
    for (int j = 0; j < m; ++j) blocked[first + j] = rays.tfar[j] < 0.0f; // -inf on a hit
  }
}

void Tracer::occluded(const glm::dvec3& origin, const float* dir_x, const float* dir_y, const float* dir_z, int n,
                      bool* blocked) const {
  const glm::vec3 o(origin);
  for (int first = 0; first < n; first += 8) {
    const int m = std::min(8, n - first);
    alignas(32) int valid[8];
    alignas(32) RTCRay8 rays;
    for (int j = 0; j < 8; ++j) {
      const int i = first + std::min(j, m - 1);
      valid[j] = j < m ? -1 : 0;
      rays.org_x[j] = o.x;
      rays.org_y[j] = o.y;
      rays.org_z[j] = o.z;
      rays.tnear[j] = 0.0f;
      rays.dir_x[j] = dir_x[i];
      rays.dir_y[j] = dir_y[i];
      rays.dir_z[j] = dir_z[i];
      rays.time[j] = 0.0f;
      rays.tfar[j] = std::numeric_limits<float>::infinity();
      rays.mask[j] = 0xFFFFFFFFu;
      rays.id[j] = 0;
      rays.flags[j] = 0;
    }
    RTCIntersectContext context;
    rtcInitIntersectContext(&context);
    context.flags = RTC_INTERSECT_CONTEXT_FLAG_COHERENT;
    rtcOccluded8(valid, impl_->scene, &context, &rays);
    for (int j = 0; j < m; ++j) blocked[first + j] = rays.tfar[j] < 0.0f; // -inf on a hit
  }
}

Tracer::Transmission Tracer::transmission(const glm::dvec3& origin, const glm::dvec3& dir, int max_crossings,
                                          double tfar) const {
  Transmission result;
  glm::dvec3 o = origin;
  SurfaceHit hit;
  while (result.crossings < max_crossings) {
    ++result.rays;
    const double left = std::isfinite(tfar) ? tfar - glm::dot(o - origin, dir) : tfar;
    if (!(left > 0.0) || !closest(o, dir, left, hit)) break;
    const double alpha = opacity(hit);
    const glm::vec3 colour = material(hit).transmission_color;
    for (int c = 0; c < 3; ++c) {
      // 1 - channel_opacity(alpha)_c, in double; exactly 1 - alpha for colour 0.
      result.channels[c] *= 1.0 - alpha * (1.0 - double(colour[c]));
      if (result.channels[c] <= 0.0) result.channels[c] = 0.0;
    }
    ++result.crossings;
    if (result.channels.r == 0.0 && result.channels.g == 0.0 && result.channels.b == 0.0) break;
    // Continue from just beyond the crossed surface.
    o = offset_origin(hit.p, hit.normal, hit.scale, dir);
  }
  // The mean, written so that three equal channels give exactly that value.
  const glm::dvec3& t = result.channels;
  result.transmittance = t.r + ((t.g - t.r) + (t.b - t.r)) / 3.0;
  return result;
}

glm::dvec3 Tracer::shading_normal(const SurfaceHit& hit) const {
  const scene::Mesh& mesh = scene_.objects[hit.object].mesh;
  const std::uint32_t* tri = &mesh.indices[3 * std::size_t(hit.triangle)];
  if (mesh.normals.size() != mesh.positions.size()) return hit.normal;
  const double u = hit.u, v = hit.v;
  const glm::dvec3 n = (1.0 - u - v) * glm::dvec3(mesh.normals[tri[0]]) + u * glm::dvec3(mesh.normals[tri[1]]) +
                       v * glm::dvec3(mesh.normals[tri[2]]);
  const double len = glm::length(n);
  return len > 1e-12 ? n / len : hit.normal;
}

glm::vec2 Tracer::uv(std::uint32_t object, std::uint32_t triangle, float u, float v) const {
  const scene::Mesh& mesh = scene_.objects[object].mesh;
  if (mesh.uvs.size() != mesh.positions.size()) return glm::vec2(0.0f);
  const std::uint32_t* tri = &mesh.indices[3 * std::size_t(triangle)];
  return (1.0f - u - v) * mesh.uvs[tri[0]] + u * mesh.uvs[tri[1]] + v * mesh.uvs[tri[2]];
}

double Tracer::texture_opacity(std::uint32_t object, std::uint32_t triangle, float u, float v) const {
  const std::uint32_t index = scene_.objects[object].material;
  double alpha = material_of(scene_, object).opacity;
  if (index < opacity_images_.size() && opacity_images_[index].width > 0)
    alpha *= double(opacity_images_[index].sample(uv(object, triangle, u, v)));
  return alpha;
}

double Tracer::opacity(const SurfaceHit& hit) const {
  if (material(hit).masked()) return 1.0;
  return texture_opacity(hit.object, hit.triangle, hit.u, hit.v);
}

bool Tracer::solid(std::uint32_t object, std::uint32_t triangle, float u, float v) const {
  const scene::Material& m = material_of(scene_, object);
  // In float, as the renderer's shaders compare.
  return !m.alpha_cutoff || float(texture_opacity(object, triangle, u, v)) >= *m.alpha_cutoff; // masked()
}

glm::vec3 Tracer::albedo(const SurfaceHit& hit) const {
  const std::uint32_t index = scene_.objects[hit.object].material;
  glm::vec3 a = material(hit).albedo;
  if (index < albedo_images_.size() && albedo_images_[index].width > 0) {
    const LinearImage& image = albedo_images_[index];
    a *= scene::sample_bilinear_repeat<glm::vec3>(
        image.width, image.height, uv(hit.object, hit.triangle, hit.u, hit.v),
        [&](int i, int j) { return image.texels[std::size_t(j) * std::size_t(image.width) + std::size_t(i)]; });
  }
  return a;
}

const scene::Material& Tracer::material(const SurfaceHit& hit) const { return material_of(scene_, hit.object); }

} // namespace msm::reference::detail
