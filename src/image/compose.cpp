#include "msm/image/compose.h"
#include "msm/image/metrics.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>

#include <fmt/core.h>

// stb_easy_font is all static functions and tables; a few of them are unused here.
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wunused-function"
#include <stb/stb_easy_font.h>
#pragma GCC diagnostic pop

namespace msm::image {

namespace {

constexpr int font_line_advance = 12; // stb_easy_font's line spacing, in font units
constexpr int font_ink_height = 9;    // the lowest ink row of any glyph is 8 (descenders)

// Pixel bounds [x0, x1) x [y0, y1); drawing is confined to one so that a caption cannot spill
// into the neighbouring cell.
struct Box {
  int x0, y0, x1, y1;
  Box intersect(const Box& o) const {
    return {std::max(x0, o.x0), std::max(y0, o.y0), std::min(x1, o.x1), std::min(y1, o.y1)};
  }
};

Box image_box(const Image& im) { return {0, 0, im.width(), im.height()}; }

void check_scale(int scale) {
  if (scale < 1) throw ImageError({}, fmt::format("text scale {} must be >= 1", scale));
}

void check_rgb(const Image& rgb) {
  if (rgb.channels() != 3 && rgb.channels() != 4)
    throw ImageError({}, fmt::format("cannot draw on an image with {} channels (needs 3 or 4)", rgb.channels()));
}

// stb_easy_font indexes its tables by (char - 32) without checking: anything outside printable
// ASCII would read out of bounds.
std::string sanitize(std::string_view text) {
  std::string out(text);
  for (char& ch : out)
    if (ch != '\n' && (ch < 32 || ch > 126)) ch = '?';
  return out;
}

// The glyph quads of `text` in font units, origin at the top-left ink corner.
std::vector<Box> glyph_quads(std::string_view text) {
  std::string s = sanitize(text);
  // 64 bytes a quad; no glyph has more than 11 quads, and stb truncates rather than overrun.
  std::vector<char> buffer(64 * 16 * (s.size() + 1));
  const int quads = stb_easy_font_print(0.0f, 0.0f, s.data(), nullptr, buffer.data(), int(buffer.size()));
  std::vector<Box> out;
  out.reserve(std::size_t(quads));
  for (int q = 0; q < quads; ++q) {
    // Vertices 0 and 2 of each quad are opposite corners (16 bytes a vertex: x, y, z, rgba).
    float v0[2], v2[2];
    std::memcpy(v0, buffer.data() + q * 64, sizeof v0);
    std::memcpy(v2, buffer.data() + q * 64 + 32, sizeof v2);
    out.push_back({int(v0[0]), int(v0[1]), int(v2[0]), int(v2[1])});
  }
  return out;
}

void fill(Image& rgb, const Box& box, glm::vec3 colour, float opacity = 1.0f) {
  const Box b = box.intersect(image_box(rgb));
  const int n = rgb.channels();
  auto px = rgb.pixels();
  for (int y = b.y0; y < b.y1; ++y)
    for (int x = b.x0; x < b.x1; ++x) {
      float* p = &px[(std::size_t(y) * std::size_t(rgb.width()) + std::size_t(x)) * std::size_t(n)];
      for (int c = 0; c < 3; ++c) p[c] = opacity == 1.0f ? colour[c] : p[c] + (colour[c] - p[c]) * opacity;
      if (n == 4) p[3] = 1.0f;
    }
}

void draw_text_clipped(Image& rgb, int x, int y, std::string_view text, glm::vec3 colour, int scale, const Box& clip) {
  const Box limit = clip.intersect(image_box(rgb));
  for (const Box& q : glyph_quads(text))
    fill(rgb, Box{x + q.x0 * scale, y + q.y0 * scale, x + q.x1 * scale, y + q.y1 * scale}.intersect(limit), colour);
}

void draw_label_clipped(Image& rgb, int x, int y, std::string_view text, const LabelStyle& style, const Box& clip) {
  if (text.empty()) return; // a bare box would only hide pixels
  const int s = style.scale;
  const Box box{x, y, x + text_width(text, s) + 2 * s, y + text_height(text, s) + 2 * s};
  fill(rgb, box.intersect(clip), style.box_colour, std::clamp(style.box_opacity, 0.0f, 1.0f));
  draw_text_clipped(rgb, x + s, y + s, text, style.text_colour, s, clip);
}

// A frame `thickness` pixels wide just inside `outer` (filled when it is thinner than twice that).
void draw_frame(Image& rgb, const Box& outer, int thickness, glm::vec3 colour, const Box& clip) {
  if (thickness <= 0) return;
  const int t = thickness;
  const Box parts[4] = {
      {outer.x0, outer.y0, outer.x1, std::min(outer.y1, outer.y0 + t)},
      {outer.x0, std::max(outer.y0, outer.y1 - t), outer.x1, outer.y1},
      {outer.x0, outer.y0, std::min(outer.x1, outer.x0 + t), outer.y1},
      {std::max(outer.x0, outer.x1 - t), outer.y0, outer.x1, outer.y1},
  };
  for (const Box& b : parts) fill(rgb, b.intersect(clip), colour);
}

// Saturated hues that stand out against the greys of shadow images; given in display (sRGB)
// terms because that is how they are seen.
std::vector<glm::vec3> default_palette() {
  const glm::vec3 display[] = {{1.0f, 0.85f, 0.0f}, {0.0f, 0.9f, 1.0f},  {1.0f, 0.2f, 0.8f},
                               {0.3f, 1.0f, 0.2f},  {1.0f, 0.45f, 0.0f}, {0.55f, 0.55f, 1.0f}};
  std::vector<glm::vec3> out;
  for (const glm::vec3& d : display) out.push_back({srgb_to_linear(d.r), srgb_to_linear(d.g), srgb_to_linear(d.b)});
  return out;
}

} // namespace

int text_width(std::string_view text, int scale) {
  check_scale(scale);
  int right = 0;
  for (const Box& q : glyph_quads(text)) right = std::max(right, q.x1);
  return right * scale;
}

int text_height(std::string_view text, int scale) {
  check_scale(scale);
  if (text.empty()) return 0;
  const int breaks = int(std::count(text.begin(), text.end(), '\n'));
  return (breaks * font_line_advance + font_ink_height) * scale;
}

void draw_text(Image& rgb, int x, int y, std::string_view text, glm::vec3 colour, int scale) {
  check_scale(scale);
  check_rgb(rgb);
  draw_text_clipped(rgb, x, y, text, colour, scale, image_box(rgb));
}

void draw_label(Image& rgb, int x, int y, std::string_view text, const LabelStyle& style) {
  check_scale(style.scale);
  check_rgb(rgb);
  draw_label_clipped(rgb, x, y, text, style, image_box(rgb));
}

std::vector<Rect> find_difference_regions(std::span<const Image> signals, int inset_w, int inset_h, int count,
                                          const std::string& channel) {
  if (signals.empty()) throw ImageError({}, "find_difference_regions: no images");
  const int w = signals[0].width(), h = signals[0].height();
  for (const Image& im : signals)
    if (im.width() != w || im.height() != h)
      throw ImageError(
          {}, fmt::format("find_difference_regions: size mismatch ({}x{} vs {}x{})", im.width(), im.height(), w, h));
  if (inset_w < 1 || inset_w > w || inset_h < 1 || inset_h > h)
    throw ImageError(
        {}, fmt::format("find_difference_regions: window {}x{} does not fit 1..{} x 1..{}", inset_w, inset_h, w, h));
  if (count < 0) throw ImageError({}, fmt::format("find_difference_regions: count {} < 0", count));

  const std::size_t n = std::size_t(w) * std::size_t(h);
  std::vector<float> lo(n, std::numeric_limits<float>::infinity()), hi(n, -std::numeric_limits<float>::infinity());
  for (const Image& im : signals) {
    const Image s = select_signal(im, channel);
    auto px = s.pixels();
    for (std::size_t i = 0; i < n; ++i)
      if (std::isfinite(px[i])) {
        lo[i] = std::min(lo[i], px[i]);
        hi[i] = std::max(hi[i], px[i]);
      }
  }
  // Summed-area table with a zero first row and column: sat[(y)(w+1) + x] = sum over [0,x)x[0,y).
  // Spreads are summed in double: they are differences of nearby floats, and a window sum is a
  // difference of four large sums.
  const std::size_t stride = std::size_t(w) + 1;
  std::vector<double> sat(stride * (std::size_t(h) + 1), 0.0);
  for (int y = 0; y < h; ++y) {
    double row = 0.0;
    for (int x = 0; x < w; ++x) {
      const std::size_t i = std::size_t(y) * std::size_t(w) + std::size_t(x);
      // A pixel finite in fewer than two images has lo > hi (or lo == hi): no spread.
      row += hi[i] > lo[i] ? double(hi[i]) - double(lo[i]) : 0.0;
      sat[(std::size_t(y) + 1) * stride + std::size_t(x) + 1] = sat[std::size_t(y) * stride + std::size_t(x) + 1] + row;
    }
  }
  auto score = [&](int x, int y) {
    const std::size_t x0 = std::size_t(x), y0 = std::size_t(y);
    const std::size_t x1 = x0 + std::size_t(inset_w), y1 = y0 + std::size_t(inset_h);
    return sat[y1 * stride + x1] - sat[y0 * stride + x1] - sat[y1 * stride + x0] + sat[y0 * stride + x0];
  };
  auto overlaps = [&](const Rect& r, int x, int y) {
    return x < r.x + r.width && r.x < x + inset_w && y < r.y + r.height && r.y < y + inset_h;
  };

  std::vector<Rect> picked;
  while (int(picked.size()) < count) {
    double best = 0.0;
    Rect best_rect{};
    for (int y = 0; y + inset_h <= h; ++y)
      for (int x = 0; x + inset_w <= w; ++x) {
        const double sc = score(x, y);
        // Strictly greater: the first window in row-major order wins ties. Rounding in the
        // table can leave a tiny positive score over a window of zero spread; insets of
        // nothing are useless, hence the relative floor.
        if (sc > best && sc > 1e-9 * sat.back() &&
            std::none_of(picked.begin(), picked.end(), [&](const Rect& r) { return overlaps(r, x, y); })) {
          best = sc;
          best_rect = {x, y, inset_w, inset_h};
        }
      }
    if (best <= 0.0) break;
    picked.push_back(best_rect);
  }
  return picked;
}

Image compose_comparison(const std::vector<Panel>& panels, const ComposeOptions& options) {
  if (panels.empty()) throw ImageError({}, "compose_comparison: no panels");
  const int W = panels[0].rgb.width(), H = panels[0].rgb.height();
  for (std::size_t j = 0; j < panels.size(); ++j) {
    const Image& im = panels[j].rgb;
    if (im.empty())
      throw ImageError({}, fmt::format("compose_comparison: panel {} ('{}') is empty", j, panels[j].label));
    if (im.width() != W || im.height() != H)
      throw ImageError({}, fmt::format("compose_comparison: panel {} ('{}') is {}x{}, panel 0 is {}x{}", j,
                                       panels[j].label, im.width(), im.height(), W, H));
  }
  const int m = options.margin, t = options.outline, s = options.text_scale;
  if (options.magnification < 1 || s < 1 || options.columns < 0 || m < 0 || t < 0)
    throw ImageError({}, fmt::format("compose_comparison: bad options (magnification {}, text_scale {}, columns "
                                     "{}, margin {}, outline {})",
                                     options.magnification, s, options.columns, m, t));
  const auto& insets = options.insets;
  const int k = int(insets.size());
  long long source_width = 0;
  for (const Rect& r : insets) {
    if (r.width < 1 || r.height < 1 || r.x < 0 || r.y < 0 || r.x > W - r.width || r.y > H - r.height)
      throw ImageError({}, fmt::format("compose_comparison: inset {}x{} at ({}, {}) is not inside the {}x{} panel",
                                       r.width, r.height, r.x, r.y, W, H));
    source_width += r.width;
  }

  // Inset sizes: the largest integer magnification that fits keeps texels square and equal;
  // only when even 1:1 does not fit is a fractional (shrinking) factor used.
  const long long fixed = 2LL * t * k + (k > 0 ? (k - 1LL) * m : 0);
  std::vector<int> dw(static_cast<std::size_t>(k), 0), dh(static_cast<std::size_t>(k), 0);
  if (k > 0) {
    if (W - fixed < k)
      throw ImageError({}, fmt::format("compose_comparison: {} insets do not fit a panel {} pixels wide", k, W));
    int f = options.magnification;
    while (f > 1 && fixed + source_width * f > W) --f;
    const bool fits = fixed + source_width * f <= W;
    const double real = fits ? double(f) : double(W - fixed) / double(source_width);
    for (int i = 0; i < k; ++i) {
      dw[std::size_t(i)] =
          fits ? insets[std::size_t(i)].width * f : std::max(1, int(std::floor(insets[std::size_t(i)].width * real)));
      dh[std::size_t(i)] =
          fits ? insets[std::size_t(i)].height * f : std::max(1, int(std::floor(insets[std::size_t(i)].height * real)));
    }
  }
  const int row_height = k > 0 ? *std::max_element(dh.begin(), dh.end()) + 2 * t : 0;
  int caption_height = 0;
  for (const Panel& p : panels) caption_height = std::max(caption_height, text_height(p.caption, s));

  const int n = int(panels.size());
  const int cols = options.columns == 0 ? n : std::min(options.columns, n);
  const int rows = (n + cols - 1) / cols;
  const long long cell_h = H + (k > 0 ? m + row_height : 0LL) + (caption_height > 0 ? m + caption_height : 0LL);
  const long long out_w = m + cols * (W + (long long)m), out_h = m + rows * (cell_h + m);
  if (out_w > max_side || out_h > max_side)
    throw ImageError(
        {}, fmt::format("compose_comparison: the figure would be {}x{}, over {} per side", out_w, out_h, max_side));

  Image out(int(out_w), int(out_h), 3);
  fill(out, image_box(out), options.background);
  const std::vector<glm::vec3> palette = options.inset_colours.empty() ? default_palette() : options.inset_colours;
  LabelStyle label = options.label;
  label.scale = s;
  const glm::vec3 caption_colour = luminance(options.background.r, options.background.g, options.background.b) < 0.18f
                                       ? glm::vec3(1.0f)
                                       : glm::vec3(0.0f);

  auto px = out.pixels();
  // Callers keep (x, y) inside the figure and (sx, sy) inside the panel.
  auto set = [&](int x, int y, const Image& src, int sx, int sy) {
    float* d = &px[(std::size_t(y) * std::size_t(out.width()) + std::size_t(x)) * 3];
    const std::size_t n = std::size_t(src.channels());
    const float* p = &src.pixels()[(std::size_t(sy) * std::size_t(W) + std::size_t(sx)) * n];
    if (n >= 3) {
      d[0] = p[0], d[1] = p[1], d[2] = p[2];
    } else {
      d[0] = d[1] = d[2] = p[0];
    }
  };

  for (int j = 0; j < n; ++j) {
    const Image& src = panels[std::size_t(j)].rgb;
    const int X = m + (j % cols) * (W + m);
    const int Y = m + int((j / cols) * (cell_h + m));
    const Box cell{X, Y, X + W, Y + int(cell_h)};
    const Box image_area{X, Y, X + W, Y + H};
    for (int y = 0; y < H; ++y)
      for (int x = 0; x < W; ++x) set(X + x, Y + y, src, x, y);
    int inset_x = X;
    for (int i = 0; i < k; ++i) {
      const Rect& r = insets[std::size_t(i)];
      const glm::vec3 colour = palette[std::size_t(i) % palette.size()];
      draw_frame(out, {X + r.x, Y + r.y, X + r.x + r.width, Y + r.y + r.height}, t, colour, image_area);
      const int w_i = dw[std::size_t(i)], h_i = dh[std::size_t(i)];
      const int ix = inset_x + t, iy = Y + H + m + t;
      draw_frame(out, {ix - t, iy - t, ix + w_i + t, iy + h_i + t}, t, colour, cell);
      for (int v = 0; v < h_i; ++v)
        for (int u = 0; u < w_i; ++u)
          if (ix + u < cell.x1)
            set(ix + u, iy + v, src, r.x + int((long long)u * r.width / w_i), r.y + int((long long)v * r.height / h_i));
      inset_x += w_i + 2 * t + m;
    }
    // The label goes on last so that no frame crosses it.
    draw_label_clipped(out, X, Y, panels[std::size_t(j)].label, label, image_area);
    const int caption_y = Y + H + (k > 0 ? m + row_height : 0) + m;
    draw_text_clipped(out, X, caption_y, panels[std::size_t(j)].caption, caption_colour, s, cell);
  }
  return out;
}

} // namespace msm::image
