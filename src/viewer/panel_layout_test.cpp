#include "panel_layout.h"

#include <gtest/gtest.h>

namespace msm::viewer {
namespace {

TEST(PanelLayout, WholePanelInLargeWindows) {
  for (auto [w, h] : {std::pair{1280.0f, 720.0f}, {1920.0f, 1080.0f}, {3840.0f, 2160.0f}}) {
    PanelLayout p = panel_layout(w, h);
    EXPECT_EQ(p.scale, 1.0f) << w << "x" << h;
    EXPECT_EQ(p.width, kPanelWidth) << w << "x" << h;
    EXPECT_FALSE(p.collapsed) << w << "x" << h;
  }
}

// A 640x360 window: the panel once covered 380 of its 640 columns (59 %).
TEST(PanelLayout, SmallWindowsGetANarrowerCollapsedPanel) {
  PanelLayout p = panel_layout(640, 360);
  EXPECT_TRUE(p.collapsed);
  EXPECT_LE(p.width, 0.4f * 640);
  EXPECT_GE(p.scale, kPanelMinScale);
  EXPECT_LT(p.scale, 1.0f);
  for (float w = 160; w <= 4096; w += 16)
    for (float h = 120; h <= 2160; h += 24) {
      PanelLayout q = panel_layout(w, h);
      ASSERT_LE(q.width, kPanelMaxWindowShare * w) << w << "x" << h;
      ASSERT_LE(q.width, kPanelWidth) << w << "x" << h;
      ASSERT_GE(q.scale, kPanelMinScale) << w << "x" << h;
      ASSERT_LE(q.scale, 1.0f) << w << "x" << h;
      ASSERT_EQ(q.collapsed, w < kPanelCollapsedBelowWidth || h < kPanelCollapsedBelowHeight) << w << "x" << h;
    }
}

TEST(PanelLayout, ScaleFollowsTheSmallerSide) {
  EXPECT_FLOAT_EQ(panel_layout(1024, 720).scale, 0.8f);
  EXPECT_FLOAT_EQ(panel_layout(1280, 576).scale, 0.8f);
  EXPECT_FLOAT_EQ(panel_layout(1024, 1080).width, 0.8f * kPanelWidth);
}

} // namespace
} // namespace msm::viewer
