// Light probes: the cube-map conventions against hand-computed directions, the solid-angle weights
// (4π), resampling, the procedural probe against its closed form, the median cut's invariants,
// the area lights of known regions, the cone's cosine integral against quadrature, and a real
// probe of blender-data; cube-map crosses and faces.
#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <numeric>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "msm/image/image.h"
#include "msm/image/io.h"
#include "msm/probe/probe.h"
#include "msm/util/random.h"

using namespace msm::probe;

namespace {

constexpr double kPi = 3.14159265358979323846;

float centre(int i, int size) { return (2.0f * (float(i) + 0.5f)) / float(size) - 1.0f; }

glm::vec3 random_direction(msm::util::SplitMix64& rng) {
  for (;;) {
    const glm::dvec3 d(2 * rng.uniform() - 1, 2 * rng.uniform() - 1, 2 * rng.uniform() - 1);
    const double l = glm::length(d);
    if (l > 1e-3 && l <= 1.0) return glm::vec3(d / l);
  }
}

std::vector<glm::vec3> constant_panorama(int width, int height, glm::vec3 value) {
  return std::vector<glm::vec3>(std::size_t(width) * height, value);
}

} // namespace

TEST(CubeMap, FacesFollowVulkansTable) {
  // Face centres and corners worked out by hand from the Vulkan spec's face-selection table
  // (+X: s_c = −r_z, t_c = −r_y; +Y: s_c = r_x, t_c = r_z; +Z: s_c = r_x, t_c = −r_y; ...).
  EXPECT_EQ(msm::msm_cube_direction(0, 0, 0), glm::vec3(1, 0, 0));
  EXPECT_EQ(msm::msm_cube_direction(3, 0, 0), glm::vec3(0, -1, 0));
  EXPECT_EQ(msm::msm_cube_direction(5, 0, 0), glm::vec3(0, 0, -1));
  EXPECT_EQ(msm::msm_cube_direction(0, 1, 1), glm::vec3(1, -1, -1)); // +X, bottom right: −Z, −Y
  EXPECT_EQ(msm::msm_cube_direction(2, -1, 1), glm::vec3(-1, 1, 1)); // +Y: v along +Z
  EXPECT_EQ(msm::msm_cube_direction(4, 1, -1), glm::vec3(1, 1, 1));  // +Z: row 0 (v = −1) is up
  msm::util::SplitMix64 rng(3);
  for (int k = 0; k < 2000; ++k) {
    const glm::vec3 d = random_direction(rng);
    const msm::MsmCubeCoord c = msm::msm_cube_coord(d);
    ASSERT_LE(std::abs(c.uv.x), 1.0f);
    ASSERT_LE(std::abs(c.uv.y), 1.0f);
    const glm::vec3 back = glm::normalize(msm::msm_cube_direction(c.face, c.uv.x, c.uv.y));
    EXPECT_LT(glm::length(back - d), 1e-5f);
    // The face axes are the derivatives of the direction.
    const glm::vec3 du =
        msm::msm_cube_direction(c.face, c.uv.x + 1e-3f, c.uv.y) - msm::msm_cube_direction(c.face, c.uv.x, c.uv.y);
    const glm::vec3 dv =
        msm::msm_cube_direction(c.face, c.uv.x, c.uv.y + 1e-3f) - msm::msm_cube_direction(c.face, c.uv.x, c.uv.y);
    EXPECT_LT(glm::length(du / 1e-3f - msm::msm_cube_u_axis(c.face)), 1e-3f);
    EXPECT_LT(glm::length(dv / 1e-3f - msm::msm_cube_v_axis(c.face)), 1e-3f);
  }
}

TEST(CubeMap, WeightsOfTheSixFacesSumToFourPi) {
  // The midpoint rule's error falls as 1 / m²: bounds 0.6 / m² relative (measured 0.5 / m²).
  for (int m : {4, 16, 64, 256, 1024}) {
    double sum = 0.0;
    for (int j = 0; j < m; ++j)
      for (int i = 0; i < m; ++i) sum += msm::msm_cube_texel_weight(centre(i, m), centre(j, m), float(m));
    EXPECT_NEAR(6.0 * sum / (4.0 * kPi), 1.0, 0.6 / (double(m) * m) + 1e-6) << m;
  }
}

TEST(CubeMap, EquirectangularMappingAndRotation) {
  msm::util::SplitMix64 rng(5);
  for (int k = 0; k < 1000; ++k) {
    const glm::vec3 d = random_direction(rng);
    EXPECT_LT(glm::length(direction_of_equirect(equirect_of(d)) - d), 1e-5f);
  }
  EXPECT_LT(glm::length(direction_of_equirect({0.5f, 0.0f}) - glm::vec3(0, 1, 0)), 1e-6f);  // row 0: zenith
  EXPECT_LT(glm::length(direction_of_equirect({0.5f, 0.5f}) - glm::vec3(0, 0, -1)), 1e-6f); // centre: −Z
  EXPECT_LT(glm::length(direction_of_equirect({0.75f, 0.5f}) - glm::vec3(1, 0, 0)), 1e-6f);

  // A constant panorama gives a constant cube; a bright spot at −Z turned by 90° about +Y
  // (counter-clockwise from above) appears at −X.
  const int w = 64, h = 32;
  const CubeMap flat = cube_from_equirect(w, h, constant_panorama(w, h, glm::vec3(2, 3, 4)), 8);
  for (const auto& face : flat.faces)
    for (const glm::vec3& t : face) EXPECT_LT(glm::length(t - glm::vec3(2, 3, 4)), 1e-5f);
  std::vector<glm::vec3> spot = constant_panorama(w, h, glm::vec3(0));
  for (int y = 14; y < 18; ++y)
    for (int x = 30; x < 34; ++x) spot[y * w + x] = glm::vec3(100);
  const CubeMap turned = cube_from_equirect(w, h, spot, 16, 90.0f);
  const auto brightest = [&](const CubeMap& c) {
    glm::vec3 best_d(0);
    float best = -1;
    for (int f = 0; f < 6; ++f)
      for (int j = 0; j < c.size; ++j)
        for (int i = 0; i < c.size; ++i)
          if (c.at(f, i, j).x > best) {
            best = c.at(f, i, j).x;
            best_d = glm::normalize(msm::msm_cube_direction(f, centre(i, c.size), centre(j, c.size)));
          }
    return best_d;
  };
  EXPECT_GT(glm::dot(brightest(turned), glm::vec3(-1, 0, 0)), 0.99f);
  EXPECT_GT(glm::dot(brightest(cube_from_equirect(w, h, spot, 16)), glm::vec3(0, 0, -1)), 0.99f);
  // The procedural sky turns the same way: its sun (0.4, 0.6, −0.3) turned by 90° is at (−0.3, 0.6, −0.4).
  EXPECT_GT(glm::dot(brightest(sky_probe(64, 90.0f)), glm::normalize(glm::vec3(-0.3f, 0.6f, -0.4f))), 0.999f);
  EXPECT_GT(glm::dot(brightest(sky_probe(64)), glm::normalize(glm::vec3(0.4f, 0.6f, -0.3f))), 0.999f);
}

TEST(CubeMap, SkySunProbeIntegratesToItsClosedForm) {
  // ∫ L dω = L_sky 4π + (L_sun − L_sky) 2π (1 − cos r).
  const glm::vec3 sky(0.5f, 0.6f, 0.8f), sun(5000.0f, 4500.0f, 4000.0f);
  const float radius = glm::radians(2.0f);
  for (int size : {64, 256}) {
    const CubeMap cube = make_sky_sun_probe(size, sky, sun, glm::vec3(0.3f, 0.8f, -0.5f), radius);
    const glm::dvec3 got = integrate(cube);
    for (int c = 0; c < 3; ++c) {
      const double exact = sky[c] * 4 * kPi + (double(sun[c]) - sky[c]) * 2 * kPi * (1 - std::cos(double(radius)));
      // The weights' first-order solid angles (0.6 / m²) and the disc's edge, sampled 16² per texel.
      EXPECT_NEAR(got[c] / exact, 1.0, 0.6 / (double(size) * size) + 2e-3) << "size " << size << " channel " << c;
    }
  }
}

TEST(MedianCut, PartitionsTheProbeAndKeepsItsEnergy) {
  const CubeMap cube = make_sky_sun_probe(64, glm::vec3(0.4f, 0.5f, 0.7f), glm::vec3(3000.0f),
                                          glm::vec3(-0.2f, 0.9f, 0.3f), glm::radians(3.0f));
  const ProbeTables tables(cube);
  for (int count : {1, 2, 3, 4, 5, 6, 7, 16, 64, 256}) {
    const std::vector<Region> regions = median_cut(tables, count);
    ASSERT_EQ(int(regions.size()), count);
    std::vector<int> cover(6 * 64 * 64, 0);
    double energy = 0.0;
    for (const Region& region : regions) {
      EXPECT_EQ(region.faces != 0, count < 6 && region_parts(region, 64).size() > 1) << count;
      double parts_energy = 0.0;
      for (const Region& r : region_parts(region, 64)) {
        ASSERT_TRUE(r.x0 < r.x1 && r.y0 < r.y1 && r.x0 >= 0 && r.y0 >= 0 && r.x1 <= 64 && r.y1 <= 64);
        for (int y = r.y0; y < r.y1; ++y)
          for (int x = r.x0; x < r.x1; ++x) ++cover[(r.face * 64 + y) * 64 + x];
        parts_energy += tables.energy(r);
      }
      EXPECT_NEAR(region.energy, tables.energy(region), 1e-9 * region.energy + 1e-12);
      EXPECT_NEAR(region.energy, parts_energy, 1e-9 * region.energy + 1e-12);
      energy += region.energy;
    }
    EXPECT_TRUE(std::all_of(cover.begin(), cover.end(), [](int c) { return c == 1; })) << count;
    const glm::dvec3 total = integrate(cube);
    EXPECT_NEAR(energy, msm::msm_luminance(glm::vec3(total)), 1e-5 * energy);
    // The lights keep the probe's irradiance (XYZ round trip: 1e-3 relative).
    glm::dvec3 light_sum(0.0);
    for (const msm::MsmAreaLight& l : area_lights(tables, regions)) light_sum += glm::dvec3(l.irradiance);
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(light_sum[c] / total[c], 1.0, 1e-3) << count;
  }
}

// Sub-lights (sub_regions): every region of a finer cut lies in one region of the coarser cut of the
// same probe, and a coarse region's fine regions hold exactly its energy (fixed point, integers),
// for every coarse count 1–256 under the finer cut into 64 (or as many as the coarse) regions,
// with and without the horizon split; cuts of two different probes do not nest and are refused.
TEST(MedianCut, FinerCutsNestInCoarserOnes) {
  const CubeMap cube = make_sky_sun_probe(32, glm::vec3(0.4f, 0.5f, 0.7f), glm::vec3(3000.0f),
                                          glm::vec3(-0.2f, 0.9f, 0.3f), glm::radians(3.0f));
  const ProbeTables tables(cube);
  for (const bool split : {false, true})
    for (int count = split ? 10 : 1; count <= 256; ++count) {
      const std::vector<Region> coarse = median_cut(tables, count, split);
      const std::vector<Region> fine = median_cut(tables, std::max(count, 64), split);
      const std::vector<std::vector<int>> inside = sub_regions(coarse, fine);
      ASSERT_EQ(inside.size(), coarse.size());
      std::vector<int> seen(fine.size(), 0);
      for (std::size_t k = 0; k < coarse.size(); ++k) {
        std::uint64_t sum = 0;
        for (int j : inside[k]) sum += fine[std::size_t(j)].fixed_energy, ++seen[std::size_t(j)];
        EXPECT_EQ(sum, coarse[k].fixed_energy) << count << " regions, region " << k;
        if (count >= 64) { // the same cut
          EXPECT_EQ(inside[k], std::vector<int>{int(k)}) << count;
        }
      }
      EXPECT_TRUE(std::all_of(seen.begin(), seen.end(), [](int c) { return c == 1; })) << count;
    }
  const ProbeTables other(make_sky_sun_probe(32, glm::vec3(0.4f, 0.5f, 0.7f), glm::vec3(3000.0f),
                                             glm::vec3(0.7f, 0.2f, -0.3f), glm::radians(3.0f)));
  EXPECT_THROW(sub_regions(median_cut(tables, 16), median_cut(other, 64)), ProbeError);
}

// The horizon split (median_cut's horizon_split): the cut starts from the ten regions of
// msm_first_region (the side faces halved at their middle row, the world's horizon), and every
// region of the cut stays on one side of the horizon: on a side face, rows [0, m/2) look above it
// (v < 0 is +Y) and rows [m/2, m) below; so every lit region's light points to its own side. The
// cut still partitions the cube and keeps the energy. Without the split, the same probe's cut has
// regions across the horizon (the property is not trivially true).
TEST(MedianCut, HorizonSplitKeepsEveryRegionOnOneSideOfTheHorizon) {
  const int m = 64;
  for (float rotation : {0.0f, 37.0f}) {
    const CubeMap cube = sky_probe(m, rotation);
    const ProbeTables tables(cube);
    const auto straddles = [&](const Region& r) {
      const bool side = r.face != 2 && r.face != 3;
      return side && r.y0 < m / 2 && r.y1 > m / 2;
    };
    const std::vector<Region> plain = median_cut(tables, 16);
    EXPECT_GT(std::count_if(plain.begin(), plain.end(), straddles), 0);
    const std::vector<Region> first = median_cut(tables, kHorizonSplitMinLights, true);
    ASSERT_EQ(int(first.size()), kHorizonSplitMinLights);
    for (int k = 0; k < kHorizonSplitMinLights; ++k) {
      const msm::MsmFirstRegion f = msm::msm_first_region(k, m, true);
      EXPECT_EQ(first[k], (Region{f.face, f.rect.x, f.rect.y, f.rect.z, f.rect.w, tables.energy(first[k]),
                                  tables.fixed_energy(first[k]), 0u}))
          << k;
    }
    for (int count : {10, 11, 16, 32, 64, 256}) {
      const std::vector<Region> regions = median_cut(tables, count, true);
      ASSERT_EQ(int(regions.size()), count);
      std::vector<int> cover(6 * m * m, 0);
      double energy = 0.0;
      for (const Region& r : regions) {
        EXPECT_EQ(r.faces, 0u);
        EXPECT_FALSE(straddles(r)) << count << " lights, face " << r.face << " rows " << r.y0 << ".." << r.y1;
        for (int y = r.y0; y < r.y1; ++y)
          for (int x = r.x0; x < r.x1; ++x) ++cover[(r.face * m + y) * m + x];
        EXPECT_NEAR(r.energy, tables.energy(r), 1e-9 * r.energy + 1e-12);
        energy += r.energy;
        if (r.fixed_energy == 0) continue;
        // Its light points to its side of the horizon (±Y faces: above / below by construction).
        const bool above = r.face == 2 || (r.face != 3 && r.y1 <= m / 2);
        const msm::MsmAreaLight l = area_lights(tables, {r}).at(0);
        EXPECT_EQ(l.direction.y > 0.0f, above) << count << " lights, face " << r.face << " rows " << r.y0;
      }
      EXPECT_TRUE(std::all_of(cover.begin(), cover.end(), [](int c) { return c == 1; })) << count;
      EXPECT_NEAR(energy, msm::msm_luminance(glm::vec3(integrate(cube))), 1e-5 * energy) << count;
    }
  }
}

TEST(MedianCut, HorizonSplitRefusesFewLightsAndOddFaces) {
  const ProbeTables tables(sky_probe(16));
  for (int count : {1, 5, 6, 9}) {
    try {
      median_cut(tables, count, true);
      ADD_FAILURE() << count << " lights with the horizon split: no error";
    } catch (const ProbeError& e) { EXPECT_NE(std::string(e.what()).find("10 to 256"), std::string::npos) << e.what(); }
  }
  EXPECT_THROW(median_cut(tables, 257, true), ProbeError);
  EXPECT_EQ(median_cut(tables, 10, true).size(), 10u);
  const ProbeTables odd(sky_probe(15));
  EXPECT_THROW(median_cut(odd, 32, true), ProbeError);
  EXPECT_EQ(median_cut(odd, 32).size(), 32u); // without the split an odd size is fine
  EXPECT_THROW(probe_area_lights("sky", 15, 32, 0.0f, 1.0f, true), ProbeError);
}

// Below six lights the face regions are merged: the N cut is the N + 1 cut with the two regions
// of least energy together among those sharing a cube edge merged (checked here from the face
// energies alone), every group's faces are edge-connected, and the sun's face (the most energetic)
// stays a light of its own down to two lights.
TEST(MedianCut, FewLightsMergeTheLeastEnergeticNeighbours) {
  const CubeMap cube = sky_probe(32);
  const ProbeTables tables(cube);
  std::array<std::uint64_t, 6> face_energy{};
  int sun_face = 0;
  for (int f = 0; f < 6; ++f) {
    face_energy[f] = tables.fixed_energy(Region{f, 0, 0, 32, 32});
    if (face_energy[f] > face_energy[sun_face]) sun_face = f;
  }
  const auto mask = [](const Region& r) { return r.faces != 0 ? r.faces : 1u << r.face; };
  const auto energy_of = [&](std::uint32_t m) {
    std::uint64_t e = 0;
    for (int f = 0; f < 6; ++f)
      if (m & (1u << f)) e += face_energy[f];
    return e;
  };
  const auto neighbours = [](std::uint32_t a, std::uint32_t b) { // a face of a next to a face of b
    for (int f = 0; f < 6; ++f)
      for (int g = 0; g < 6; ++g)
        if ((a >> f & 1u) && (b >> g & 1u) &&
            msm::msm_dot_in_order(msm::msm_cube_direction(f, 0, 0), msm::msm_cube_direction(g, 0, 0)) == 0.0f)
          return true;
    return false;
  };
  std::vector<Region> finer = median_cut(tables, 6);
  for (int count = 5; count >= 1; --count) {
    const std::vector<Region> cut = median_cut(tables, count);
    ASSERT_EQ(int(cut.size()), count);
    // The expected merge: the adjacent pair of least energy together (ties: the first pair).
    int bi = -1, bj = -1;
    for (int i = 0; i < int(finer.size()); ++i)
      for (int j = i + 1; j < int(finer.size()); ++j)
        if (neighbours(mask(finer[i]), mask(finer[j])) &&
            (bi < 0 || energy_of(mask(finer[i]) | mask(finer[j])) < energy_of(mask(finer[bi]) | mask(finer[bj]))))
          bi = i, bj = j;
    ASSERT_GE(bi, 0);
    std::vector<std::uint32_t> expected;
    for (int k = 0; k < int(finer.size()); ++k)
      if (k == bi)
        expected.push_back(mask(finer[bi]) | mask(finer[bj]));
      else if (k != bj)
        expected.push_back(mask(finer[k]));
    std::vector<std::uint32_t> got;
    for (const Region& r : cut) {
      got.push_back(mask(r));
      EXPECT_EQ(r.fixed_energy, energy_of(mask(r)));
      EXPECT_EQ(r.face, std::countr_zero(mask(r))); // the lowest face names the group
      // Edge-connected: every face of a group of several has a neighbour in it.
      for (int f = 0; f < 6; ++f) {
        if (r.faces >> f & 1u) { EXPECT_TRUE(neighbours(1u << f, r.faces & ~(1u << f))) << count; }
      }
    }
    EXPECT_EQ(got, expected) << count << " lights";
    if (count >= 2) { EXPECT_TRUE(std::find(got.begin(), got.end(), 1u << sun_face) != got.end()) << count; }
    finer = cut;
  }
  EXPECT_EQ(median_cut(tables, 1)[0].faces, 63u);
}

TEST(MedianCut, SplitsAtTheEnergyMedian) {
  // Each split of a region leaves two parts whose energies differ by no more than the energy of
  // the one row or column at the cut (the median cannot fall closer on a texel grid).
  const CubeMap cube =
      make_sky_sun_probe(32, glm::vec3(1.0f), glm::vec3(50.0f), glm::vec3(1, 0.2f, 0.1f), glm::radians(10.0f));
  const ProbeTables tables(cube);
  const std::vector<Region> six = median_cut(tables, 6), seven = median_cut(tables, 7);
  // The split region is the most energetic face (+X, where the sun is).
  EXPECT_EQ(seven[0].face, 0);
  EXPECT_EQ(seven[6].face, 0);
  const Region& a = seven[0];
  const Region& b = seven[6];
  Region line = a; // the column of a next to the cut
  line.x0 = a.x1 - 1;
  EXPECT_EQ(a.x1, b.x0);
  EXPECT_LE(std::abs(a.energy - b.energy), tables.energy(line) + std::max(a.energy, b.energy) * 1e-12);
  EXPECT_NEAR(a.energy + b.energy, six[0].energy, 1e-9 * six[0].energy);
}

TEST(AreaLights, SunBecomesALightTowardsTheSun) {
  const glm::vec3 towards = glm::normalize(glm::vec3(0.3f, 0.8f, -0.5f));
  const float radius = glm::radians(2.0f);
  const glm::vec3 sun(20000.0f);
  const CubeMap cube = make_sky_sun_probe(128, glm::vec3(0.0f), sun, towards, radius);
  const ProbeTables tables(cube);
  const std::vector<msm::MsmAreaLight> lights = area_lights(tables, median_cut(tables, 16));
  // Only the sun has energy: the lights with energy point at it, and together carry its irradiance.
  double irradiance = 0.0;
  for (const msm::MsmAreaLight& l : lights) {
    EXPECT_GT(glm::dot(l.direction, towards), std::cos(radius * 1.5f));
    EXPECT_LT(l.cone_half_angle, radius * 1.5f);
    irradiance += l.irradiance.x;
  }
  const double exact = sun.x * 2 * kPi * (1 - std::cos(double(radius)));
  EXPECT_NEAR(irradiance / exact, 1.0, 5e-3);
}

TEST(AreaLights, UniformSquareRegionRecoversItsExtent) {
  // A uniform patch at the centre of +Z, 2h wide in face units: centroid (0, 0), d = h (up to the
  // texel grid's (n² − 1) / n² in the variance), tangents of angles = d at the face centre.
  const int m = 256, half = 32; // patch of 64 texels: face units h = 64 / 256 = 0.25
  CubeMap cube;
  cube.size = m;
  for (auto& f : cube.faces) f.assign(std::size_t(m) * m, glm::vec3(0.0f));
  for (int j = m / 2 - half; j < m / 2 + half; ++j)
    for (int i = m / 2 - half; i < m / 2 + half; ++i) cube.at(4, i, j) = glm::vec3(1.0f);
  const ProbeTables tables(cube);
  const Region r{4, m / 2 - half, m / 2 - half, m / 2 + half, m / 2 + half};
  const msm::MsmAreaLight l = msm::msm_area_light_from_region(4, tables.sums(r));
  EXPECT_LT(glm::length(l.direction - glm::vec3(0, 0, 1)), 1e-5f);
  // Luminance weighting by the solid angle pulls the variance in a little (the weight falls off
  // away from the centre): d within 3% of h.
  EXPECT_NEAR(l.half_extent.x, 0.25f, 0.25f * 0.03f);
  EXPECT_NEAR(l.half_extent.y, 0.25f, 0.25f * 0.03f);
  // The cone of the rectangle's solid angle: for 2t x 2t at unit distance nearly the disc of its
  // area, π tan² α = 4 t² (0.2820 against 0.2821 at t = 0.25).
  EXPECT_NEAR(std::tan(l.cone_half_angle), std::sqrt(4 * 0.25 * 0.25 / kPi), 0.03 * 0.28);
  EXPECT_NEAR(l.cone_half_angle, msm::msm_rect_light_cone_half_angle(l.half_extent), 1e-6f);
  EXPECT_LT(std::abs(glm::dot(l.x_axis, l.direction)), 1e-5f);
  EXPECT_LT(glm::length(l.x_axis - glm::vec3(1, 0, 0)), 1e-5f);  // +Z: u along +X
  EXPECT_LT(glm::length(l.y_axis - glm::vec3(0, -1, 0)), 1e-5f); // v along −Y
}

// A region's light points along the mean of its unit directions (msm_region_mean_direction), the
// direction whose cosine law gives a receiver above its horizon the region's exact irradiance,
// not along Eq. (9)'s centroid on the face plane. Here a uniform quarter of +Z ([−1, 0]², texels
// weighted by their solid angle) and the same quarter with a strip four times as bright along its
// outer edge, against the mean of the texels' unit directions summed here. Measured: 0.077° and
// 0.201° from it (the expansion's higher orders), where the face-plane centroid, projected, is
// 1.41° and 1.52° off, outwards; asserted: 1.5x those, and the centroid more than 1°. The mean is
// summed from the texels' weights and directions, not from the tables.
TEST(AreaLights, DirectionIsTheRegionsMeanDirection) {
  const int m = 64;
  for (int pattern = 0; pattern < 2; ++pattern) {
    CubeMap cube;
    cube.size = m;
    for (auto& f : cube.faces) f.assign(std::size_t(m) * m, glm::vec3(0.0f));
    const Region r{4, 0, 0, m / 2, m / 2};
    glm::dvec3 mean(0.0);
    for (int j = r.y0; j < r.y1; ++j)
      for (int i = r.x0; i < r.x1; ++i) {
        const float radiance = pattern == 0 || i < m / 8 ? 1.0f : 0.25f;
        cube.at(4, i, j) = glm::vec3(radiance);
        const float u = msm::msm_cube_face_coordinate(i, 0.5f, float(m)),
                    v = msm::msm_cube_face_coordinate(j, 0.5f, float(m));
        mean += double(msm::msm_cube_texel_weight(u, v, float(m))) * radiance *
                glm::normalize(glm::dvec3(msm::msm_cube_direction(4, u, v)));
      }
    const ProbeTables tables(cube);
    const msm::MsmRegionSums sums = tables.sums(r);
    const msm::MsmAreaLight l = msm::msm_area_light_from_region(4, sums);
    const double to_mean =
        glm::degrees(std::acos(std::min(glm::dot(glm::dvec3(l.direction), glm::normalize(mean)), 1.0)));
    const glm::vec2 centroid = sums.first / sums.xyz.y;
    const glm::dvec3 plane = glm::normalize(glm::dvec3(msm::msm_cube_direction(4, centroid.x, centroid.y)));
    const double plane_to_mean = glm::degrees(std::acos(std::min(glm::dot(plane, glm::normalize(mean)), 1.0)));
    EXPECT_LT(to_mean, 1.5 * (pattern == 0 ? 0.077 : 0.201)) << "pattern " << pattern;
    EXPECT_GT(plane_to_mean, 1.0) << "pattern " << pattern;
    std::printf("pattern %d: light %.3f deg from the mean direction, the face-plane centroid %.3f deg\n", pattern,
                to_mean, plane_to_mean);
  }
}

// The light of a group of faces (N < 6) against hand-computed answers.
TEST(AreaLights, GroupOfFacesMakesOneLight) {
  const int m = 64;
  const auto black = [&] {
    CubeMap cube;
    cube.size = m;
    for (auto& f : cube.faces) f.assign(std::size_t(m) * m, glm::vec3(0.0f));
    return cube;
  };
  // One lit face in a group: the group's light is that face's light (direction, x axis and extent,
  // irradiance; here, the lit rectangle centred in u, also its cone).
  {
    CubeMap cube = black();
    for (int j = 10; j < 30; ++j)
      for (int i = 20; i < 44; ++i) cube.at(2, i, j) = glm::vec3(1.0f, 2.0f, 3.0f);
    const ProbeTables tables(cube);
    Region group{0, 0, 0, m, m};
    group.faces = 0b000111; // +X, −X, +Y
    const msm::MsmAreaLight merged = area_lights(tables, {group}).at(0);
    const msm::MsmAreaLight face = msm::msm_area_light_from_region(2, tables.sums(Region{2, 0, 0, m, m}));
    EXPECT_LT(glm::length(merged.direction - face.direction), 1e-6f);
    EXPECT_LT(glm::length(merged.x_axis - face.x_axis), 1e-6f);
    EXPECT_NEAR(merged.half_extent.x, face.half_extent.x, 1e-6f * face.half_extent.x);
    EXPECT_EQ(merged.irradiance, face.irradiance);
    EXPECT_NEAR(merged.cone_half_angle, face.cone_half_angle, 1e-5f * face.cone_half_angle);
  }
  // Two equal small spots at the centres of +X and +Z: the light lies half way, (1, 0, 1)/√2; along
  // the axis joining them the offsets are sin 45° (σ² = 1/2 plus the spots' own spread), so the half
  // extent is sqrt(3/2) = 1.22 there, and across it the spots' own, sqrt(3) / 64 (2 texels at
  // ±1/64); the irradiances add.
  {
    CubeMap cube = black();
    for (int f : {0, 4})
      for (int j = m / 2 - 1; j < m / 2 + 1; ++j)
        for (int i = m / 2 - 1; i < m / 2 + 1; ++i) cube.at(f, i, j) = glm::vec3(1000.0f);
    const ProbeTables tables(cube);
    Region group{0, 0, 0, m, m};
    group.faces = 0b010001; // +X, +Z
    const msm::MsmAreaLight l = area_lights(tables, {group}).at(0);
    EXPECT_LT(glm::length(l.direction - glm::normalize(glm::vec3(1, 0, 1))), 1e-5f);
    const glm::vec2 t = glm::abs(glm::dot(l.x_axis, glm::normalize(glm::vec3(1, 0, -1)))) > 0.99f
                            ? l.half_extent
                            : glm::vec2(l.half_extent.y, l.half_extent.x); // (along the pair, across)
    EXPECT_NEAR(t.x, std::sqrt(1.5f), 2e-3f);
    EXPECT_NEAR(t.y, std::sqrt(3.0f) / 64.0f, 1e-4f);
    const msm::MsmAreaLight spot = msm::msm_area_light_from_region(0, tables.sums(Region{0, 0, 0, m, m}));
    EXPECT_NEAR(l.irradiance.x, 2.0f * spot.irradiance.x, 1e-6f * l.irradiance.x);
  }
  // The whole uniform sphere in one light: its directions cancel out (the most energetic face's,
  // +X of the equal ones, is taken), its cone is below a hemisphere, its irradiance is 4π L.
  {
    CubeMap cube = black();
    for (auto& f : cube.faces) f.assign(std::size_t(m) * m, glm::vec3(0.5f));
    const ProbeTables tables(cube);
    const std::vector<Region> one = median_cut(tables, 1);
    ASSERT_EQ(one.size(), 1u);
    const msm::MsmAreaLight l = area_lights(tables, one).at(0);
    EXPECT_LT(glm::length(l.direction - glm::vec3(1, 0, 0)), 1e-6f);
    EXPECT_TRUE(l.cone_half_angle > 0.0f && l.cone_half_angle < kPi / 2) << l.cone_half_angle;
    EXPECT_NEAR(l.irradiance.x, 0.5 * 4 * kPi, 2e-3 * 0.5 * 4 * kPi);
    EXPECT_TRUE(std::isfinite(l.half_extent.x) && std::isfinite(l.half_extent.y));
  }
}

// The rectangle's closed forms (msm/light_probe.h) against the midpoint rule on its plane at unit
// distance in double: Ω = ∫ dA / r³, F = ∫ dA / r⁴; the cone of the same solid angle; F / Ω in
// the point-light limit and against the disc of Eq. (18) (the paper's circular lights).
TEST(AreaLights, RectangleClosedFormsMatchQuadrature) {
  for (const glm::dvec2& t : {glm::dvec2(1e-3, 2e-3), glm::dvec2(0.05, 0.3), glm::dvec2(0.25, 0.25),
                              glm::dvec2(0.98, 0.1), glm::dvec2(0.98, 0.98)}) {
    const int k = 1000;
    double omega = 0.0, facing = 0.0;
    for (int j = 0; j < k; ++j)
      for (int i = 0; i < k; ++i) {
        const double a = ((i + 0.5) / k * 2 - 1) * t.x, b = ((j + 0.5) / k * 2 - 1) * t.y;
        const double r = std::sqrt(1 + a * a + b * b);
        omega += 1 / (r * r * r);
        facing += 1 / (r * r * r * r);
      }
    const double area = 4 * t.x * t.y / (double(k) * k);
    omega *= area;
    facing *= area;
    const glm::vec2 tf(t);
    EXPECT_NEAR(msm::msm_rect_light_solid_angle(tf), omega, 1e-5 * omega) << t.x << " x " << t.y;
    EXPECT_NEAR(msm::msm_rect_light_facing_integral(tf), facing, 1e-5 * facing) << t.x << " x " << t.y;
    EXPECT_NEAR(msm::msm_rect_light_facing_fraction(tf), facing / omega, 1e-5) << t.x << " x " << t.y;
    const double alpha = msm::msm_rect_light_cone_half_angle(tf);
    EXPECT_NEAR(2 * kPi * (1 - std::cos(alpha)), omega, 1e-5 * omega + 1e-9) << t.x << " x " << t.y;
  }
  EXPECT_EQ(msm::msm_rect_light_facing_fraction(glm::vec2(0.0f)), 1.0f); // the point light
  EXPECT_EQ(msm::msm_rect_light_cone_half_angle(glm::vec2(0.0f)), 0.0f);
  // A square and the disc of its solid angle (Eq. 18: (1 + cos α) / 2): within 0.3% up to 89° wide.
  for (double deg : {2.0, 17.0, 45.0, 89.0}) {
    const glm::vec2 t(float(std::tan(glm::radians(deg / 2))));
    const double disc = 0.5 * (1 + std::cos(msm::msm_rect_light_cone_half_angle(t)));
    EXPECT_NEAR(msm::msm_rect_light_facing_fraction(t), disc, 0.003 * disc) << deg;
  }
}

// msm_rect_light_cosine against the midpoint rule in double over the rectangle's plane at unit
// distance: ∫ max(n·p, 0) / r⁴ dA / ∫ 1 / r⁴ dA (n·ω = n·p / r, dω = dA / r³), p = ℓ + a x + b y.
// Normals all around the light, most of them straddling the horizon, for squares, a thin and a
// wide rectangle and a small light; the axis passed not orthogonal to ℓ (the function projects it
// off). The midpoint rule's error at the horizon's kink is below 1e-5 at k = 600; stated
// tolerance: 2e-5 absolute on a factor in [0, 1], plus 2e-4 relative for the thin rectangle (its
// long edges nearly cancel in single precision).
TEST(AreaLights, RectangleCosineIsTheIntegralOverTheClippedRectangle) {
  const glm::dvec3 l = glm::normalize(glm::dvec3(0.3, 0.8, -0.5));
  const glm::dvec3 x = glm::normalize(glm::cross(l, glm::dvec3(0.0, 0.0, 1.0))), y = glm::cross(l, x);
  int straddling = 0;
  for (const glm::dvec2& t : {glm::dvec2(0.02, 0.02), glm::dvec2(0.3, 0.3), glm::dvec2(0.98, 0.98),
                              glm::dvec2(1.0, 0.01), glm::dvec2(0.05, 1.5), glm::dvec2(0.4, 0.15)}) {
    const int k = 600;
    for (double theta : {0.0, 0.5, 1.2, 1.45, 1.55, 1.5708, 1.6, 1.7, 1.9, 2.3, 3.0})
      for (double phi : {0.0, 0.4, 0.785398, 1.3, 2.0, 3.5}) {
        const glm::dvec3 n =
            std::sin(theta) * std::cos(phi) * x + std::sin(theta) * std::sin(phi) * y + std::cos(theta) * l;
        double lit = 0.0, facing = 0.0;
        for (int j = 0; j < k; ++j)
          for (int i = 0; i < k; ++i) {
            const double a = ((i + 0.5) / k * 2 - 1) * t.x, b = ((j + 0.5) / k * 2 - 1) * t.y;
            const double r2 = 1 + a * a + b * b;
            lit += std::max(glm::dot(n, l + a * x + b * y), 0.0) / (r2 * r2);
            facing += 1 / (r2 * r2);
          }
        const double expected = lit / facing;
        const float got = msm::msm_rect_light_cosine(glm::vec3(n), glm::vec3(l), glm::vec3(x + 0.3 * l), glm::vec2(t));
        EXPECT_NEAR(got, expected, 2e-5 + 2e-4 * expected)
            << t.x << " x " << t.y << ", theta " << theta << " phi " << phi;
        const double reach = t.x * std::abs(glm::dot(n, x)) + t.y * std::abs(glm::dot(n, y));
        if (std::abs(glm::dot(n, l)) < reach) ++straddling;
      }
  }
  EXPECT_GT(straddling, 100); // the test is about the horizon
  // Wholly above the horizon: n·ℓ; wholly below: 0; the point-light limit: max(n·ℓ, 0).
  const glm::vec3 lf(l), xf(x), n_up = glm::normalize(lf + 0.2f * xf);
  EXPECT_NEAR(msm::msm_rect_light_cosine(n_up, lf, xf, glm::vec2(0.3f, 0.2f)), glm::dot(n_up, lf), 1e-6f);
  EXPECT_EQ(msm::msm_rect_light_cosine(-n_up, lf, xf, glm::vec2(0.3f, 0.2f)), 0.0f);
  EXPECT_EQ(msm::msm_rect_light_cosine(n_up, lf, xf, glm::vec2(0.0f)), glm::dot(n_up, lf));
  EXPECT_EQ(msm::msm_rect_light_cosine(-n_up, lf, xf, glm::vec2(0.0f)), 0.0f);
  // A line (one extent 0) is the rectangle 1e-4 wide: continuous, finite.
  const glm::vec3 n_side = glm::normalize(xf + 0.1f * lf);
  const float line = msm::msm_rect_light_cosine(n_side, lf, xf, glm::vec2(0.5f, 0.0f));
  EXPECT_NEAR(line, msm::msm_rect_light_cosine(n_side, lf, xf, glm::vec2(0.5f, 1e-4f)), 1e-6f);
  EXPECT_TRUE(std::isfinite(line) && line > 0.0f && line < 1.0f) << line;
  // Dispatch: discs (t = 0) by the cone.
  EXPECT_EQ(msm::msm_light_cosine(n_side, lf, xf, glm::vec2(0.0f), 0.3f),
            msm::msm_cone_cosine(glm::dot(n_side, lf), 0.3f));
  EXPECT_EQ(msm::msm_light_cosine(n_side, lf, xf, glm::vec2(0.5f, 0.2f), 0.3f),
            msm::msm_rect_light_cosine(n_side, lf, xf, glm::vec2(0.5f, 0.2f)));
}

// The rectangle's factor in double by another route: over a = tan u (u uniform, Simpson's rule on
// 4·10^4 panels), the integral over b of max(n·ℓ + a n·x + b n·y, 0) / (1 + a² + b²)² in closed
// form (∫ db / (k² + b²)² = b / (2k² (k² + b²)) + atan(b / k) / (2k³), ∫ b db / (k² + b²)² =
// −1 / (2 (k² + b²)), k² = 1 + a²) between ±t.y and the horizon's crossing; divided by the same
// integral for n = ℓ.
double rect_cosine_by_strips(const glm::dvec3& n_frame, const glm::dvec2& t) {
  auto strip = [&](double a) {
    const double k2 = 1 + a * a, k = std::sqrt(k2), alpha = n_frame.z + a * n_frame.x, beta = n_frame.y;
    double lo = -t.y, hi = t.y;
    if (beta > 0) lo = std::max(lo, -alpha / beta);
    if (beta < 0) hi = std::min(hi, -alpha / beta);
    if (beta == 0 && alpha < 0) return 0.0;
    if (lo >= hi) return 0.0;
    auto i0 = [&](double b) { return b / (2 * k2 * (k2 + b * b)) + std::atan(b / k) / (2 * k2 * k); };
    auto i1 = [&](double b) { return -1 / (2 * (k2 + b * b)); };
    return alpha * (i0(hi) - i0(lo)) + beta * (i1(hi) - i1(lo));
  };
  auto integral = [&](auto f) {
    const int panels = 40000;
    const double u0 = -std::atan(t.x), h = 2 * std::atan(t.x) / panels;
    double sum = 0;
    for (int i = 0; i <= panels; ++i) {
      const double u = u0 + i * h, a = std::tan(u);
      sum += (i == 0 || i == panels ? 1 : i % 2 ? 4 : 2) * f(a) * (1 + a * a);
    }
    return sum * h / 3;
  };
  const double lit = integral(strip);
  auto facing_strip = [&](double a) {
    const double k2 = 1 + a * a, k = std::sqrt(k2);
    return 2 * (t.y / (2 * k2 * (k2 + t.y * t.y)) + std::atan(t.y / k) / (2 * k2 * k));
  };
  return lit / integral(facing_strip);
}

// Wide rectangles (tan of the half extents 10 to 10^4 along one axis, 0.1 to 10 along the other),
// normals near ℓ and anywhere up to the horizon, most straddling it: the factor against the
// double-precision value above, within 2e-6, and never above 1 + 1e-6 (the double values stay at
// or below 1 + 1e-9). Formed from 3D vectors ℓ + a x + b y, the edges of such rectangles cancelled:
// errors up to 2.4e-5, factors up to 1 + 2.4e-5. (Thin ones, tan < 0.1, lose digits to the Lambert
// edges' sum itself: RectangleCosineIsTheIntegralOverTheClippedRectangle's relative tolerance.)
TEST(AreaLights, RectangleCosineOfWideRectanglesIsBoundedAndExact) {
  const glm::dvec3 l = glm::normalize(glm::dvec3(0.3, 0.8, -0.5));
  const glm::dvec3 x = glm::normalize(glm::cross(l, glm::dvec3(0.0, 0.0, 1.0))), y = glm::cross(l, x);
  msm::util::SplitMix64 rng(35);
  double worst_error = 0, worst_factor = 0, worst_exact = 0;
  int straddling = 0;
  for (int i = 0; i < 120; ++i) {
    const double wide = std::pow(10.0, 1 + 3 * rng.uniform()), narrow = std::pow(10.0, -1 + 2 * rng.uniform());
    const glm::dvec2 t = i % 2 ? glm::dvec2(wide, narrow) : glm::dvec2(narrow, wide);
    const double theta = i % 3 == 0 ? std::pow(10.0, -5 + 4 * rng.uniform()) : 1.6 * rng.uniform();
    const double phi = 2 * kPi * rng.uniform();
    const glm::dvec3 n_frame(std::sin(theta) * std::cos(phi), std::sin(theta) * std::sin(phi), std::cos(theta));
    const glm::dvec3 n = n_frame.x * x + n_frame.y * y + n_frame.z * l;
    const double reach = t.x * std::abs(n_frame.x) + t.y * std::abs(n_frame.y);
    if (std::abs(n_frame.z) < reach) ++straddling;
    const double exact = rect_cosine_by_strips(n_frame, t);
    const float got = msm::msm_rect_light_cosine(glm::vec3(n), glm::vec3(l), glm::vec3(x), glm::vec2(t));
    EXPECT_NEAR(got, exact, 2e-6) << t.x << " x " << t.y << ", theta " << theta << " phi " << phi;
    EXPECT_LE(got, 1.0f + 1e-6f) << t.x << " x " << t.y << ", theta " << theta << " phi " << phi;
    worst_error = std::max(worst_error, std::abs(got - exact));
    worst_factor = std::max(worst_factor, double(got));
    worst_exact = std::max(worst_exact, exact);
  }
  std::printf("[rectangle cosine, wide] max |error| %.2e, largest factor 1 + %.2e (exact 1 + %.2e), straddling %d\n",
              worst_error, worst_factor - 1, worst_exact - 1, straddling);
  EXPECT_LE(worst_exact, 1 + 1e-9);
  EXPECT_GT(straddling, 80);
}

// msm_light_tangent_bounds for every kind of light msm_light_cosine shades (rectangles, lines,
// rectangles whose x axis is along their direction, discs, points), 400 random lights within 50°
// of the frame's direction: every direction of the light (400 samples) lies in the rectangle of
// tangents; and msm_tangent_rect_side's verdict holds for normals on both sides of the rectangle's
// horizon boundary, 1e-4 rad away, and for random ones (above: the light's cosine is n·ℓ_k;
// below: 0). Lights reaching behind the frame's direction have no bounds.
TEST(AreaLights, TangentBoundsHoldEveryKindOfLight) {
  const glm::vec3 l = glm::normalize(glm::vec3(0.2f, 0.9f, 0.1f));
  const glm::vec3 x = glm::normalize(glm::cross(l, glm::vec3(0.0f, 0.0f, 1.0f))), y = glm::cross(l, x);
  msm::util::SplitMix64 rng(3);
  const auto uniform = [&](double lo, double hi) { return float(lo + (hi - lo) * rng.uniform()); };
  const auto around = [&](glm::vec3 axis, float max_angle) { // a direction within max_angle of axis
    const glm::vec3 u =
        glm::normalize(glm::cross(axis, std::abs(axis.x) < 0.9f ? glm::vec3(1, 0, 0) : glm::vec3(0, 1, 0)));
    const float theta = uniform(0.0, max_angle), phi = uniform(0.0, 2 * kPi);
    return glm::normalize(std::cos(theta) * axis +
                          std::sin(theta) * (std::cos(phi) * u + std::sin(phi) * glm::cross(axis, u)));
  };
  int decided = 0;
  for (int i = 0; i < 400; ++i) {
    const int kind = i % 5; // rectangle, line, x along ℓ_k, disc, point
    const glm::vec3 lk = around(l, 0.87f);
    glm::vec3 xk = glm::normalize(glm::vec3(uniform(-1, 1), uniform(-1, 1), uniform(-1, 1)));
    glm::vec2 t(uniform(0.0, 0.5), uniform(0.0, 0.5));
    float cone = 0.0f;
    if (kind == 1) t.y = 0.0f;
    if (kind == 2) xk = lk;
    if (kind >= 3) t = glm::vec2(0.0f);
    if (kind == 3) cone = uniform(0.01, 0.4);
    const glm::vec2 bounds = msm::msm_light_tangent_bounds(l, x, y, lk, xk, t, cone);
    ASSERT_GE(bounds.x, 0.0f) << i; // within 50° + 0.4 rad (+ a rectangle's corner) of ℓ: in front
    // Directions of the light as msm_light_cosine integrates it.
    const glm::vec3 px = glm::normalize(xk - lk * glm::dot(xk, lk)), py = glm::cross(lk, px);
    const glm::vec2 widened = glm::max(t, glm::vec2(1e-4f));
    for (int j = 0; j < 400; ++j) {
      glm::vec3 d = lk;
      if (kind == 0 || kind == 1) d = lk + uniform(-widened.x, widened.x) * px + uniform(-widened.y, widened.y) * py;
      if (kind == 3) d = around(lk, cone);
      const float ahead = glm::dot(d, l);
      ASSERT_GT(ahead, 0.0f);
      EXPECT_LE(std::abs(glm::dot(d, x)) / ahead, bounds.x * (1 + 1e-5f) + 1e-6f) << i << " kind " << kind;
      EXPECT_LE(std::abs(glm::dot(d, y)) / ahead, bounds.y * (1 + 1e-5f) + 1e-6f) << i << " kind " << kind;
    }
    // Normals: at the boundary n·ℓ = A |n·x| + B |n·y| (tan θ = 1 / (A |cos φ| + B |sin φ|)), 1e-4 rad
    // inside and outside of it, above and below; and random ones.
    for (int j = 0; j < 200; ++j) {
      glm::vec3 n;
      if (j < 160) {
        const float phi = uniform(0.0, 2 * kPi);
        const float edge = std::atan(1.0f / (bounds.x * std::abs(std::cos(phi)) + bounds.y * std::abs(std::sin(phi))));
        const float theta = (j % 4 < 2 ? edge : kPi - edge) + (j % 2 == 0 ? -1e-4f : 1e-4f);
        n = std::cos(theta) * l + std::sin(theta) * (std::cos(phi) * x + std::sin(phi) * y);
      } else {
        n = around(l, kPi);
      }
      const int side = msm::msm_tangent_rect_side(n, l, x, y, bounds);
      const float cosine = msm::msm_light_cosine(n, lk, xk, t, cone);
      if (side > 0) {
        EXPECT_NEAR(cosine, glm::dot(n, lk), 1e-6f) << i << " kind " << kind;
      } else if (side < 0) {
        EXPECT_LE(cosine, 1e-6f) << i << " kind " << kind;
      }
      decided += side != 0 ? 1 : 0;
    }
  }
  EXPECT_GT(decided, 400 * 200 / 4); // the test is about both verdicts
  // Behind the frame's direction: no bounds, and no verdict.
  const glm::vec2 none = msm::msm_light_tangent_bounds(l, x, y, glm::normalize(x + 0.1f * l), x, glm::vec2(0.3f), 0.0f);
  EXPECT_LT(none.x, 0.0f);
  EXPECT_EQ(msm::msm_tangent_rect_side(l, l, x, y, none), 0);
  EXPECT_LT(msm::msm_light_tangent_bounds(l, x, y, l, x, glm::vec2(0.0f), 1.6f).x, 0.0f); // a disc past 90°
}

TEST(AreaLights, ConeCosineIsTheIntegralOverTheVisibleCone) {
  // ∫_cone max(n·ω, 0) dω / (π sin² α) by quadrature in double (θ, φ about the cone's axis).
  for (double alpha : {0.02, 0.3, 0.8, 1.3}) {
    for (double angle = 0.0; angle <= kPi; angle += kPi / 24) {
      const glm::dvec3 n(std::sin(angle), 0.0, std::cos(angle)); // axis +Z
      const int nt = 400, np = 400;
      double sum = 0.0;
      for (int a = 0; a < nt; ++a) {
        const double theta = (a + 0.5) * alpha / nt;
        for (int b = 0; b < np; ++b) {
          const double phi = (b + 0.5) * 2 * kPi / np;
          const glm::dvec3 w(std::sin(theta) * std::cos(phi), std::sin(theta) * std::sin(phi), std::cos(theta));
          sum += std::max(glm::dot(n, w), 0.0) * std::sin(theta) * (alpha / nt) * (2 * kPi / np);
        }
      }
      const double expected = sum / (kPi * std::sin(alpha) * std::sin(alpha));
      EXPECT_NEAR(msm::msm_cone_cosine(float(std::cos(angle)), float(alpha)), expected, 2e-3)
          << "alpha " << alpha << " angle " << angle;
    }
  }
  EXPECT_EQ(msm::msm_cone_cosine(0.7f, 0.0f), 0.7f); // the point-light limit
  EXPECT_EQ(msm::msm_cone_cosine(-0.2f, 0.0f), 0.0f);
}

TEST(Probes, RealProbeFromBlenderData) {
  const std::filesystem::path file = std::filesystem::path(MSM_STUDIOLIGHTS_DIR) / "studio.exr";
  const CubeMap cube = load_equirect_probe(file, 64);
  ASSERT_EQ(cube.size, 64);
  const ProbeTables tables(cube);
  const std::vector<Region> regions = median_cut(tables, 32);
  const std::vector<msm::MsmAreaLight> lights = area_lights(tables, regions);
  ASSERT_EQ(lights.size(), 32u);
  const glm::dvec3 total = integrate(cube);
  glm::dvec3 sum(0.0);
  for (const msm::MsmAreaLight& l : lights) {
    EXPECT_NEAR(glm::length(l.direction), 1.0f, 1e-5f);
    EXPECT_TRUE(std::isfinite(l.cone_half_angle) && l.cone_half_angle >= 0.0f && l.cone_half_angle < 1.6f);
    sum += glm::dvec3(l.irradiance);
  }
  for (int c = 0; c < 3; ++c) EXPECT_NEAR(sum[c] / total[c], 1.0, 1e-3);
}

TEST(Probes, BadInputIsAnError) {
  EXPECT_THROW(load_equirect_probe("/nonexistent/probe.exr", 16), ProbeError);
  EXPECT_THROW(load_equirect_probe(std::filesystem::path(MSM_STUDIOLIGHTS_DIR) / "license.txt", 16), ProbeError);
  const ProbeTables tables(make_sky_sun_probe(8, glm::vec3(1), glm::vec3(2), glm::vec3(0, 1, 0), 0.1f));
  EXPECT_THROW(median_cut(tables, 0), ProbeError);
  EXPECT_THROW(median_cut(tables, -3), ProbeError);
  EXPECT_THROW(median_cut(tables, 257), ProbeError);
  EXPECT_THROW(make_sky_sun_probe(0, glm::vec3(1), glm::vec3(1), glm::vec3(0, 1, 0), 0.1f), ProbeError);
  // A 1² cube map cannot be split past its six texels: six regions.
  const ProbeTables tiny(make_sky_sun_probe(1, glm::vec3(1), glm::vec3(2), glm::vec3(0, 1, 0), 0.1f));
  EXPECT_EQ(median_cut(tiny, 20).size(), 6u);
}

// ---- Cube-map inputs: crosses and six faces ----

namespace {

// A cube whose texels are their own unit directions (as colours) plus a texel-unique offset, so
// that a misplaced or mirrored texel cannot go unnoticed.
CubeMap direction_cube(int m) {
  return make_cube(m, [m](int face, int i, int j) {
    const float u = (2.0f * float(i) + 1.0f) / float(m) - 1.0f, v = (2.0f * float(j) + 1.0f) / float(m) - 1.0f;
    return glm::normalize(msm::msm_cube_direction(face, u, v)) + glm::vec3(2.0f);
  });
}

bool same_cube(const CubeMap& a, const CubeMap& b) { return a.size == b.size && a.faces == b.faces; }

std::string message_of(const std::function<void()>& f) {
  try {
    f();
  } catch (const ProbeError& e) { return e.what(); }
  return "(no error)";
}

} // namespace

// A cross made from a known cube gives it back texel for texel (in memory and through an EXR
// file), and the layout is continuous: across every border between two face cells of the picture,
// neighbouring texels are neighbouring directions (at most 2.2 texel spacings apart, as inside a
// face), which checks each face's cell and orientation against the cube-map conventions.
TEST(CubeInputs, CrossRoundTripsAndIsContinuous) {
  const int m = 8;
  const CubeMap cube = direction_cube(m);
  const std::filesystem::path dir = std::filesystem::temp_directory_path() / "msm_probe_cross_test";
  std::filesystem::create_directories(dir);
  for (bool vertical : {false, true}) {
    const int width = (vertical ? 3 : 4) * m, height = (vertical ? 4 : 3) * m;
    const std::vector<glm::vec3> rgb = cross_of_cube(cube, vertical);
    EXPECT_TRUE(same_cube(cube_from_cross(width, height, rgb), cube)) << vertical;
    const CubeMap tagged = [&] {
      CubeMap t = cube;
      for (int face = 0; face < 6; ++face)
        for (glm::vec3& c : t.faces[face]) c = glm::vec3(float(face));
      return t;
    }();
    const std::vector<glm::vec3> tags = cross_of_cube(tagged, vertical);
    const std::vector<glm::vec3> filled = cross_of_cube(direction_cube(m), vertical);
    int borders = 0;
    double worst = 0.0;
    for (int y = 0; y < height; ++y)
      for (int x = 0; x < width; ++x)
        for (auto [dx, dy] : {std::pair(1, 0), std::pair(0, 1)}) {
          const int x2 = x + dx, y2 = y + dy;
          if (x2 >= width || y2 >= height) continue;
          const std::size_t a = std::size_t(y) * width + x, b = std::size_t(y2) * width + x2;
          if (filled[a] == glm::vec3(0.0f) || filled[b] == glm::vec3(0.0f)) continue; // an empty cell
          const double d = glm::length(glm::dvec3(filled[a] - filled[b]));
          worst = std::max(worst, d);
          borders += tags[a] != tags[b];
        }
    // Texel spacing on a face is at most 2/m radians (at its centre).
    EXPECT_LT(worst, 2.2 * 2.0 / m) << (vertical ? "vertical" : "horizontal");
    EXPECT_EQ(borders, 5 * m) << "face borders crossed"; // five borders between cells of either cross
    msm::image::Image picture(width, height, std::vector<std::string>{"R", "G", "B"});
    for (std::size_t k = 0; k < rgb.size(); ++k)
      for (int c = 0; c < 3; ++c) picture.pixels()[3 * k + c] = rgb[k][c];
    const std::filesystem::path file = dir / (vertical ? "vertical.exr" : "horizontal.exr");
    msm::image::write_exr(file, picture);
    EXPECT_TRUE(same_cube(load_probe_file(file, m), cube)) << file;
    EXPECT_TRUE(same_cube(load_probe_file(file, m / 2), downsample_cube(cube, m / 2))) << file;
    // Box filtering keeps the probe's integral to the midpoint rule's accuracy.
    const glm::dvec3 full = integrate(cube), half = integrate(load_probe_file(file, m / 2));
    EXPECT_NEAR(half.x, full.x, 0.02 * full.x);
  }
  std::filesystem::remove_all(dir);
}

// Six face files named by a "{face}" path (px nx py ny pz nz) give the cube back texel for texel, box
// filtered to a smaller size as a cross is; the file named px holds the face around +X (its centre
// texels' direction). A missing face names its file; turning them is refused.
TEST(CubeInputs, SixFaceFilesMakeTheCube) {
  const int m = 8;
  const CubeMap cube = direction_cube(m);
  const std::filesystem::path dir = std::filesystem::temp_directory_path() / "msm_probe_faces_test";
  std::filesystem::create_directories(dir);
  const std::filesystem::path pattern = dir / "sky_{face}.exr";
  ASSERT_TRUE(is_cube_faces_path(pattern));
  EXPECT_FALSE(is_cube_faces_path(dir / "sky.exr"));
  const std::array<std::filesystem::path, 6> files = cube_face_files(pattern);
  EXPECT_EQ(files[0], dir / "sky_px.exr");
  EXPECT_EQ(files[5], dir / "sky_nz.exr");
  write_cube_faces(pattern, cube);
  for (const std::filesystem::path& f : files) EXPECT_FALSE(std::filesystem::exists(f.string() + ".partial.exr"));
  EXPECT_EQ(probe_input_files(pattern), std::vector<std::filesystem::path>(files.begin(), files.end()));
  EXPECT_EQ(probe_input_files(dir / "sky.exr"), std::vector<std::filesystem::path>{dir / "sky.exr"});
  EXPECT_THROW(write_cube_faces(dir / "sky.exr", cube), ProbeError);
  const CubeMap loaded = load_probe_file(pattern, m);
  EXPECT_TRUE(same_cube(loaded, cube));
  EXPECT_TRUE(same_cube(load_probe_file(pattern, m / 2), downsample_cube(cube, m / 2)));
  // direction_cube stores direction + 2 per texel.
  const glm::vec3 centre =
      glm::normalize(0.5f * (loaded.at(0, m / 2, m / 2) + loaded.at(0, m / 2 - 1, m / 2 - 1)) - glm::vec3(2.0f));
  EXPECT_GT(centre.x, 0.99f) << "px is the +X face";
  EXPECT_NE(message_of([&] { load_probe_file(pattern, m, 10.0f); }).find("cannot be rotated"), std::string::npos);
  std::filesystem::remove(files[5]);
  EXPECT_NE(message_of([&] { load_probe_file(pattern, m); }).find("sky_nz.exr"), std::string::npos);
  std::filesystem::remove_all(dir);
}

// Six faces of one size make the cube; anything else is refused with a message naming the problem.
// The layout of a probe picture by its shape: what load_probe_file and the frame sequences read.
TEST(CubeInputs, PictureLayoutIsToldByShape) {
  EXPECT_EQ(picture_layout(64, 32), PictureLayout::panorama);
  EXPECT_EQ(picture_layout(2, 1), PictureLayout::panorama);
  EXPECT_EQ(picture_layout(16, 12), PictureLayout::cross); // horizontal, 4s x 3s
  EXPECT_EQ(picture_layout(12, 16), PictureLayout::cross); // vertical, 3s x 4s
  EXPECT_EQ(picture_layout(30, 20), PictureLayout::neither);
  EXPECT_EQ(picture_layout(32, 32), PictureLayout::neither); // a single face
  EXPECT_EQ(picture_layout(0, 0), PictureLayout::neither);
}

TEST(CubeInputs, BadLayoutsAreRefusedClearly) {
  const CubeMap cube = direction_cube(4);
  std::array<int, 6> sizes{4, 4, 4, 4, 4, 4};
  EXPECT_TRUE(same_cube(cube_from_faces(sizes, cube.faces), cube));
  sizes[3] = 2;
  EXPECT_NE(message_of([&] { cube_from_faces(sizes, cube.faces); }).find("cube face 3"), std::string::npos);
  EXPECT_NE(message_of([&] { cube_from_cross(5, 3, std::vector<glm::vec3>(15)); }).find("not a cube-map cross"),
            std::string::npos);
  EXPECT_NE(message_of([&] { cube_from_cross(16, 12, std::vector<glm::vec3>(10)); }).find("with 10 texels"),
            std::string::npos);
  EXPECT_NE(message_of([&] { downsample_cube(cube, 3); }).find("not a divisor"), std::string::npos);
  const std::filesystem::path dir = std::filesystem::temp_directory_path() / "msm_probe_bad_cross_test";
  std::filesystem::create_directories(dir);
  const std::filesystem::path odd = dir / "odd.exr", cross = dir / "cross.exr";
  msm::image::write_exr(odd, msm::image::Image(30, 20, std::vector<std::string>{"R", "G", "B"}, 1.0f));
  EXPECT_NE(message_of([&] { load_probe_file(odd, 4); }).find("is neither an equirectangular panorama"),
            std::string::npos);
  msm::image::write_exr(cross, msm::image::Image(16, 12, std::vector<std::string>{"R", "G", "B"}, 1.0f));
  EXPECT_NE(message_of([&] { load_probe_file(cross, 4, 30.0f); }).find("cannot be rotated"), std::string::npos);
  EXPECT_NE(message_of([&] { load_probe_file(cross, 3); }).find("not a divisor"), std::string::npos);
  EXPECT_THROW(load_cube_faces({odd, odd, odd, odd, odd, odd}, 4), ProbeError); // not square
  std::filesystem::remove_all(dir);
}
