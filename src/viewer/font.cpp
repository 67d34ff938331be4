#include "font.h"

#include "msm/cpu/techniques.h"

#include <fmt/format.h>

#include <cstring>
#include <fstream>
#include <iterator>
#include <string_view>

namespace msm::viewer {
namespace {

// The signatures of a TrueType or OpenType font (a collection's too).
bool is_truetype(const std::string& bytes) {
  if (bytes.size() < 12) return false;
  std::string_view tag(bytes.data(), 4);
  return tag == std::string_view("\0\1\0\0", 4) || tag == "true" || tag == "OTTO" || tag == "ttcf";
}

} // namespace

std::filesystem::path default_font_file() { return MSM_VIEWER_FONT_FILE; }

std::vector<std::string_view> technique_texts(const Technique& technique) {
  std::vector<std::string_view> texts = {technique.name};
  for (const Parameter& p : technique.parameters) {
    if (!p.declared()) continue;
    texts.push_back(p.name);
    texts.push_back(p.meaning);
    for (const ParameterChoice& c : p.choices) texts.push_back(c.meaning);
  }
  return texts;
}

ImVector<ImWchar> panel_glyph_ranges() {
  ImFontGlyphRangesBuilder builder;
  // Basic Latin and Latin-1 (Dear ImGui's default ranges), Greek and Coptic.
  static const ImWchar blocks[] = {0x0020, 0x00FF, 0x0370, 0x03FF, 0};
  builder.AddRanges(blocks);
  for (const Technique& t : techniques()) {
    for (std::string_view text : technique_texts(t)) builder.AddText(text.data(), text.data() + text.size());
  }
  ImVector<ImWchar> ranges;
  builder.BuildRanges(&ranges);
  return ranges;
}

PanelFont load_panel_font(ImFontAtlas& atlas, const std::filesystem::path& file, float pixels,
                          ImVector<ImWchar>& ranges) {
  ranges = panel_glyph_ranges();
  // Read here rather than by Dear ImGui, which asserts on a file it cannot open or parse; the atlas
  // owns (and frees) its copy.
  std::ifstream in(file, std::ios::binary);
  std::string bytes{std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
  PanelFont out;
  if (is_truetype(bytes)) {
    void* data = IM_ALLOC(bytes.size());
    std::memcpy(data, bytes.data(), bytes.size());
    out.font = atlas.AddFontFromMemoryTTF(data, int(bytes.size()), pixels, nullptr, ranges.Data);
  }
  if (out.font) {
    out.message = fmt::format("font: {} ({:g} px)", file.string(), pixels);
    return out;
  }
  out.font = atlas.AddFontDefault();
  out.fallback = true;
  out.message = fmt::format("font: cannot read {} (Debian: fonts-dejavu-core); the built-in font shows "
                            "Greek letters as '?'",
                            file.string());
  return out;
}

} // namespace msm::viewer
