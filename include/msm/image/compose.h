// Labelled side-by-side comparison figures with magnified insets, as `make demo` writes them:
// one panel per shadow technique, its name drawn on it, the windows where the techniques differ
// most outlined and shown magnified (nearest-neighbour, so texels stay visible) below it.
//
//   std::vector<Image> vis = {pcf_visibility, vsm_visibility, msm_visibility};
//   ComposeOptions options;
//   options.insets = find_difference_regions(vis, 48, 32, 2);
//   write_png("comparison.png", compose_comparison({{"PCF", pcf_rgb}, {"VSM", vsm_rgb, "MAE 0.012"},
//                                                   {"MSM 64", msm_rgb}}, options));
//
// Text uses stb_easy_font (ASCII, drawn as axis-aligned quads on a 1-unit grid) rasterized at an
// integer scale, so every glyph edge falls on a pixel edge: no blending, exact in tests.
// All colours are linear RGB (the images' space); write_png encodes them to sRGB.
#pragma once

#include "msm/image/image.h"

#include <span>
#include <string>
#include <string_view>
#include <vector>

#include <glm/vec3.hpp>

namespace msm::image {

// A pixel window: x in [x, x + width), y in [y, y + height).
struct Rect {
  int x = 0, y = 0, width = 0, height = 0;
  bool operator==(const Rect&) const = default;
};

// ---- Text ------------------------------------------------------------------------------------

// Size in pixels of the ink of `text` drawn at `scale` (0 x 0 for empty text): width = up to
// and including the rightmost ink column of the widest line, height = 12 * scale per line break plus 9 * scale
// for the last line (9 font units cover every glyph, descenders included). '\n' breaks lines;
// bytes other than printable ASCII (32..126) are drawn as '?'. Requires scale >= 1 (else
// ImageError).
int text_width(std::string_view text, int scale);
int text_height(std::string_view text, int scale);

// Sets the pixels covered by the glyphs of `text`, top-left ink corner at (x, y), to `colour`
// (channels 0..2; a fourth channel, alpha, is set to 1). Touches only pixels inside
// [x, x + text_width) x [y, y + text_height) and inside the image (the rest is clipped, so any
// x, y is allowed). Requires an image with 3 or 4 channels and scale >= 1 (else ImageError).
void draw_text(Image& rgb, int x, int y, std::string_view text, glm::vec3 colour, int scale);

// Text that reads on bright and dark images alike: a box of `box_colour` blended over the image
// with `box_opacity` in [0, 1], covering [x, x + text_width + 2 * scale) x
// [y, y + text_height + 2 * scale), then the text inset by `scale` pixels (one font unit).
// Nothing is drawn for empty text. Same requirements and clipping as draw_text.
struct LabelStyle {
  glm::vec3 text_colour{1.0f};
  glm::vec3 box_colour{0.0f};
  float box_opacity = 0.75f;
  int scale = 2;
};
void draw_label(Image& rgb, int x, int y, std::string_view text, const LabelStyle& style = {});

// ---- Inset selection -------------------------------------------------------------------------

// Up to `count` non-overlapping inset_w x inset_h windows where the images disagree most.
//
// Each image is reduced to one scalar per pixel as select_signal(image, channel) does (the named
// channel, else the only channel, else luminance). The disagreement of a pixel is the spread
// max_i s_i - min_i s_i over the images whose value there is finite (0 where fewer than two
// are); the score of a window is the sum of the spreads of its pixels (a summed-area table in
// double). Windows are picked greedily: the best-scoring window, then the best one overlapping
// none picked so far, and so on; ties go to the smallest y, then the smallest x, so the result
// is deterministic. Only windows with a positive score are returned (identical images give
// none), in the order picked (best first).
//
// Requires: at least one image, all the same size, 1 <= inset_w <= width, 1 <= inset_h <= height,
// count >= 0 (else ImageError; also for an unknown channel). Cost: O(count^2) per window
// position: count passes over every window position (about 50 ms for 5 images, count 3,
// 1024 x 1024).
std::vector<Rect> find_difference_regions(std::span<const Image> signals, int inset_w, int inset_h, int count,
                                          const std::string& channel = {});

// ---- Comparison figure -----------------------------------------------------------------------

struct Panel {
  std::string label;   // drawn on the image, top-left (may be empty)
  Image rgb;           // linear; 3 or 4 channels = R,G,B(,A), 1 or 2 = grey(,A); alpha is ignored
  std::string caption; // optional line(s) under the cell, e.g. "MAE 0.012 vs PCF"
};

struct ComposeOptions {
  std::vector<Rect> insets;             // windows in panel pixels, each inside the panel (same for all)
  int magnification = 3;                // >= 1: inset scale when the row of insets fits the panel width
  int columns = 0;                      // panels per row; 0 (or >= the panel count): all in one row
  int margin = 8;                       // >= 0: around the figure, between cells and between a cell's parts
  int outline = 2;                      // >= 0: thickness of the inset frames
  int text_scale = 2;                   // >= 1: labels and captions (a glyph is 9 * scale pixels tall)
  glm::vec3 background{0.02f};          // linear
  std::vector<glm::vec3> inset_colours; // frame colour of inset i = inset_colours[i % size];
                                        // empty: a built-in palette of saturated hues
  LabelStyle label{};                   // the label's scale is text_scale
};

// One linear RGB image (channels R,G,B) of all panels in a grid. With W x H the panel size,
// n panels, c = the columns (n if options.columns is 0 or more than n), m = margin,
// t = outline, s = text_scale and k = insets.size():
//
//   inset row: inset i is shown at w_i * f x h_i * f pixels, nearest-neighbour (source texel of
//     output pixel (u, v): (x_i + u * w_i / dw_i, y_i + v * h_i / dh_i), integer division), in a
//     frame t pixels wide around it; insets stand left to right, m apart (frame to frame).
//     f = the largest integer in 1..magnification for which the row, sum (w_i * f + 2t) +
//     (k - 1) m, fits in W; if none does, the real factor that makes it fit (sides rounded down,
//     at least 1 pixel; what the rounding up to 1 pushes past the cell is clipped). Row height
//     R = max (h_i * f) + 2t (0 when k = 0).
//   caption height C = the largest text_height of the captions (0 when none has one).
//   cell: W x (H + (k ? m + R : 0) + (C ? m + C : 0)); cell j at column j % c, row j / c, its
//     top-left corner at (m + (j % c) (W + m), m + (j / c) (cell height + m)).
//   output: (m + c (W + m)) x (m + rows (cell height + m)), rows = ceil(n / c), background
//     colour everywhere outside what is drawn.
//   within a cell at (X, Y):
//     the panel's pixels at (X, Y), with each inset window outlined on it by a frame t pixels
//       wide drawn inside the window, and the label (draw_label, scale s) at (X, Y) on top;
//       both clipped to the W x H image;
//     inset i's magnified pixels at (X + t + sum_{j<i} (w_j f + 2t + m), Y + H + m + t), taken
//       from the panel as given (no frames or label);
//     the caption (draw_text, scale s) at (X, Y + H + (k ? m + R : 0) + m), white on a dark
//       background (luminance < 0.18), else black, clipped to the cell width.
//
// Requires (else ImageError): at least one panel; every panel non-empty and the same size;
// every inset non-empty and inside the panel; magnification, text_scale >= 1; columns,
// margin, outline >= 0; the insets fit the panel width at 1 pixel each; the output within
// max_side.
Image compose_comparison(const std::vector<Panel>& panels, const ComposeOptions& options = {});

} // namespace msm::image
