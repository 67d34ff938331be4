// The panel's font: a TrueType font with the letters the panel's text uses beyond ASCII (the
// techniques' parameter help names δ1, ε, θ, ξ, ...), which Dear ImGui's built-in font lacks.
#pragma once

#include "msm/cpu/techniques.h"

#include <imgui.h>

#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

namespace msm::viewer {

// DejaVu Sans Mono (Debian: fonts-dejavu-core, scripts/bootstrap.sh): monospaced, so the panel's
// columns of GPU times stay aligned, with Greek and the other symbols of the help.
std::filesystem::path default_font_file();

// The characters the panel draws: Dear ImGui's default ranges (Latin-1), the Greek and Coptic block
// and every character of the techniques' names and parameter help (msm::techniques()).
// The texts the panel shows of a technique: its name and its parameters' names, meanings and choices.
std::vector<std::string_view> technique_texts(const Technique& technique);
ImVector<ImWchar> panel_glyph_ranges();

struct PanelFont {
  ImFont* font = nullptr;
  bool fallback = false; // the file could not be read: Dear ImGui's built-in font (ASCII only)
  std::string message;   // what was loaded, or why not and what to install
};

// Adds the font of `file` at `pixels` to the atlas with panel_glyph_ranges(), kept in `ranges`
// (the atlas reads them when it is built, so they must outlive that). A missing or unreadable
// file gives the built-in font and a message naming the file and the package.
PanelFont load_panel_font(ImFontAtlas& atlas, const std::filesystem::path& file, float pixels,
                          ImVector<ImWchar>& ranges);

} // namespace msm::viewer
