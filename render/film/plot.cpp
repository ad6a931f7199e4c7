#include "render/film/plot.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
// A header of static functions, some unused here: keep its warnings out of ours.
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wunused-function"
#include <stb_easy_font.h>
#pragma GCC diagnostic pop

namespace vpl {

namespace {

using Rgb = std::array<uint8_t, 3>;
constexpr Rgb kSeriesColours[] = {{31, 119, 180}, {214, 39, 40}, {44, 160, 44}, {255, 127, 14},
                                  {148, 103, 189}, {140, 86, 75}, {227, 119, 194}, {23, 190, 207}};

class Canvas {
 public:
  Canvas(int w, int h) : out_{w, h, std::vector<uint8_t>(size_t(w) * size_t(h) * 3, 255)} {}
  void set(int x, int y, Rgb c) {
    if (x < 0 || y < 0 || x >= out_.width || y >= out_.height) return;
    const size_t i = (size_t(y) * size_t(out_.width) + size_t(x)) * 3;
    out_.rgb[i] = c[0];
    out_.rgb[i + 1] = c[1];
    out_.rgb[i + 2] = c[2];
  }
  void rect(int x0, int y0, int x1, int y1, Rgb c) {
    for (int y = y0; y < y1; ++y)
      for (int x = x0; x < x1; ++x) set(x, y, c);
  }
  // A line `thickness` pixels wide, by stepping along its longer axis.
  void line(double x0, double y0, double x1, double y1, Rgb c, int thickness) {
    const int steps = int(std::ceil(std::max(std::abs(x1 - x0), std::abs(y1 - y0)))) + 1;
    for (int s = 0; s <= steps; ++s) {
      const double t = double(s) / steps;
      const int x = int(std::lround(x0 + (x1 - x0) * t)), y = int(std::lround(y0 + (y1 - y0) * t));
      rect(x - thickness / 2, y - thickness / 2, x - thickness / 2 + thickness, y - thickness / 2 + thickness, c);
    }
  }
  // stb_easy_font draws 7-pixel-high glyphs from quads; scale 2 for legibility.
  void text(int x, int y, const std::string& s, Rgb c, int scale = 2) {
    static thread_local std::vector<char> vertices(64 * 1024);
    std::string copy = s;
    const int quads = stb_easy_font_print(0, 0, copy.data(), nullptr, vertices.data(), int(vertices.size()));
    for (int q = 0; q < quads; ++q) {
      const float* v0 = reinterpret_cast<const float*>(&vertices[size_t(q) * 64]);
      const float* v2 = reinterpret_cast<const float*>(&vertices[size_t(q) * 64 + 32]);
      rect(x + int(v0[0]) * scale, y + int(v0[1]) * scale, x + int(v2[0]) * scale, y + int(v2[1]) * scale, c);
    }
  }
  static int textWidth(const std::string& s, int scale = 2) {
    std::string copy = s;
    return stb_easy_font_width(copy.data()) * scale;
  }
  PlotPixels take() { return std::move(out_); }

 private:
  PlotPixels out_;
};

std::string decadeLabel(int e) {
  char buf[16];
  std::snprintf(buf, sizeof(buf), "1e%d", e);
  return buf;
}

}  // namespace

PlotPixels plotLogLog(const std::vector<PlotSeries>& series, const std::string& title, const std::string& xLabel,
                      const std::string& yLabel, int width, int height) {
  Canvas canvas(width, height);
  // Data bounds in decades, over the usable points only.
  double lx0 = INFINITY, lx1 = -INFINITY, ly0 = INFINITY, ly1 = -INFINITY;
  for (const PlotSeries& s : series)
    for (size_t i = 0; i < std::min(s.x.size(), s.y.size()); ++i)
      if (s.x[i] > 0 && s.y[i] > 0 && std::isfinite(s.x[i]) && std::isfinite(s.y[i])) {
        lx0 = std::min(lx0, std::log10(s.x[i]));
        lx1 = std::max(lx1, std::log10(s.x[i]));
        ly0 = std::min(ly0, std::log10(s.y[i]));
        ly1 = std::max(ly1, std::log10(s.y[i]));
      }
  if (!std::isfinite(lx0)) lx0 = 0, lx1 = 1, ly0 = -3, ly1 = 0;
  const int ex0 = int(std::floor(lx0)), ex1 = std::max(ex0 + 1, int(std::ceil(lx1)));
  const int ey0 = int(std::floor(ly0)), ey1 = std::max(ey0 + 1, int(std::ceil(ly1)));
  const int left = 90, right = width - 170, top = 50, bottom = height - 60;
  auto px = [&](double v) { return left + (std::log10(v) - ex0) / (ex1 - ex0) * (right - left); };
  auto py = [&](double v) { return bottom - (std::log10(v) - ey0) / (ey1 - ey0) * (bottom - top); };

  const Rgb grid{225, 225, 225}, ink{40, 40, 40};
  for (int e = ex0; e <= ex1; ++e) {
    const double x = px(std::pow(10.0, e));
    canvas.line(x, top, x, bottom, grid, 1);
    canvas.text(int(x) - Canvas::textWidth(decadeLabel(e)) / 2, bottom + 10, decadeLabel(e), ink);
  }
  for (int e = ey0; e <= ey1; ++e) {
    const double y = py(std::pow(10.0, e));
    canvas.line(left, y, right, y, grid, 1);
    canvas.text(left - 10 - Canvas::textWidth(decadeLabel(e)), int(y) - 7, decadeLabel(e), ink);
  }
  canvas.line(left, top, left, bottom, ink, 2);
  canvas.line(left, bottom, right, bottom, ink, 2);
  canvas.text(left, 15, title, ink);
  canvas.text((left + right) / 2 - Canvas::textWidth(xLabel) / 2, bottom + 34, xLabel, ink);
  canvas.text(10, top - 30, yLabel, ink);

  for (size_t k = 0; k < series.size(); ++k) {
    const Rgb colour = kSeriesColours[k % std::size(kSeriesColours)];
    const PlotSeries& s = series[k];
    bool havePrevious = false;
    double prevX = 0, prevY = 0;
    for (size_t i = 0; i < std::min(s.x.size(), s.y.size()); ++i) {
      if (!(s.x[i] > 0 && s.y[i] > 0 && std::isfinite(s.x[i]) && std::isfinite(s.y[i]))) continue;
      const double x = px(s.x[i]), y = py(s.y[i]);
      if (havePrevious) canvas.line(prevX, prevY, x, y, colour, 3);
      canvas.rect(int(x) - 4, int(y) - 4, int(x) + 5, int(y) + 5, colour);
      prevX = x;
      prevY = y;
      havePrevious = true;
    }
    const int ly = top + 10 + int(k) * 26;
    canvas.rect(right + 20, ly, right + 44, ly + 14, colour);
    canvas.text(right + 52, ly, s.name, ink);
  }
  return canvas.take();
}

}  // namespace vpl
