// The panel's size for a window size: the whole panel at 1280x720 and above; in smaller windows
// its text and widgets scaled down with the window (to a readable least), its width capped at a
// share of the window, and it starts collapsed to its title bar below a size.
#pragma once

#include <algorithm>

namespace msm::viewer {

inline constexpr float kPanelWidth = 380.0f;        // at scale 1
inline constexpr float kPanelFontPixels = 13.0f;    // the font's size at scale 1 (font.h)
inline constexpr float kPanelMinScale = 0.75f;      // smaller text is hard to read
inline constexpr float kPanelMaxWindowShare = 0.4f; // of the window's width, at most
inline constexpr float kPanelWidgetShare = 0.55f;   // of the panel's width; the labels have the rest
// Below either size the panel starts collapsed (its title bar only); it opens with a click.
inline constexpr float kPanelCollapsedBelowWidth = 800.0f;
inline constexpr float kPanelCollapsedBelowHeight = 450.0f;

struct PanelLayout {
  float scale = 1.0f; // of the font (ImGuiIO::FontGlobalScale) and the style's sizes
  float width = kPanelWidth;
  bool collapsed = false; // the default for this window size
};

inline PanelLayout panel_layout(float window_width, float window_height) {
  PanelLayout p;
  p.scale = std::clamp(std::min(window_width / 1280.0f, window_height / 720.0f), kPanelMinScale, 1.0f);
  p.width = std::min(kPanelWidth * p.scale, kPanelMaxWindowShare * window_width);
  p.collapsed = window_width < kPanelCollapsedBelowWidth || window_height < kPanelCollapsedBelowHeight;
  return p;
}

} // namespace msm::viewer
