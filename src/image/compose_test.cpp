// Tests of compose.h: text stays in its documented box and scales exactly, inset selection finds
// planted disagreements (and matches a brute-force evaluation of its criterion), and the
// comparison figure puts panel pixels, magnified insets, frames and captions where the header
// says.
#include "msm/image/compose.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <initializer_list>
#include <limits>
#include <utility>

using namespace msm::image;

namespace {

bool inside(const Rect& r, int x, int y) { return x >= r.x && x < r.x + r.width && y >= r.y && y < r.y + r.height; }

glm::vec3 rgb_at(const Image& im, int x, int y) { return {im.at(x, y, 0), im.at(x, y, 1), im.at(x, y, 2)}; }

// Pixels differing from `fill` in any colour channel.
int inked(const Image& im, float fill = 0.0f) {
  int count = 0;
  for (int y = 0; y < im.height(); ++y)
    for (int x = 0; x < im.width(); ++x)
      if (rgb_at(im, x, y) != glm::vec3(fill)) ++count;
  return count;
}

// Deterministic pseudo-random values in [0, 1) (a 32-bit LCG; std distributions differ across
// standard libraries).
struct Lcg {
  std::uint32_t state;
  float next() {
    state = state * 1664525u + 1013904223u;
    return float(state >> 8) / float(1u << 24);
  }
};

Image noise(int w, int h, std::uint32_t seed) {
  Image im(w, h, 1);
  Lcg rng{seed};
  for (float& v : im.pixels()) v = rng.next();
  return im;
}

// Every pixel of every panel distinct, so a copied pixel cannot match by accident.
Image unique_rgb(int w, int h, int panel) {
  Image im(w, h, 3);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      im.at(x, y, 0) = float(x) / float(w);
      im.at(x, y, 1) = float(y) / float(h);
      im.at(x, y, 2) = 0.1f * float(panel) + 0.001f * float(x + y);
    }
  return im;
}

// The criterion of find_difference_regions, evaluated directly (no summed-area table).
double brute_score(const std::vector<Image>& images, const Rect& r) {
  double sum = 0.0;
  for (int y = r.y; y < r.y + r.height; ++y)
    for (int x = r.x; x < r.x + r.width; ++x) {
      float lo = std::numeric_limits<float>::infinity(), hi = -lo;
      for (const Image& im : images) {
        const float v = im.at(x, y);
        if (!std::isfinite(v)) continue;
        lo = std::min(lo, v);
        hi = std::max(hi, v);
      }
      if (hi > lo) sum += double(hi) - double(lo);
    }
  return sum;
}

bool overlap(const Rect& a, const Rect& b) {
  return a.x < b.x + b.width && b.x < a.x + a.width && a.y < b.y + b.height && b.y < a.y + a.height;
}

} // namespace

// ---- Text ------------------------------------------------------------------------------------

TEST(ComposeText, DrawsInsideItsBoxOnlyAndTouchesEveryEdge) {
  const std::string text = "Shadow gq 128!";
  const int scale = 2, x0 = 13, y0 = 7;
  Image im(220, 40, 3);
  draw_text(im, x0, y0, text, glm::vec3(1.0f), scale);
  const Rect box{x0, y0, text_width(text, scale), text_height(text, scale)};
  EXPECT_EQ(box.height, 18); // 9 font units
  EXPECT_GT(box.width, 0);
  int in = 0, out = 0;
  bool left = false, right = false, top = false, bottom = false;
  for (int y = 0; y < im.height(); ++y)
    for (int x = 0; x < im.width(); ++x) {
      const glm::vec3 v = rgb_at(im, x, y);
      if (v == glm::vec3(0.0f)) continue;
      EXPECT_EQ(v, glm::vec3(1.0f)) << x << "," << y;
      if (!inside(box, x, y)) {
        ++out;
        continue;
      }
      ++in;
      left |= x == box.x;
      right |= x == box.x + box.width - 1;
      top |= y == box.y;
      bottom |= y == box.y + box.height - 1; // the descenders of g and q
    }
  EXPECT_EQ(out, 0);
  EXPECT_GT(in, box.width * box.height / 10);
  EXPECT_TRUE(left && right && top && bottom) << "the box is not tight";
}

TEST(ComposeText, IntegerScaleMultipliesInkExactly) {
  Image a(100, 30, 3), b(300, 90, 3);
  draw_text(a, 0, 0, "MSM 64", glm::vec3(1.0f), 1);
  draw_text(b, 0, 0, "MSM 64", glm::vec3(1.0f), 3);
  ASSERT_GT(inked(a), 20);
  EXPECT_EQ(inked(b), 9 * inked(a));
  for (int y = 0; y < b.height(); ++y)
    for (int x = 0; x < b.width(); ++x) ASSERT_EQ(b.at(x, y), a.at(x / 3, y / 3)) << x << "," << y;
  EXPECT_EQ(text_width("MSM 64", 3), 3 * text_width("MSM 64", 1));
}

TEST(ComposeText, DifferentTextDifferentPixelsAndLines) {
  Image a(60, 20, 3), b(60, 20, 3);
  draw_text(a, 1, 1, "PCF", glm::vec3(1.0f), 1);
  draw_text(b, 1, 1, "VSM", glm::vec3(1.0f), 1);
  EXPECT_NE(a, b);
  EXPECT_EQ(text_height("a\nb", 2), 2 * (12 + 9));
  EXPECT_EQ(text_width("ab\nabcd", 1), text_width("abcd", 1));
  EXPECT_EQ(text_width("", 2), 0);
  EXPECT_EQ(text_height("", 2), 0);
  // Non-ASCII bytes are drawn (as '?') instead of read out of the font's tables.
  EXPECT_EQ(text_width("\xc3\xa9", 1), text_width("??", 1));
}

TEST(ComposeText, ClipsAtTheImageAndSetsAlpha) {
  Image im(10, 10, 4, 0.0f);
  draw_text(im, -7, -3, "WWWW", glm::vec3(0.5f, 0.25f, 1.0f), 3);
  bool any = false;
  for (int y = 0; y < 10; ++y)
    for (int x = 0; x < 10; ++x)
      if (im.at(x, y, 0) != 0.0f) {
        any = true;
        EXPECT_EQ(im.at(x, y, 2), 1.0f);
        EXPECT_EQ(im.at(x, y, 3), 1.0f);
      }
  EXPECT_TRUE(any);
}

TEST(ComposeText, LabelBoxCoversTextPlusPaddingOnly) {
  const float fill = 0.6f;
  Image im(120, 40, 3, fill);
  const LabelStyle style{
      .text_colour = glm::vec3(1.0f), .box_colour = glm::vec3(0.0f), .box_opacity = 0.5f, .scale = 2};
  draw_label(im, 5, 4, "EVSM4", style);
  const Rect box{5, 4, text_width("EVSM4", 2) + 4, text_height("EVSM4", 2) + 4};
  int text_pixels = 0;
  for (int y = 0; y < im.height(); ++y)
    for (int x = 0; x < im.width(); ++x) {
      const float v = im.at(x, y);
      if (!inside(box, x, y)) {
        EXPECT_EQ(v, fill) << x << "," << y;
      } else if (v == 1.0f) {
        ++text_pixels;
        // One font unit (2 px) of padding stays box-only.
        EXPECT_TRUE(x >= box.x + 2 && x < box.x + box.width - 2 && y >= box.y + 2 && y < box.y + box.height - 2);
      } else {
        EXPECT_FLOAT_EQ(v, fill * 0.5f) << x << "," << y;
      }
    }
  EXPECT_GT(text_pixels, 50);
  Image untouched(20, 20, 3, fill);
  draw_label(untouched, 0, 0, "", style);
  EXPECT_EQ(inked(untouched, fill), 0);
}

TEST(ComposeText, RejectsBadArguments) {
  Image grey(10, 10, 1);
  EXPECT_THROW(draw_text(grey, 0, 0, "x", glm::vec3(1.0f), 1), ImageError);
  Image rgb(10, 10, 3);
  EXPECT_THROW(draw_text(rgb, 0, 0, "x", glm::vec3(1.0f), 0), ImageError);
  EXPECT_THROW((void)text_width("x", 0), ImageError);
}

// ---- Inset selection -------------------------------------------------------------------------

TEST(ComposeRegions, FindsPlantedPatchesBestFirst) {
  const Image base = noise(64, 48, 1);
  std::vector<Image> images{base, base, base};
  const Rect strong{40, 20, 10, 8}, weak{5, 30, 10, 8};
  for (int y = 0; y < 48; ++y)
    for (int x = 0; x < 64; ++x) {
      if (inside(strong, x, y)) images[1].at(x, y) += 0.5f;
      if (inside(weak, x, y)) images[2].at(x, y) -= 0.2f;
    }
  // Everywhere else the images agree, so only the two patches have positive scores.
  const auto found = find_difference_regions(images, 10, 8, 4);
  ASSERT_EQ(found.size(), 2u);
  EXPECT_EQ(found[0], strong);
  EXPECT_EQ(found[1], weak);
  EXPECT_EQ(find_difference_regions(images, 10, 8, 1), std::vector<Rect>{strong});
  EXPECT_TRUE(find_difference_regions(images, 10, 8, 0).empty());
  const std::vector<Image> same{base, base};
  EXPECT_TRUE(find_difference_regions(same, 10, 8, 3).empty());
}

TEST(ComposeRegions, GreedyOptimumNonOverlappingAndDeterministic) {
  std::vector<Image> images{noise(50, 40, 7), noise(50, 40, 8), noise(50, 40, 9)};
  const auto found = find_difference_regions(images, 12, 9, 5);
  ASSERT_EQ(found.size(), 5u);
  for (std::size_t i = 0; i < found.size(); ++i) {
    const Rect& r = found[i];
    EXPECT_EQ(r.width, 12);
    EXPECT_EQ(r.height, 9);
    EXPECT_TRUE(r.x >= 0 && r.y >= 0 && r.x + 12 <= 50 && r.y + 9 <= 40);
    for (std::size_t j = 0; j < i; ++j) EXPECT_FALSE(overlap(r, found[j])) << i << " overlaps " << j;
    // Each pick is the best window (by direct evaluation) overlapping none of the earlier ones.
    double best = 0.0;
    for (int y = 0; y + 9 <= 40; ++y)
      for (int x = 0; x + 12 <= 50; ++x) {
        const Rect c{x, y, 12, 9};
        bool free = true;
        for (std::size_t j = 0; j < i; ++j) free = free && !overlap(c, found[j]);
        if (free) best = std::max(best, brute_score(images, c));
      }
    EXPECT_NEAR(brute_score(images, r), best, 1e-9 * best) << "pick " << i;
  }
  EXPECT_EQ(find_difference_regions(images, 12, 9, 5), found);
}

TEST(ComposeRegions, TiesGoToTheFirstWindowInRowMajorOrder) {
  const Image a(30, 20, 1, 0.25f), b(30, 20, 1, 0.75f);
  const std::vector<Image> images{a, b};
  const auto found = find_difference_regions(images, 10, 10, 3);
  ASSERT_EQ(found.size(), 3u);
  EXPECT_EQ(found[0], (Rect{0, 0, 10, 10}));
  EXPECT_EQ(found[1], (Rect{10, 0, 10, 10}));
  EXPECT_EQ(found[2], (Rect{20, 0, 10, 10}));
}

TEST(ComposeRegions, IgnoresNonFiniteValuesAndUsesTheNamedChannel) {
  Image a(32, 32, std::vector<std::string>{"visibility", "depth"});
  Image b = a;
  // A huge disagreement in "depth" must not matter when "visibility" is chosen.
  for (int y = 0; y < 8; ++y)
    for (int x = 0; x < 8; ++x) b.at(x, y, 1) = 100.0f;
  for (int y = 20; y < 26; ++y)
    for (int x = 4; x < 10; ++x) b.at(x, y, 0) = 0.3f;
  // NaN and inf next to finite values are no disagreement.
  for (int y = 0; y < 6; ++y)
    for (int x = 20; x < 26; ++x) b.at(x, y, 0) = (x % 2) ? std::nanf("") : std::numeric_limits<float>::infinity();
  const std::vector<Image> images{a, b};
  const auto found = find_difference_regions(images, 6, 6, 3, "visibility");
  ASSERT_EQ(found.size(), 1u);
  EXPECT_EQ(found[0], (Rect{4, 20, 6, 6}));
  EXPECT_THROW(find_difference_regions(images, 6, 6, 1), ImageError); // several channels, no R,G,B
  EXPECT_THROW(find_difference_regions(images, 6, 6, 1, "nope"), ImageError);
}

TEST(ComposeRegions, RejectsBadArguments) {
  const std::vector<Image> none;
  EXPECT_THROW(find_difference_regions(none, 4, 4, 1), ImageError);
  const std::vector<Image> mismatched{Image(10, 10, 1), Image(10, 11, 1)};
  EXPECT_THROW(find_difference_regions(mismatched, 4, 4, 1), ImageError);
  const std::vector<Image> ok{Image(10, 10, 1), Image(10, 10, 1)};
  EXPECT_THROW(find_difference_regions(ok, 11, 4, 1), ImageError);
  EXPECT_THROW(find_difference_regions(ok, 4, 0, 1), ImageError);
  EXPECT_THROW(find_difference_regions(ok, 4, 4, -1), ImageError);
}

// ---- Comparison figure -----------------------------------------------------------------------

TEST(ComposeFigure, LayoutPanelsInsetsFramesAndCaptions) {
  const int W = 80, H = 60;
  std::vector<Panel> panels{
      {"PCF", unique_rgb(W, H, 0), ""}, {"VSM", unique_rgb(W, H, 1), "MAE 0.012"}, {"MSM 64", unique_rgb(W, H, 2), ""}};
  ComposeOptions options;
  options.insets = {{5, 34, 6, 5}, {60, 40, 8, 6}};
  options.inset_colours = {glm::vec3(1, 0, 0), glm::vec3(0, 1, 0)};
  const int m = options.margin, t = options.outline, s = options.text_scale, f = 3;
  ASSERT_EQ(m, 8);
  ASSERT_EQ(t, 2);
  ASSERT_EQ(options.magnification, f);
  // The row (6*3 + 4) + (8*3 + 4) + 8 = 58 fits in 80: magnification 3 is kept.
  const int R = 6 * f + 2 * t, C = text_height("MAE 0.012", s);
  const int cell_h = H + m + R + m + C;
  const Image out = compose_comparison(panels, options);
  ASSERT_EQ(out.channels(), 3);
  ASSERT_EQ(out.width(), m + 3 * (W + m));
  ASSERT_EQ(out.height(), m + cell_h + m);
  EXPECT_EQ(rgb_at(out, 0, 0), options.background);
  EXPECT_EQ(rgb_at(out, out.width() - 1, out.height() - 1), options.background);

  for (int j = 0; j < 3; ++j) {
    const Image& src = panels[std::size_t(j)].rgb;
    const int X = m + j * (W + m), Y = m;
    // Panel pixels away from the label (top-left) and the inset frames.
    for (auto [x, y] :
         std::initializer_list<std::pair<int, int>>{{79, 59}, {40, 30}, {70, 25}, {0, 59}, {79, 0}, {20, 50}})
      EXPECT_EQ(rgb_at(out, X + x, Y + y), rgb_at(src, x, y)) << "panel " << j << " at " << x << "," << y;
    // The label is drawn over the top-left corner: its box darkens the padding.
    EXPECT_NE(rgb_at(out, X + 1, Y + 1), rgb_at(src, 1, 1));
    // Frames inside the windows on the image; the window's interior stays the panel's.
    EXPECT_EQ(rgb_at(out, X + 5, Y + 34), glm::vec3(1, 0, 0));
    EXPECT_EQ(rgb_at(out, X + 60 + 7, Y + 40 + 5), glm::vec3(0, 1, 0));
    EXPECT_EQ(rgb_at(out, X + 62, Y + 42), rgb_at(src, 62, 42));
    EXPECT_EQ(rgb_at(out, X + 4, Y + 33), rgb_at(src, 4, 33)); // just outside: untouched

    // Insets: the exact nearest-neighbour magnification, every pixel, with the frames around.
    int ix = X + t;
    for (std::size_t i = 0; i < options.insets.size(); ++i) {
      const Rect& r = options.insets[i];
      const int iy = Y + H + m + t;
      for (int v = 0; v < r.height * f; ++v)
        for (int u = 0; u < r.width * f; ++u)
          ASSERT_EQ(rgb_at(out, ix + u, iy + v), rgb_at(src, r.x + u / f, r.y + v / f))
              << "panel " << j << " inset " << i << " at " << u << "," << v;
      const glm::vec3 colour = options.inset_colours[i];
      EXPECT_EQ(rgb_at(out, ix - 1, iy), colour);
      EXPECT_EQ(rgb_at(out, ix - t, iy - t), colour);
      EXPECT_EQ(rgb_at(out, ix + r.width * f, iy + r.height * f), colour);
      EXPECT_EQ(rgb_at(out, ix + r.width * f + t - 1, iy + r.height * f + t - 1), colour);
      EXPECT_EQ(rgb_at(out, ix + r.width * f + t, iy), options.background);
      ix += r.width * f + 2 * t + m;
    }

    // Captions: white text on the dark background, only for the panel that has one.
    const Rect caption{X, Y + H + m + R + m, W, C};
    int lit = 0;
    for (int y = caption.y; y < caption.y + caption.height; ++y)
      for (int x = caption.x; x < caption.x + caption.width; ++x) {
        const glm::vec3 v = rgb_at(out, x, y);
        if (v != options.background) {
          EXPECT_EQ(v, glm::vec3(1.0f));
          ++lit;
        }
      }
    if (j == 1) {
      EXPECT_GT(lit, 40);
    } else {
      EXPECT_EQ(lit, 0);
    }
  }
}

TEST(ComposeFigure, WrapsIntoRowsAndAcceptsGreyPanels) {
  std::vector<Panel> panels;
  // (A label built as "T" + to_string trips GCC 12's false -Wrestrict.)
  for (int j = 0; j < 5; ++j) panels.push_back({std::string(1, char('A' + j)), unique_rgb(16, 12, j), ""});
  Image grey(16, 12, 1);
  for (int y = 0; y < 12; ++y)
    for (int x = 0; x < 16; ++x) grey.at(x, y) = 0.01f * float(x * 12 + y);
  panels[4].rgb = grey;
  ComposeOptions options;
  options.columns = 2;
  options.margin = 3;
  const Image out = compose_comparison(panels, options);
  // No insets, no captions: cells are the panels.
  ASSERT_EQ(out.width(), 3 + 2 * (16 + 3));
  ASSERT_EQ(out.height(), 3 + 3 * (12 + 3));
  const int X4 = 3, Y4 = 3 + 2 * (12 + 3);
  EXPECT_EQ(rgb_at(out, X4 + 15, Y4 + 11), glm::vec3(grey.at(15, 11)));
  const int X3 = 3 + 16 + 3, Y3 = 3 + 12 + 3;
  EXPECT_EQ(rgb_at(out, X3 + 15, Y3 + 11), rgb_at(panels[3].rgb, 15, 11));
  EXPECT_EQ(rgb_at(out, out.width() - 1, Y4 + 5), options.background); // the empty sixth cell
}

TEST(ComposeFigure, ShrinksMagnificationToFitThePanelWidth) {
  Image src = unique_rgb(40, 30, 0);
  ComposeOptions options;
  options.insets = {{0, 0, 12, 6}, {20, 10, 10, 6}};
  options.margin = 4;
  options.outline = 1;
  // f = 3: 36+2 + 30+2 + 4 = 74 > 40; f = 2: 26 + 22 + 4 = 52 > 40; f = 1: 14 + 12 + 4 = 30.
  Image out = compose_comparison({{"", src, ""}}, options);
  const int H = 30, m = 4, t = 1;
  EXPECT_EQ(out.height(), m + H + m + (6 + 2 * t) + m);
  const int ix = m + t + 12 + 2 * t + m, iy = m + H + m + t; // the second inset, 1:1
  for (int v = 0; v < 6; ++v)
    for (int u = 0; u < 10; ++u) ASSERT_EQ(rgb_at(out, ix + u, iy + v), rgb_at(src, 20 + u, 10 + v));
  // Wider than the panel even at 1:1: a fractional factor, (40 - 4 - 4) / 64 = 0.5.
  options.insets = {{0, 0, 32, 8}, {8, 20, 32, 8}};
  out = compose_comparison({{"", src, ""}}, options);
  EXPECT_EQ(out.height(), m + H + m + (4 + 2 * t) + m);
  const int jx = m + t + 16 + 2 * t + m;
  for (int v = 0; v < 4; ++v)
    for (int u = 0; u < 16; ++u) ASSERT_EQ(rgb_at(out, jx + u, iy + v), rgb_at(src, 8 + 2 * u, 20 + 2 * v));
}

TEST(ComposeFigure, RejectsBadInput) {
  const Image a(20, 10, 3), b(21, 10, 3);
  EXPECT_THROW(compose_comparison({}), ImageError);
  EXPECT_THROW(compose_comparison({{"a", a, ""}, {"b", b, ""}}), ImageError);
  EXPECT_THROW(compose_comparison({{"a", a, ""}, {"empty", Image(), ""}}), ImageError);
  auto with = [](auto change) {
    ComposeOptions o;
    change(o);
    return o;
  };
  const std::vector<Panel> ok{{"a", a, ""}};
  EXPECT_NO_THROW(compose_comparison(ok, with([](ComposeOptions& o) { o.insets = {{14, 4, 6, 6}}; })));
  EXPECT_THROW(compose_comparison(ok, with([](ComposeOptions& o) { o.insets = {{15, 4, 6, 6}}; })), ImageError);
  EXPECT_THROW(compose_comparison(ok, with([](ComposeOptions& o) { o.insets = {{-1, 0, 2, 2}}; })), ImageError);
  EXPECT_THROW(compose_comparison(ok, with([](ComposeOptions& o) { o.insets = {{0, 0, 0, 2}}; })), ImageError);
  EXPECT_THROW(compose_comparison(ok, with([](ComposeOptions& o) { o.magnification = 0; })), ImageError);
  EXPECT_THROW(compose_comparison(ok, with([](ComposeOptions& o) { o.text_scale = 0; })), ImageError);
  EXPECT_THROW(compose_comparison(ok, with([](ComposeOptions& o) { o.margin = -1; })), ImageError);
  EXPECT_THROW(compose_comparison(ok, with([](ComposeOptions& o) { o.columns = -1; })), ImageError);
  // Six framed insets cannot share 20 pixels.
  EXPECT_THROW(compose_comparison(ok, with([](ComposeOptions& o) {
                                    o.insets.assign(6, Rect{0, 0, 2, 2});
                                  })),
               ImageError);
}
