#include "font.h"
#include "panel_layout.h"

#include "msm/cpu/techniques.h"

#include <gtest/gtest.h>

#include <string>
#include <vector>

namespace msm::viewer {
namespace {

// The code points of UTF-8 text (Dear ImGui's decoder, through a ranges builder).
std::vector<ImWchar> code_points(std::string_view text) {
  ImFontGlyphRangesBuilder builder;
  builder.AddText(text.data(), text.data() + text.size());
  ImVector<ImWchar> ranges;
  builder.BuildRanges(&ranges);
  std::vector<ImWchar> out;
  for (int i = 0; i + 1 < ranges.Size && ranges[i] != 0; i += 2)
    for (int c = ranges[i]; c <= ranges[i + 1]; ++c) out.push_back(ImWchar(c));
  return out;
}

struct Atlas {
  Atlas() { ImGui::CreateContext(); }
  ~Atlas() { ImGui::DestroyContext(); }
  ImFontAtlas& fonts() { return *ImGui::GetIO().Fonts; }
};

TEST(PanelFont, HasEveryLetterOfTheParameterHelp) {
  Atlas atlas;
  ImVector<ImWchar> ranges;
  PanelFont font = load_panel_font(atlas.fonts(), default_font_file(), kPanelFontPixels, ranges);
  ASSERT_FALSE(font.fallback) << font.message;
  ASSERT_TRUE(atlas.fonts().Build());
  int greek = 0;
  for (const Technique& t : techniques())
    for (std::string_view text : technique_texts(t))
      for (ImWchar c : code_points(text)) {
        EXPECT_NE(font.font->FindGlyphNoFallback(c), nullptr)
            << "U+" << std::hex << int(c) << " of " << t.name << ": " << text;
        greek += c >= 0x0370 && c <= 0x03FF;
      }
  EXPECT_GT(greek, 0) << "the help names no Greek letter: the test checks nothing beyond ASCII";
  for (ImWchar c : code_points("δε")) EXPECT_NE(font.font->FindGlyphNoFallback(c), nullptr);
}

TEST(PanelFont, MissingFileFallsBackAndSaysWhatToInstall) {
  Atlas atlas;
  ImVector<ImWchar> ranges;
  PanelFont font = load_panel_font(atlas.fonts(), "/nonexistent/DejaVuSansMono.ttf", 15.0f, ranges);
  EXPECT_TRUE(font.fallback);
  ASSERT_NE(font.font, nullptr);
  EXPECT_NE(font.message.find("/nonexistent/DejaVuSansMono.ttf"), std::string::npos) << font.message;
  EXPECT_NE(font.message.find("fonts-dejavu-core"), std::string::npos) << font.message;
  ASSERT_TRUE(atlas.fonts().Build());
}

TEST(PanelFont, NotAFontFallsBack) {
  Atlas atlas;
  ImVector<ImWchar> ranges;
  PanelFont font = load_panel_font(atlas.fonts(), __FILE__, 15.0f, ranges);
  EXPECT_TRUE(font.fallback) << font.message;
  ASSERT_TRUE(atlas.fonts().Build());
}

} // namespace
} // namespace msm::viewer
