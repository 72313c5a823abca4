#include "tools/render/print.hpp"

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include <stb_easy_font.h>

#include "tools/render/hash.hpp"

namespace papertear::render {

namespace {

struct Rgb8 {
  std::uint8_t r, g, b;
};

constexpr Rgb8 kPaper{247, 244, 236};
constexpr Rgb8 kInk{38, 38, 46};
constexpr Rgb8 kCrimson{196, 38, 46};
constexpr Rgb8 kCream{250, 240, 215};
constexpr Rgb8 kTeal{24, 112, 140};
constexpr Rgb8 kSun{246, 190, 40};
constexpr Rgb8 kNavy{28, 42, 82};
constexpr Rgb8 kOrange{236, 120, 40};

// Draws in a 1024 x 1024 design space scaled to the canvas.
class Canvas {
 public:
  explicit Canvas(int size) : image_(size, size), scale_(float(size) / 1024.0f) {
    fill(0, 0, 1024, 1024, kPaper);
  }
  Image take() { return std::move(image_); }

  void fill(float x0, float y0, float x1, float y1, Rgb8 c) {
    const int ix0 = px(x0), iy0 = px(y0), ix1 = px(x1), iy1 = px(y1);
    for (int y = std::max(iy0, 0); y < std::min(iy1, image_.height); ++y)
      for (int x = std::max(ix0, 0); x < std::min(ix1, image_.width); ++x) put(x, y, c, 1.0f);
  }

  // A disc with a one-pixel soft edge.
  void disc(float cx, float cy, float r, Rgb8 c) {
    const float s = scale_;
    for (int y = std::max(px(cy - r) - 1, 0); y < std::min(px(cy + r) + 2, image_.height); ++y)
      for (int x = std::max(px(cx - r) - 1, 0); x < std::min(px(cx + r) + 2, image_.width); ++x) {
        const float dx = (float(x) + 0.5f) - cx * s, dy = (float(y) + 0.5f) - cy * s;
        const float cover = std::clamp(r * s - std::sqrt(dx * dx + dy * dy) + 0.5f, 0.0f, 1.0f);
        if (cover > 0.0f) put(x, y, c, cover);
      }
  }

  // A band between two parallel lines x + y = a and x + y = b, clipped to a box.
  void diagonal_band(float x0, float y0, float x1, float y1, float a, float b, Rgb8 c) {
    for (int y = px(y0); y < px(y1); ++y)
      for (int x = px(x0); x < px(x1); ++x) {
        const float t = (float(x) + float(y) + 1.0f) / scale_;
        if (t >= a && t < b) put(x, y, c, 1.0f);
      }
  }

  // Real letters for headings, from stb_easy_font's quads, `size` design units per font
  // pixel.
  void text(float x, float y, const std::string& s, float size, Rgb8 c) {
    std::vector<char> buffer(s.size() * 300 + 64);
    std::string copy = s;
    const int quads = stb_easy_font_print(0.0f, 0.0f, copy.data(), nullptr, buffer.data(), int(buffer.size()));
    for (int q = 0; q < quads; ++q) {
      const float* v0 = reinterpret_cast<const float*>(buffer.data() + std::size_t(q) * 64);
      const float* v2 = reinterpret_cast<const float*>(buffer.data() + std::size_t(q) * 64 + 32);
      fill(x + v0[0] * size, y + v0[1] * size, x + v2[0] * size, y + v2[1] * size, c);
    }
  }

  // Lines of text-like marks: words of letter-sized blocks with gaps, a ragged right edge,
  // and a short last line per paragraph. Returns the y below the last line.
  float paragraphs(float x0, float y0, float x1, float y1, float pitch, std::uint64_t seed, Rgb8 c) {
    HashStream rng(seed);
    const float letter_h = pitch * 0.42f;
    int line_in_paragraph = 0, paragraph_length = 4 + rng.below(5);
    float y = y0;
    for (; y + pitch <= y1; y += pitch) {
      const bool last = ++line_in_paragraph == paragraph_length;
      const float right = last ? x0 + (x1 - x0) * rng.uniform(0.25f, 0.7f) : x1 - rng.uniform(0.0f, 30.0f);
      float x = x0 + (line_in_paragraph == 1 ? pitch : 0.0f);
      while (x < right) {
        const int letters = 2 + rng.below(8);
        for (int l = 0; l < letters && x < right; ++l) {
          const float w = pitch * rng.uniform(0.22f, 0.38f);
          const bool tall = rng.uniform() < 0.3f;
          fill(x, y + (tall ? pitch * 0.12f : pitch * 0.28f), x + w, y + pitch * 0.28f + letter_h, c);
          x += w + pitch * 0.07f;
        }
        x += pitch * 0.35f;
      }
      if (last) {
        line_in_paragraph = 0;
        paragraph_length = 4 + rng.below(5);
        y += pitch * 0.5f;
      }
    }
    return y;
  }

 private:
  int px(float design) const { return int(std::lround(design * scale_)); }
  void put(int x, int y, Rgb8 c, float cover) {
    std::uint8_t* p = image_.pixel(x, y);
    const std::uint8_t rgb[3] = {c.r, c.g, c.b};
    for (int k = 0; k < 3; ++k) p[k] = std::uint8_t(std::lround(float(p[k]) + (float(rgb[k]) - float(p[k])) * cover));
  }

  Image image_;
  float scale_;
};

void draw_header(Canvas& c) {
  c.fill(40, 40, 984, 240, kCrimson);
  c.text(70, 62, "PAPER TEAR", 11.0f, kCream);
  c.text(74, 186, "CG EXPRESSION OF PAPER TEARING  -  FIBRES, BLOCKS, SPRINGS", 2.6f, kCream);
  c.fill(40, 252, 984, 258, kInk);
}

void draw_graphic(Canvas& c) {
  c.fill(40, 280, 470, 700, kTeal);
  c.disc(255, 470, 150, kSun);
  c.diagonal_band(40, 280, 470, 700, 820, 880, kCream);
  c.diagonal_band(40, 280, 470, 700, 905, 925, kOrange);
  for (float i = 0; i < 5; ++i) c.fill(70, 610 + 16 * i, 70 + 60 * (i + 2), 618 + 16 * i, kNavy);
}

void draw_columns(Canvas& c) {
  c.text(510, 282, "THE GRAIN DECIDES", 4.0f, kInk);
  c.paragraphs(510, 318, 984, 700, 20, 11, kInk);
  const float top = 730;
  for (int col = 0; col < 3; ++col) {
    const float x0 = 40 + float(col) * 322, x1 = x0 + 298;
    c.fill(x0, top, x0 + 140, top + 14, kCrimson);
    c.paragraphs(x0, top + 28, x1, 940, 18, 100 + std::uint64_t(col), kInk);
  }
  c.fill(40, 950, 984, 990, kNavy);
  c.text(56, 958, "PRINTED ON A MULTI-LAYER MASS-SPRING LATTICE", 2.6f, kCream);
}

}  // namespace

Image default_print(int size) {
  Canvas c(size);
  draw_header(c);
  draw_graphic(c);
  draw_columns(c);
  return c.take();
}

Image load_print(const PrintSettings& print) {
  if (!print.enabled || print.image.empty()) return default_print();
  try {
    return read_png(print.image);
  } catch (const RenderError& e) {
    throw RenderError(std::string("print.image: ") + e.what());
  }
}

}  // namespace papertear::render
