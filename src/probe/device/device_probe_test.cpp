// msm::probe::DeviceProbe on the Vulkan device (MSM_DEVICE; lavapipe here), validation on
// (VulkanTest: any message fails), against the CPU reference of msm::probe:
//  - the cube map resampled on the device against cube_from_equirect (same formulas of
//    light_probe.h; the device's atan/acos/division may round differently: stated tolerance);
//  - the fixed-point tables equal ProbeTables' bit for bit;
//  - the cut equals median_cut's region for region, for N in {1, ..., 7, 16, 32, 64, 256} (below 6:
//    the same groups of faces), on the procedural sky and on blender-data's studio.exr (rotated
//    too; and 512² faces for N = 1, 3, 32, 256), and the regions partition the cube;
//  - the lights agree with area_lights' of the same regions;
//  - bad input (N outside 1..256, sizes, no probe, NaN/inf/negative texels) is a ProbeError; a black probe gives no lights.
#include "msm/probe/device_probe.h"
#include "msm/test/vulkan_test.h"
#include "msm/vk/vk.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <span>

namespace {

using namespace msm::probe;
using msm::MsmAreaLight;

class DeviceProbeTest : public msm::vk::test::VulkanTest {};

const std::filesystem::path kStudio = std::filesystem::path(MSM_STUDIOLIGHTS_DIR) / "studio.exr";
const int kCounts[] = {1, 2, 3, 4, 5, 6, 7, 16, 32, 64, 256};

// A smooth panorama with a few bright texels (hot spots, as in a studio probe).
Panorama test_panorama(int width, int height) {
  Panorama p{width, height, std::vector<glm::vec3>(std::size_t(width) * height)};
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x)
      p.rgb[std::size_t(y) * width + x] =
          glm::vec3(1.0f + 0.5f * std::sin(0.1f * x), 0.5f + 0.4f * std::cos(0.17f * y), 0.2f + 0.001f * (x + y));
  p.rgb[std::size_t(height / 4) * width + width / 3] = glm::vec3(500.0f, 400.0f, 300.0f);
  p.rgb[std::size_t(height / 2) * width + 2 * width / 3] = glm::vec3(50.0f, 80.0f, 200.0f);
  return p;
}

// Largest |device − CPU| over all texels and channels, relative to the CPU texel's largest channel
// (floored at 1e-3 of the probe's largest, so that black texels do not divide by zero).
double max_relative_difference(const CubeMap& device, const CubeMap& cpu) {
  float largest = 0.0f;
  for (const auto& face : cpu.faces)
    for (const glm::vec3& t : face) largest = std::max({largest, t.x, t.y, t.z});
  double worst = 0.0;
  for (int f = 0; f < 6; ++f)
    for (std::size_t i = 0; i < cpu.faces[f].size(); ++i) {
      const glm::vec3 a = device.faces[f][i], b = cpu.faces[f][i];
      const double d = glm::length(glm::dvec3(a - b)) / std::max({b.x, b.y, b.z, 1e-3f * largest});
      worst = std::max(worst, d);
    }
  return worst;
}

// Every texel of the cube in exactly one region.
bool partitions(const std::vector<Region>& regions, int size) {
  std::vector<int> covered(6 * std::size_t(size) * size, 0);
  for (const Region& region : regions)
    for (const Region& r : region_parts(region, size))
      for (int y = r.y0; y < r.y1; ++y)
        for (int x = r.x0; x < r.x1; ++x) ++covered[(std::size_t(r.face) * size + y) * size + x];
  return std::all_of(covered.begin(), covered.end(), [](int c) { return c == 1; });
}

// The device's cut of its own cube map against the CPU's cut of the same cube map with the same
// scale (and the probe's horizon split), region for region, and their lights.
void expect_cut_equals_cpu(const DeviceProbe& probe, const char* what, float rotation_deg,
                           std::span<const int> counts = kCounts) {
  const CubeMap cube = probe.read_cube();
  const ProbeTables tables(cube, probe.scale());
  for (int n : counts) {
    const DeviceCut device = probe.run(n, rotation_deg);
    const std::vector<Region> cpu = median_cut(tables, n, probe.horizon_split());
    ASSERT_EQ(device.regions.size(), cpu.size()) << what << " N " << n;
    std::size_t differing = 0;
    for (std::size_t k = 0; k < cpu.size(); ++k) differing += !(device.regions[k] == cpu[k]);
    EXPECT_EQ(differing, 0u) << what << " N " << n << ": regions differ";
    EXPECT_TRUE(partitions(device.regions, probe.size())) << what << " N " << n;
    // Lights: the same float formula on the same sums; the device's sqrt, atan, division may
    // round differently (a few ulp), so the tolerances are a few ulp's worth, relative.
    const std::vector<MsmAreaLight> lights = area_lights(tables, cpu);
    ASSERT_EQ(device.lights.size(), lights.size()) << what << " N " << n;
    double worst_direction = 0, worst_irradiance = 0, worst_cone = 0;
    std::size_t identical = 0; // every member equal bit for bit (reported, not asserted)
    for (std::size_t k = 0; k < lights.size(); ++k) {
      const MsmAreaLight &a = device.lights[k], &b = lights[k];
      identical += a.direction == b.direction && a.x_axis == b.x_axis && a.y_axis == b.y_axis &&
                   a.half_extent == b.half_extent && a.cone_half_angle == b.cone_half_angle &&
                   a.irradiance == b.irradiance;
      worst_direction = std::max(worst_direction, double(glm::length(a.direction - b.direction)));
      const float scale = std::max({b.irradiance.x, b.irradiance.y, b.irradiance.z, 1e-30f});
      worst_irradiance = std::max(worst_irradiance, double(glm::length(a.irradiance - b.irradiance) / scale));
      worst_cone = std::max(worst_cone, double(std::abs(a.cone_half_angle - b.cone_half_angle)));
    }
    std::printf("[device-probe] %s N %d: %zu regions equal, %zu lights (%zu bit for bit): direction %.2e, irradiance "
                "%.2e (rel), cone %.2e rad\n",
                what, n, cpu.size(), lights.size(), identical, worst_direction, worst_irradiance, worst_cone);
    EXPECT_LT(worst_direction, 1e-5) << what << " N " << n;
    EXPECT_LT(worst_irradiance, 1e-5) << what << " N " << n;
    EXPECT_LT(worst_cone, 1e-5) << what << " N " << n;
  }
}

TEST_F(DeviceProbeTest, CubeMapMatchesTheCpuResampling) {
  const Panorama panoramas[] = {test_panorama(96, 48), load_equirect(kStudio)};
  const char* names[] = {"synthetic 96x48", "studio.exr"};
  for (int p = 0; p < 2; ++p)
    for (float rotation : {0.0f, 37.0f}) {
      DeviceProbe probe(ctx(), 32);
      probe.set_panorama(panoramas[p]);
      probe.run(6, rotation);
      const CubeMap device = probe.read_cube(),
                    cpu = cube_from_equirect(panoramas[p].width, panoramas[p].height, panoramas[p].rgb, 32, rotation);
      const double d = max_relative_difference(device, cpu);
      const double integral = glm::length(integrate(device) - integrate(cpu)) / glm::length(integrate(cpu));
      std::printf("[device-probe] cube map of %s, rotation %.0f°: max relative difference %.2e, ∫L dω %.2e\n", names[p],
                  rotation, d, integral);
      // Same formulas; the device's atan and division need not round correctly, which moves a
      // sample point by a few ulp of its coordinate, and the value by that much of the gradient
      // (lavapipe: up to 9.3e-4 next to the hot spots, 1.7e-5 of the integral).
      EXPECT_LT(d, 2e-3) << names[p];
      EXPECT_LT(integral, 1e-4) << names[p];
    }
}

TEST_F(DeviceProbeTest, TablesEqualTheCpuTablesBitForBit) {
  DeviceProbe probe(ctx(), 24); // not a power of two: u, v are not exact binary fractions
  probe.set_panorama(load_equirect(kStudio));
  probe.run(16, 12.5f);
  const ProbeTables tables(probe.read_cube(), probe.scale());
  std::size_t differing = 0;
  for (int face = 0; face < 6; ++face)
    for (int k = 0; k < 7; ++k) {
      const std::vector<std::uint64_t> device = probe.read_table(face, k);
      for (int y = 0; y <= 24; ++y)
        for (int x = 0; x <= 24; ++x) differing += device[std::size_t(y) * 25 + x] != tables.at(face, k, x, y);
    }
  EXPECT_EQ(differing, 0u);
}

TEST_F(DeviceProbeTest, CutOfTheSkyProbeEqualsTheCpuCut) {
  DeviceProbe probe(ctx(), 64);
  probe.set_cube(sky_probe(64));
  expect_cut_equals_cpu(probe, "sky 64", 0.0f);
}

TEST_F(DeviceProbeTest, CutOfStudioEqualsTheCpuCut) {
  const Panorama studio = load_equirect(kStudio);
  for (float rotation : {0.0f, 100.0f}) {
    DeviceProbe probe(ctx(), 64);
    probe.set_panorama(studio);
    probe.run(6, rotation); // the cube map that the cuts below start from
    expect_cut_equals_cpu(probe, rotation == 0.0f ? "studio.exr 64" : "studio.exr 64 rotated 100°", rotation);
  }
}

TEST_F(DeviceProbeTest, CutAtTheLargestBenchedFaceEqualsTheCpuCut) {
  // 512² faces (msm bench's largest): the face sums come closest to the fixed point's 2^63.
  DeviceProbe probe(ctx(), 512);
  probe.set_panorama(load_equirect(kStudio));
  probe.run(6, 45.0f);
  const int counts[] = {1, 3, 32, 256};
  expect_cut_equals_cpu(probe, "studio.exr 512 rotated 45°", 45.0f, counts);
}

// The horizon split (ten first regions) on the device: region for region the CPU's, on the sky,
// on studio.exr turned by 100° and at 512² faces; a count below ten is refused before recording.
TEST_F(DeviceProbeTest, CutWithTheHorizonSplitEqualsTheCpuCut) {
  const int counts[] = {10, 11, 16, 32, 64, 256};
  {
    DeviceProbe probe(ctx(), 64);
    probe.set_horizon_split(true);
    probe.set_cube(sky_probe(64, 30.0f));
    expect_cut_equals_cpu(probe, "sky 64 rotated 30°, horizon split", 0.0f, counts);
    EXPECT_THROW(probe.run(9), ProbeError);
    probe.set_horizon_split(false);
    EXPECT_EQ(probe.run(9).regions.size(), 9u); // the same probe without the split
  }
  const Panorama studio = load_equirect(kStudio);
  DeviceProbe probe(ctx(), 64);
  probe.set_horizon_split(true);
  probe.set_panorama(studio);
  probe.run(10, 100.0f);
  expect_cut_equals_cpu(probe, "studio.exr 64 rotated 100°, horizon split", 100.0f, counts);
  DeviceProbe large(ctx(), 512);
  large.set_horizon_split(true);
  large.set_panorama(studio);
  large.run(10, 45.0f);
  const int large_counts[] = {10, 32, 256};
  expect_cut_equals_cpu(large, "studio.exr 512 rotated 45°, horizon split", 45.0f, large_counts);
}

TEST_F(DeviceProbeTest, DeviceLightsAgreeWithTheCpuPipeline) {
  // The whole CPU pipeline (its own cube map) against the whole device pipeline: the cube maps
  // differ by rounding, so regions may move by a texel where a median is nearly tied; the light
  // that carries most energy and the total irradiance must agree.
  const Panorama studio = load_equirect(kStudio);
  DeviceProbe probe(ctx(), 64);
  probe.set_panorama(studio);
  const DeviceCut device = probe.run(32, 30.0f);
  const ProbeTables tables(cube_from_equirect(studio.width, studio.height, studio.rgb, 64, 30.0f));
  const std::vector<MsmAreaLight> cpu = area_lights(tables, median_cut(tables, 32));
  glm::dvec3 sum_device(0.0), sum_cpu(0.0);
  for (const MsmAreaLight& l : device.lights) sum_device += glm::dvec3(l.irradiance);
  for (const MsmAreaLight& l : cpu) sum_cpu += glm::dvec3(l.irradiance);
  EXPECT_LT(glm::length(sum_device - sum_cpu) / glm::length(sum_cpu), 1e-4);
  const auto brightest = [](const std::vector<MsmAreaLight>& lights) {
    return *std::max_element(lights.begin(), lights.end(), [](const MsmAreaLight& a, const MsmAreaLight& b) {
      return msm::msm_luminance(a.irradiance) < msm::msm_luminance(b.irradiance);
    });
  };
  EXPECT_LT(glm::length(brightest(device.lights).direction - brightest(cpu).direction), 1e-2);
}

// Sub-lights from the device's cuts (what `msm render --frames` does with a scene's "sub_lights"):
// the device's cuts into N and 64 regions grouped by with_sub_lights give each light the same
// sub-lights as the CPU's lights_with_sub_lights on the same cube map and scale (the regions are
// equal, so the counts per light must be; the lights agree to a few ulp as above), light_of_region
// included; a region without energy has no light on either.
TEST_F(DeviceProbeTest, SubLightsFromTheDeviceCutsEqualTheCpus) {
  DeviceProbe probe(ctx(), 32);
  probe.set_panorama(load_equirect(kStudio));
  probe.run(1); // makes the cube map and the tables' scale
  const ProbeTables tables(probe.read_cube(), probe.scale());
  for (int n : {1, 3, 6, 16}) {
    const DeviceCut coarse = probe.run(n);
    EXPECT_EQ(coarse.light_of_region, cut_lights(tables, n).light_of_region) << n;
    const std::vector<ProbeLight> device = with_sub_lights(coarse, probe.run(64));
    const std::vector<ProbeLight> cpu = lights_with_sub_lights(tables, n, 64);
    ASSERT_EQ(device.size(), cpu.size()) << n;
    for (std::size_t k = 0; k < cpu.size(); ++k) {
      ASSERT_EQ(device[k].sub_lights.size(), cpu[k].sub_lights.size()) << n << ", light " << k;
      for (std::size_t j = 0; j < cpu[k].sub_lights.size(); ++j) {
        const glm::vec3 a = device[k].sub_lights[j].irradiance, b = cpu[k].sub_lights[j].irradiance;
        EXPECT_LT(glm::length(a - b) / std::max({b.x, b.y, b.z, 1e-30f}), 1e-5f) << n << ", " << k << ", " << j;
      }
    }
  }
}

TEST_F(DeviceProbeTest, BlackProbeHasNoLights) {
  CubeMap black;
  black.size = 8;
  for (auto& face : black.faces) face.assign(64, glm::vec3(0.0f));
  DeviceProbe probe(ctx(), 8);
  probe.set_cube(black);
  const DeviceCut cut = probe.run(16);
  EXPECT_TRUE(cut.lights.empty());
  EXPECT_EQ(cut.regions, median_cut(ProbeTables(black), 16));
}

TEST_F(DeviceProbeTest, BadInputIsAProbeError) {
  EXPECT_THROW(DeviceProbe(ctx(), 0), ProbeError);
  EXPECT_THROW(DeviceProbe(ctx(), kMaxDeviceCubeSize + 1), ProbeError);
  DeviceProbe probe(ctx(), 4);
  EXPECT_THROW(probe.run(6), ProbeError); // no probe yet
  EXPECT_THROW(probe.set_cube(sky_probe(8)), ProbeError);
  EXPECT_THROW(probe.set_panorama(Panorama{4, 2, std::vector<glm::vec3>(7)}), ProbeError);
  // Texels the tables cannot hold: NaN, infinite, negative.
  for (const glm::vec3& bad : {glm::vec3(std::nanf(""), 0, 0), glm::vec3(0, INFINITY, 0), glm::vec3(0, 0, -1)}) {
    Panorama p{4, 2, std::vector<glm::vec3>(8, glm::vec3(1.0f))};
    p.rgb[5] = bad;
    EXPECT_THROW(probe.set_panorama(p), ProbeError);
    CubeMap c = sky_probe(4);
    c.faces[3][7] = bad;
    EXPECT_THROW(probe.set_cube(c), ProbeError);
  }
  probe.set_cube(sky_probe(4));
  EXPECT_THROW(probe.run(0), ProbeError);
  EXPECT_THROW(probe.run(257), ProbeError);
  // A 4² cube has 96 texels: a cut into 256 stops when every region is one texel, as the CPU's.
  const DeviceCut all = probe.run(256);
  EXPECT_EQ(all.regions.size(), 96u);
  EXPECT_EQ(all.regions, median_cut(ProbeTables(sky_probe(4)), 256));
}

} // namespace
