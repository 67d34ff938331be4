// msm::probe::DeviceProbe: the light-probe pipeline of Kneiphof 2017 §5 in compute, run every
// frame when a scene's probe changes (a rotation): panorama → cube map → fixed-point summed-area
// tables → median cut in one workgroup (or the merge of faces below six) → area lights. It makes the same regions as the CPU
// reference (probe.h's ProbeTables and median_cut) region for region: both build the same integer
// tables bit for bit from the same cube map (light_probe.h, msm_probe_texel) and run the same cut.
//
//   msm::probe::DeviceProbe probe(ctx, 128);
//   probe.set_panorama(msm::probe::load_equirect(file));
//   DeviceCut cut = probe.run(32, rotation_deg);    // or record() into a frame, then read()
//
// Passes (GpuTimer scopes): probe_cube (resampling, as cube_from_equirect: 4² bilinear samples per
// texel), probe_tables (rows, then columns, of 7 uint64 tables per face), probe_cut (the cut and the
// lights of its regions, one workgroup of 256 invocations). The shaders are src/probe/device/shaders.
#pragma once

#include <cstdint>
#include <vector>

#include "msm/probe/probe.h"
#include "msm/vk/context.h"
#include "msm/vk/program.h"
#include "msm/vk/resources.h"
#include "msm/vk/timer.h"

namespace msm::probe {

// Largest face size on the device: 6 x 7 uint64 tables of 1024² texels are 352 MB.
inline constexpr int kMaxDeviceCubeSize = 1024;
// Regions of one cut: one per invocation of the cut's workgroup.
inline constexpr int kMaxDeviceLights = 256;

// A cut read back from the device: the regions in median_cut's order (energy and fixed_energy
// set) and the area lights of those with energy (area_lights' order), as cut_lights makes them.
using DeviceCut = CutLights;

class DeviceProbe {
 public:
  // Throws ProbeError if the device has no shaderInt64 (the tables are uint64) or size is outside
  // 1..kMaxDeviceCubeSize.
  DeviceProbe(const vk::Context& ctx, int size);
  DeviceProbe(const DeviceProbe&) = delete;
  DeviceProbe& operator=(const DeviceProbe&) = delete;

  int size() const { return size_; }
  // The tables' fixed-point scale: table_scale of the probe's largest component.
  float scale() const { return scale_; }

  // The probe: a panorama, resampled on the device by every record(); or a cube map of size()²
  // faces, uploaded as it is (record() then does not resample and ignores the rotation). Either sets
  // scale() from its largest component (a resampled texel is an average, never above it). Throws
  // ProbeError for a panorama cube_from_equirect would refuse or a cube of another size.
  void set_panorama(const Panorama& panorama);
  void set_cube(const CubeMap& cube);

  // The cut's horizon split (median_cut's horizon_split; off by default): record() then needs
  // count >= kHorizonSplitMinLights and an even size() (ProbeError otherwise).
  void set_horizon_split(bool on) { horizon_split_ = on; }
  bool horizon_split() const { return horizon_split_; }

  // Records the passes for a cut into `count` regions of the probe turned by rotation_deg about +Y
  // (outside a render pass; the caller submits); below 6, groups of faces (median_cut). Throws
  // ProbeError for count outside [1, kMaxDeviceLights] or no probe set.
  void record(VkCommandBuffer cmd, int count, float rotation_deg = 0.0f, vk::GpuTimer* timer = nullptr) const;
  // After the recorded work completed: the cut (read from host-visible memory, no copy).
  DeviceCut read() const;
  // After the recorded work completed: the device's cube map and its tables (staging copies; for tests).
  CubeMap read_cube() const;
  // Table k (0..6) of a face as ProbeTables::at would give it, (size + 1)² entries.
  std::vector<std::uint64_t> read_table(int face, int k) const;

  // record(), submit and wait, read().
  DeviceCut run(int count, float rotation_deg = 0.0f, vk::GpuTimer* timer = nullptr) const;

 private:
  const vk::Context* ctx_;
  int size_;
  float scale_ = 1.0f;
  bool has_probe_ = false, resample_ = false, horizon_split_ = false;
  int panorama_width_ = 0, panorama_height_ = 0;
  vk::Program cube_, rows_, columns_, cut_;
  vk::Buffer panorama_, cube_buffer_, weights_, tables_, result_;
};

} // namespace msm::probe
