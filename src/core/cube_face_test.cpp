// msm/cube_face.h against directions worked out by hand, and the face's axes against the look-at
// and perspective matrices the renderer builds from them (the map's texel of a direction is its
// coordinates on the face over the half width).
#include <glm/gtc/matrix_transform.hpp>
#include <gtest/gtest.h>

#include "msm/cube_face.h"

namespace {

TEST(CubeFace, TheMajorAxisAndItsSignPickTheFace) {
  EXPECT_EQ(msm::msm_cube_face({2.0f, 1.0f, -1.5f}), 0);
  EXPECT_EQ(msm::msm_cube_face({-3.0f, 2.9f, 0.0f}), 1);
  EXPECT_EQ(msm::msm_cube_face({0.1f, 0.5f, -0.4f}), 2);
  EXPECT_EQ(msm::msm_cube_face({0.0f, -1.0f, 0.0f}), 3);
  EXPECT_EQ(msm::msm_cube_face({0.7f, -0.2f, 0.71f}), 4);
  EXPECT_EQ(msm::msm_cube_face({0.0f, 0.0f, -1e-30f}), 5);
  // Ties: x before y before z; 0 counts as positive.
  EXPECT_EQ(msm::msm_cube_face({-1.0f, 1.0f, 1.0f}), 1);
  EXPECT_EQ(msm::msm_cube_face({0.5f, -1.0f, 1.0f}), 3);
  EXPECT_EQ(msm::msm_cube_face({-0.0f, 0.0f, 0.0f}), 0);
}

TEST(CubeFace, CoordinatesAreTangentsAlongRightAndUp) {
  // +x: forward (1,0,0), up (0,1,0), right = forward × up = (0,0,1).
  glm::vec2 uv = msm::msm_cube_face_uv({2.0f, 1.0f, -1.5f}, 0);
  EXPECT_FLOAT_EQ(uv.x, -0.75f);
  EXPECT_FLOAT_EQ(uv.y, 0.5f);
  // -y: forward (0,-1,0), up (0,0,1), right = (0,-1,0) × (0,0,1) = (-1,0,0).
  uv = msm::msm_cube_face_uv({0.25f, -0.5f, 0.4f}, 3);
  EXPECT_FLOAT_EQ(uv.x, -0.5f);
  EXPECT_FLOAT_EQ(uv.y, 0.8f);
  // -z: forward (0,0,-1), up (0,1,0), right = (0,0,-1) × (0,1,0) = (1,0,0).
  uv = msm::msm_cube_face_uv({-0.3f, 0.6f, -1.2f}, 5);
  EXPECT_FLOAT_EQ(uv.x, -0.25f);
  EXPECT_FLOAT_EQ(uv.y, 0.5f);
  // On an edge between two faces the coordinate across it is ±1 on both.
  EXPECT_FLOAT_EQ(msm::msm_cube_face_uv({1.0f, 0.3f, 1.0f}, 0).x, 1.0f);
  EXPECT_FLOAT_EQ(msm::msm_cube_face_uv({1.0f, 0.3f, 1.0f}, 4).x, -1.0f);
}

TEST(CubeFace, EveryFaceIsARightHandedFrame) {
  for (int face = 0; face < 6; ++face) {
    const glm::vec3 f = msm::msm_cube_face_forward(face), u = msm::msm_cube_face_up(face),
                    r = msm::msm_cube_face_right(face);
    EXPECT_FLOAT_EQ(glm::dot(f, u), 0.0f) << face;
    EXPECT_FLOAT_EQ(glm::length(r), 1.0f) << face;
    EXPECT_EQ(msm::msm_cube_face(f), face);
    EXPECT_EQ(msm::msm_cube_face(f + 0.99f * r - 0.99f * u), face);
  }
}

// A map of 256 texels with 6 texels of guard band each side: g = 1 / (1 - 12/256); the face's
// 90-degree edge is 6 texels in from the map's.
TEST(CubeFace, TheGuardBandWidensTheFieldOfView) {
  const float g = msm::msm_cube_face_half_width(6.0f, 256.0f);
  EXPECT_FLOAT_EQ(g, 256.0f / 244.0f);
  EXPECT_FLOAT_EQ(msm::msm_cube_face_seam_texels({1.0f, 0.2f}, g, 256.0f), 0.0f);
  EXPECT_FLOAT_EQ(msm::msm_cube_face_seam_texels({-0.5f, 0.2f}, g, 256.0f), 0.5f * 122.0f);
  EXPECT_FLOAT_EQ(msm::msm_cube_face_half_width(0.0f, 256.0f), 1.0f);
}

// The renderer's face matrix: glm::lookAt along forward with the face's up and a perspective of
// 2 atan(g): a direction lands at normalized device coordinates uv / g (the shading reads the map
// there), so the face the shading picks is the face whose map holds the direction.
TEST(CubeFace, TheFaceMatrixMapsADirectionToItsCoordinatesOverTheHalfWidth) {
  const glm::vec3 light(0.5f, 2.0f, -1.0f);
  const float g = msm::msm_cube_face_half_width(4.0f, 128.0f);
  const glm::mat4 projection = glm::perspective(2.0f * std::atan(g), 1.0f, 0.01f, 10.0f);
  for (const glm::vec3& d :
       {glm::vec3(2.0f, 1.0f, -1.5f), glm::vec3(-0.2f, -0.9f, 0.85f), glm::vec3(0.3f, 0.2f, 0.4f),
        glm::vec3(-1.0f, 0.99f, -0.2f), glm::vec3(0.1f, 0.3f, -0.6f), glm::vec3(-0.5f, 0.6f, 0.1f)}) {
    const int face = msm::msm_cube_face(d);
    const glm::mat4 view = glm::lookAt(light, light + msm::msm_cube_face_forward(face), msm::msm_cube_face_up(face));
    const glm::vec4 clip = projection * view * glm::vec4(light + d, 1.0f);
    const glm::vec2 uv = msm::msm_cube_face_uv(d, face);
    EXPECT_NEAR(clip.x / clip.w, uv.x / g, 1e-5f) << face;
    EXPECT_NEAR(clip.y / clip.w, uv.y / g, 1e-5f) << face;
  }
}

} // namespace

namespace {

// A face of 256 texels, a blur of radius 4: at the map's centre every level of a 256² chain
// (to_edge 128 - 4 = 124: log2 124 - 1 = 5.95); 12 texels from the edge (a seam with a guard band
// of 12), level log2(8) - 1 = 2, whose bilinear fetch reaches 2^3 = 8 texels, to the blur's
// clamped texels and no further; at the map's edge level 0.
TEST(CubeFace, TheLookupsMipStaysWithinTheGuardBand) {
  EXPECT_NEAR(msm::msm_cube_face_max_lod({127.5f, 127.5f}, 256.0f, 4.0f), std::log2(124.0f) - 1.0f, 1e-5f);
  EXPECT_FLOAT_EQ(msm::msm_cube_face_max_lod({11.5f, 100.0f}, 256.0f, 4.0f), 2.0f);
  EXPECT_FLOAT_EQ(msm::msm_cube_face_max_lod({100.0f, 243.5f}, 256.0f, 4.0f), 2.0f);
  EXPECT_FLOAT_EQ(msm::msm_cube_face_max_lod({0.0f, 100.0f}, 256.0f, 4.0f), -1.0f);
}

} // namespace
