// The light-probe pipeline on the device (include/msm/probe/device_probe.h); shaders in shaders/.
#include "msm/probe/device_probe.h"

#include <algorithm>
#include <cstddef>
#include <cstring>

#include <fmt/format.h>

#include "msm/vk/commands.h"
#include "shaders/probe_interface.h"

namespace msm::probe {
namespace {

static_assert(MSM_PROBE_MAX_REGIONS == kMaxDeviceLights, "probe_cut.comp's output holds every light of the cut");

constexpr int kSupersampling = 4; // cube_from_equirect's default

const VkMemoryBarrier2 kComputeToCompute = vk::memory_barrier(
    VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT, VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT,
    VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT, VK_ACCESS_2_SHADER_STORAGE_READ_BIT | VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT);

// The largest component; ProbeError for a NaN, infinite or negative one (the fixed-point tables
// and their scale need finite radiance >= 0; load_equirect clamps and checks files the same way).
float largest_component(const std::vector<glm::vec3>& texels) {
  float m = 0.0f;
  for (const glm::vec3& t : texels) {
    if (!glm::all(glm::greaterThanEqual(t, glm::vec3(0.0f))) || !glm::all(glm::lessThan(t, glm::vec3(3e38f))))
      throw ProbeError(
          fmt::format("a light probe texel of ({}, {}, {}): radiance must be finite and >= 0", t.x, t.y, t.z));
    m = std::max({m, t.x, t.y, t.z});
  }
  return m;
}

std::vector<glm::vec4> padded(const std::vector<glm::vec3>& texels) {
  std::vector<glm::vec4> out(texels.size());
  for (std::size_t i = 0; i < texels.size(); ++i) out[i] = glm::vec4(texels[i], 0.0f);
  return out;
}

} // namespace

DeviceProbe::DeviceProbe(const vk::Context& ctx, int size) : ctx_(&ctx), size_(size) {
  if (size < 1 || size > kMaxDeviceCubeSize)
    throw ProbeError(fmt::format("cube map size {} outside 1..{} on the device", size, kMaxDeviceCubeSize));
  if (!ctx.features().core.shaderInt64)
    throw ProbeError("the device has no shaderInt64: the light-probe tables are 64-bit integers");
  constexpr vk::Binding buffer = vk::Binding::storage_buffer;
  cube_ = vk::create_program(ctx, "probe_cube.comp",
                             {{MSM_BINDING_PROBE_CUBE_PANORAMA, buffer}, {MSM_BINDING_PROBE_CUBE_FACES, buffer}},
                             sizeof(ProbePush));
  rows_ = vk::create_program(ctx, "probe_table_rows.comp",
                             {{MSM_BINDING_PROBE_ROWS_CUBE, buffer},
                              {MSM_BINDING_PROBE_ROWS_WEIGHTS, buffer},
                              {MSM_BINDING_PROBE_ROWS_TABLES, buffer}},
                             sizeof(ProbePush));
  columns_ = vk::create_program(ctx, "probe_table_columns.comp", {{MSM_BINDING_PROBE_COLUMNS_TABLES, buffer}},
                                sizeof(ProbePush));
  cut_ = vk::create_program(ctx, "probe_cut.comp",
                            {{MSM_BINDING_PROBE_CUT_TABLES, buffer}, {MSM_BINDING_PROBE_CUT_RESULT, buffer}},
                            sizeof(ProbePush));
  const VkDeviceSize texels = VkDeviceSize(size) * VkDeviceSize(size);
  cube_buffer_ = vk::create_buffer(ctx, 6 * texels * sizeof(glm::vec4), VK_BUFFER_USAGE_STORAGE_BUFFER_BIT);
  tables_ = vk::create_buffer(ctx, 6 * 7 * texels * sizeof(uint64_t), VK_BUFFER_USAGE_STORAGE_BUFFER_BIT);
  result_ = vk::create_buffer(ctx, sizeof(ProbeCutResult), VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, vk::Memory::host);
  // The weights of one face's texels, then the coordinates of the texel centres (host-computed:
  // light_probe.h explains why).
  std::vector<float> weights = texel_weights(size);
  const std::vector<float> coordinates = face_coordinates(size);
  weights.insert(weights.end(), coordinates.begin(), coordinates.end());
  weights_ = vk::create_buffer(ctx, weights.size() * sizeof(float), VK_BUFFER_USAGE_STORAGE_BUFFER_BIT);
  vk::upload_buffer(ctx, weights_, std::as_bytes(std::span(weights)));
}

void DeviceProbe::set_panorama(const Panorama& p) {
  if (p.width < 2 || p.height < 1 || p.rgb.size() != std::size_t(p.width) * std::size_t(p.height))
    throw ProbeError(fmt::format("equirectangular image of {}x{} with {} texels", p.width, p.height, p.rgb.size()));
  const float largest = largest_component(p.rgb); // checks before anything changes
  const std::vector<glm::vec4> texels = padded(p.rgb);
  panorama_ = vk::create_buffer(*ctx_, texels.size() * sizeof(glm::vec4), VK_BUFFER_USAGE_STORAGE_BUFFER_BIT);
  vk::upload_buffer(*ctx_, panorama_, std::as_bytes(std::span(texels)));
  panorama_width_ = p.width;
  panorama_height_ = p.height;
  scale_ = table_scale(largest);
  has_probe_ = resample_ = true;
}

void DeviceProbe::set_cube(const CubeMap& cube) {
  if (cube.size != size_)
    throw ProbeError(fmt::format("a cube map of {}² faces for a device probe of {}²", cube.size, size_));
  float largest = 0.0f;
  for (const auto& face : cube.faces) largest = std::max(largest, largest_component(face)); // checks first
  std::vector<glm::vec4> texels;
  for (const auto& face : cube.faces) {
    const std::vector<glm::vec4> f = padded(face);
    texels.insert(texels.end(), f.begin(), f.end());
  }
  vk::upload_buffer(*ctx_, cube_buffer_, std::as_bytes(std::span(texels)));
  scale_ = table_scale(largest);
  has_probe_ = true;
  resample_ = false;
}

void DeviceProbe::record(VkCommandBuffer cmd, int count, float rotation_deg, vk::GpuTimer* timer) const {
  if (count < 1 || count > kMaxDeviceLights)
    throw ProbeError(fmt::format("{} lights: the median cut makes 1 to {}", count, kMaxDeviceLights));
  check_cut(count, size_, horizon_split_);
  if (!has_probe_) throw ProbeError("DeviceProbe::record: no probe set");
  ProbePush push{};
  push.panorama = glm::ivec2(panorama_width_, panorama_height_);
  push.size = size_;
  push.supersampling = kSupersampling;
  push.cos_sin = rotation_cos_sin(rotation_deg);
  push.scale = scale_;
  push.inv_scale = 1.0f / scale_;
  push.count = count;
  push.horizon_split = horizon_split_ ? 1 : 0;
  const uint32_t m = uint32_t(size_);
  // Earlier reads and writes of these buffers (the last frame's passes, the host's read of the
  // result) before this frame's writes.
  vk::pipeline_barrier(cmd,
                       vk::memory_barrier(VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT | VK_PIPELINE_STAGE_2_HOST_BIT,
                                          VK_ACCESS_2_MEMORY_READ_BIT | VK_ACCESS_2_MEMORY_WRITE_BIT,
                                          VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT,
                                          VK_ACCESS_2_SHADER_STORAGE_READ_BIT | VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT));
  if (resample_) {
    if (timer) timer->begin(cmd, "probe_cube");
    vk::dispatch(cmd, cube_, vk::group_count(m, 8), vk::group_count(m, 8), 6,
                 {{MSM_BINDING_PROBE_CUBE_PANORAMA, panorama_}, {MSM_BINDING_PROBE_CUBE_FACES, cube_buffer_}}, push);
    if (timer) timer->end(cmd);
    vk::pipeline_barrier(cmd, kComputeToCompute);
  }
  if (timer) timer->begin(cmd, "probe_tables");
  vk::dispatch(cmd, rows_, vk::group_count(m, 64), 6, 1,
               {{MSM_BINDING_PROBE_ROWS_CUBE, cube_buffer_},
                {MSM_BINDING_PROBE_ROWS_WEIGHTS, weights_},
                {MSM_BINDING_PROBE_ROWS_TABLES, tables_}},
               push);
  vk::pipeline_barrier(cmd, kComputeToCompute);
  vk::dispatch(cmd, columns_, vk::group_count(m, 64), 7, 6, {{MSM_BINDING_PROBE_COLUMNS_TABLES, tables_}}, push);
  if (timer) timer->end(cmd);
  vk::pipeline_barrier(cmd, kComputeToCompute);
  if (timer) timer->begin(cmd, "probe_cut");
  vk::dispatch(cmd, cut_, 1, 1, 1, {{MSM_BINDING_PROBE_CUT_TABLES, tables_}, {MSM_BINDING_PROBE_CUT_RESULT, result_}},
               push);
  if (timer) timer->end(cmd);
  vk::pipeline_barrier(cmd,
                       vk::memory_barrier(VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT, VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT,
                                          VK_PIPELINE_STAGE_2_HOST_BIT, VK_ACCESS_2_HOST_READ_BIT));
}

DeviceCut DeviceProbe::read() const {
  ProbeCutResult out;
  std::memcpy(static_cast<void*>(&out), result_.data(), sizeof(out)); // glm members: no trivial assignment, same bytes
  DeviceCut cut;
  const int n = std::min(int(out.region_count), kMaxDeviceLights);
  for (int k = 0; k < n; ++k) {
    const ProbeCutRegion& r = out.regions[k];
    Region region{r.face, r.rect.x, r.rect.y, r.rect.z, r.rect.w};
    region.fixed_energy = r.fixed_energy;
    region.faces = r.faces;
    region.energy = double(r.fixed_energy) / double(scale_);
    cut.regions.push_back(region);
    cut.light_of_region.push_back(r.lit ? int(cut.lights.size()) : -1);
    if (!r.lit) continue;
    const ProbeCutLight& l = out.lights[k];
    cut.lights.push_back(MsmAreaLight(glm::vec3(l.direction_cone), glm::vec3(l.x_axis_half_x),
                                      glm::vec3(l.y_axis_half_y), glm::vec2(l.x_axis_half_x.w, l.y_axis_half_y.w),
                                      l.direction_cone.w, glm::vec3(l.irradiance)));
  }
  return cut;
}

CubeMap DeviceProbe::read_cube() const {
  const std::size_t texels = std::size_t(size_) * std::size_t(size_);
  const std::vector<glm::vec4> all = vk::readback_buffer<glm::vec4>(*ctx_, cube_buffer_, 6 * texels);
  CubeMap cube;
  cube.size = size_;
  for (int face = 0; face < 6; ++face) {
    cube.faces[face].resize(texels);
    for (std::size_t i = 0; i < texels; ++i) cube.faces[face][i] = glm::vec3(all[face * texels + i]);
  }
  return cube;
}

std::vector<std::uint64_t> DeviceProbe::read_table(int face, int k) const {
  const std::size_t m = std::size_t(size_), texels = m * m;
  const std::vector<std::uint64_t> inclusive = vk::readback_buffer<std::uint64_t>(
      *ctx_, tables_, texels, (VkDeviceSize(face) * 7 + VkDeviceSize(k)) * texels * sizeof(std::uint64_t));
  // The device keeps inclusive sums (entry (x, y) covers [0, x] x [0, y]); ProbeTables::at's are
  // exclusive, with a zero first row and column.
  std::vector<std::uint64_t> out((m + 1) * (m + 1), 0);
  for (std::size_t y = 0; y < m; ++y)
    for (std::size_t x = 0; x < m; ++x) out[(y + 1) * (m + 1) + x + 1] = inclusive[y * m + x];
  return out;
}

DeviceCut DeviceProbe::run(int count, float rotation_deg, vk::GpuTimer* timer) const {
  vk::submit_and_wait(*ctx_, [&](VkCommandBuffer cmd) {
    if (timer) timer->reset(cmd);
    record(cmd, count, rotation_deg, timer);
  });
  return read();
}

} // namespace msm::probe
