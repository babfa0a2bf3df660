// The PNG rendering of a gi-bench plot: a small rasteriser (no library) drawing the same layout
// as the SVG (plot.h): grid, axes, series polylines with their points, time error bars, point
// labels (swept setting, then time and NRMSE), the Pareto front (dashed staircase, rings) and
// the legend. Text uses a 5x7 bitmap font, scaled by whole pixels.
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <string>

#include "plot.h"

namespace gi::bench {

namespace {

// 5x7 glyphs as 5 columns of 7 bits (bit 0 the top row), for the characters of kGlyphChars.
constexpr const char* kGlyphChars =
    " !\"#%'()*+,-./0123456789:;<=>?ABCDEFGHIJKLMNOPQRSTUVWXYZ[]_abcdefghijklmnopqrstuvwxyz|";
constexpr uint8_t kGlyphs[][5] = {
    {0x00, 0x00, 0x00, 0x00, 0x00}, {0x00, 0x00, 0x5F, 0x00, 0x00},  // space !
    {0x00, 0x07, 0x00, 0x07, 0x00}, {0x14, 0x7F, 0x14, 0x7F, 0x14},  // " #
    {0x23, 0x13, 0x08, 0x64, 0x62}, {0x00, 0x05, 0x03, 0x00, 0x00},  // % '
    {0x00, 0x1C, 0x22, 0x41, 0x00}, {0x00, 0x41, 0x22, 0x1C, 0x00},  // ( )
    {0x14, 0x08, 0x3E, 0x08, 0x14}, {0x08, 0x08, 0x3E, 0x08, 0x08},  // * +
    {0x00, 0x50, 0x30, 0x00, 0x00}, {0x08, 0x08, 0x08, 0x08, 0x08},  // , -
    {0x00, 0x60, 0x60, 0x00, 0x00}, {0x20, 0x10, 0x08, 0x04, 0x02},  // . /
    {0x3E, 0x51, 0x49, 0x45, 0x3E}, {0x00, 0x42, 0x7F, 0x40, 0x00},  // 0 1
    {0x42, 0x61, 0x51, 0x49, 0x46}, {0x21, 0x41, 0x45, 0x4B, 0x31},  // 2 3
    {0x18, 0x14, 0x12, 0x7F, 0x10}, {0x27, 0x45, 0x45, 0x45, 0x39},  // 4 5
    {0x3C, 0x4A, 0x49, 0x49, 0x30}, {0x01, 0x71, 0x09, 0x05, 0x03},  // 6 7
    {0x36, 0x49, 0x49, 0x49, 0x36}, {0x06, 0x49, 0x49, 0x29, 0x1E},  // 8 9
    {0x00, 0x36, 0x36, 0x00, 0x00}, {0x00, 0x56, 0x36, 0x00, 0x00},  // : ;
    {0x08, 0x14, 0x22, 0x41, 0x00}, {0x14, 0x14, 0x14, 0x14, 0x14},  // < =
    {0x00, 0x41, 0x22, 0x14, 0x08}, {0x02, 0x01, 0x51, 0x09, 0x06},  // > ?
    {0x7E, 0x11, 0x11, 0x11, 0x7E}, {0x7F, 0x49, 0x49, 0x49, 0x36},  // A B
    {0x3E, 0x41, 0x41, 0x41, 0x22}, {0x7F, 0x41, 0x41, 0x22, 0x1C},  // C D
    {0x7F, 0x49, 0x49, 0x49, 0x41}, {0x7F, 0x09, 0x09, 0x09, 0x01},  // E F
    {0x3E, 0x41, 0x49, 0x49, 0x7A}, {0x7F, 0x08, 0x08, 0x08, 0x7F},  // G H
    {0x00, 0x41, 0x7F, 0x41, 0x00}, {0x20, 0x40, 0x41, 0x3F, 0x01},  // I J
    {0x7F, 0x08, 0x14, 0x22, 0x41}, {0x7F, 0x40, 0x40, 0x40, 0x40},  // K L
    {0x7F, 0x02, 0x0C, 0x02, 0x7F}, {0x7F, 0x04, 0x08, 0x10, 0x7F},  // M N
    {0x3E, 0x41, 0x41, 0x41, 0x3E}, {0x7F, 0x09, 0x09, 0x09, 0x06},  // O P
    {0x3E, 0x41, 0x51, 0x21, 0x5E}, {0x7F, 0x09, 0x19, 0x29, 0x46},  // Q R
    {0x46, 0x49, 0x49, 0x49, 0x31}, {0x01, 0x01, 0x7F, 0x01, 0x01},  // S T
    {0x3F, 0x40, 0x40, 0x40, 0x3F}, {0x1F, 0x20, 0x40, 0x20, 0x1F},  // U V
    {0x3F, 0x40, 0x38, 0x40, 0x3F}, {0x63, 0x14, 0x08, 0x14, 0x63},  // W X
    {0x07, 0x08, 0x70, 0x08, 0x07}, {0x61, 0x51, 0x49, 0x45, 0x43},  // Y Z
    {0x00, 0x7F, 0x41, 0x41, 0x00}, {0x00, 0x41, 0x41, 0x7F, 0x00},  // [ ]
    {0x40, 0x40, 0x40, 0x40, 0x40},                                  // _
    {0x20, 0x54, 0x54, 0x54, 0x78}, {0x7F, 0x48, 0x44, 0x44, 0x38},  // a b
    {0x38, 0x44, 0x44, 0x44, 0x20}, {0x38, 0x44, 0x44, 0x48, 0x7F},  // c d
    {0x38, 0x54, 0x54, 0x54, 0x18}, {0x08, 0x7E, 0x09, 0x01, 0x02},  // e f
    {0x0C, 0x52, 0x52, 0x52, 0x3E}, {0x7F, 0x08, 0x04, 0x04, 0x78},  // g h
    {0x00, 0x44, 0x7D, 0x40, 0x00}, {0x20, 0x40, 0x44, 0x3D, 0x00},  // i j
    {0x7F, 0x10, 0x28, 0x44, 0x00}, {0x00, 0x41, 0x7F, 0x40, 0x00},  // k l
    {0x7C, 0x04, 0x18, 0x04, 0x78}, {0x7C, 0x08, 0x04, 0x04, 0x78},  // m n
    {0x38, 0x44, 0x44, 0x44, 0x38}, {0x7C, 0x14, 0x14, 0x14, 0x08},  // o p
    {0x08, 0x14, 0x14, 0x18, 0x7C}, {0x7C, 0x08, 0x04, 0x04, 0x08},  // q r
    {0x48, 0x54, 0x54, 0x54, 0x20}, {0x04, 0x3F, 0x44, 0x40, 0x20},  // s t
    {0x3C, 0x40, 0x40, 0x20, 0x7C}, {0x1C, 0x20, 0x40, 0x20, 0x1C},  // u v
    {0x3C, 0x40, 0x30, 0x40, 0x3C}, {0x44, 0x28, 0x10, 0x28, 0x44},  // w x
    {0x0C, 0x50, 0x50, 0x50, 0x3C}, {0x44, 0x64, 0x54, 0x4C, 0x44},  // y z
    {0x00, 0x00, 0x7F, 0x00, 0x00},                                  // |
};
static_assert(sizeof(kGlyphs) / sizeof(kGlyphs[0]) == std::char_traits<char>::length(kGlyphChars));

const uint8_t* glyph(char c) {
  const std::string chars = kGlyphChars;
  size_t i = chars.find(c);
  if (i == std::string::npos) i = chars.find('?');
  return kGlyphs[i];
}

struct Rgb {
  uint8_t r, g, b;
};

Rgb parseColour(const char* hex) {  // "#rrggbb"
  const long v = std::strtol(hex + 1, nullptr, 16);
  return {uint8_t(v >> 16), uint8_t(v >> 8), uint8_t(v)};
}

class Canvas {
 public:
  Canvas(int w, int h) {
    image_.width = w;
    image_.height = h;
    image_.pixels.assign(size_t(w) * size_t(h) * 4, 255);
  }
  ImageRGBA8 take() { return std::move(image_); }

  void pixel(int x, int y, Rgb c) {
    if (x < 0 || y < 0 || x >= image_.width || y >= image_.height) return;
    uint8_t* p = &image_.pixels[(size_t(y) * size_t(image_.width) + size_t(x)) * 4];
    p[0] = c.r, p[1] = c.g, p[2] = c.b, p[3] = 255;
  }
  void disc(double cx, double cy, double r, Rgb c) {
    for (int y = int(std::floor(cy - r)); y <= int(std::ceil(cy + r)); ++y)
      for (int x = int(std::floor(cx - r)); x <= int(std::ceil(cx + r)); ++x)
        if ((x + 0.5 - cx) * (x + 0.5 - cx) + (y + 0.5 - cy) * (y + 0.5 - cy) <= r * r)
          pixel(x, y, c);
  }
  void ring(double cx, double cy, double r, Rgb c) {
    const int steps = std::max(16, int(8 * r));
    for (int i = 0; i < steps; ++i) {
      const double a = 2.0 * 3.14159265358979323846 * i / steps;
      disc(cx + r * std::cos(a), cy + r * std::sin(a), 0.7, c);
    }
  }
  // A line of `width` pixels; dash > 0 draws `dash` pixels on, dash * 0.75 off.
  void line(double x0, double y0, double x1, double y1, Rgb c, double width = 1.0,
            double dash = 0.0) {
    const double len = std::hypot(x1 - x0, y1 - y0);
    const int steps = std::max(1, int(std::ceil(len * 2)));
    for (int i = 0; i <= steps; ++i) {
      const double t = double(i) / steps, d = t * len;
      if (dash > 0 && std::fmod(d, dash * 1.75) > dash) continue;
      const double x = x0 + t * (x1 - x0), y = y0 + t * (y1 - y0);
      if (width <= 1.0)
        pixel(int(std::floor(x)), int(std::floor(y)), c);
      else
        disc(x, y, width / 2, c);
    }
  }
  // Text with its top-left corner at (x, y); `vertical` runs it upwards from (x, y) bottom-left.
  void text(double x, double y, const std::string& s, Rgb c, int scale = 1, bool vertical = false) {
    int pen = 0;
    for (char ch : s) {
      const uint8_t* g = glyph(ch);
      for (int col = 0; col < 5; ++col)
        for (int row = 0; row < 7; ++row)
          if (g[col] >> row & 1)
            for (int sy = 0; sy < scale; ++sy)
              for (int sx = 0; sx < scale; ++sx) {
                const int gx = (pen + col) * scale + sx, gy = row * scale + sy;
                if (vertical)
                  pixel(int(x) + gy, int(y) - gx, c);
                else
                  pixel(int(x) + gx, int(y) + gy, c);
              }
      pen += 6;
    }
  }
  static double textWidth(const std::string& s, int scale = 1) {
    return double(s.size()) * 6.0 * scale;
  }

 private:
  ImageRGBA8 image_;
};

}  // namespace

ImageRGBA8 rasterPlot(const Plot& plot) {
  const PlotLayout l = layoutFor(plot);
  const double pw = l.width - l.left - l.right, ph = l.height - l.top - l.bottom;
  Canvas cv(int(l.width), int(l.height));
  const Rgb black{0, 0, 0}, grid{221, 221, 221}, grey{85, 85, 85};
  cv.text(l.left, 14, plot.title, black, 1);
  for (double t : l.xTicks) {
    cv.line(l.x(t), l.top, l.x(t), l.top + ph, grid);
    const std::string s = formatTick(t);
    cv.text(l.x(t) - Canvas::textWidth(s) / 2, l.top + ph + 6, s, black);
  }
  for (double e : l.yTicks) {
    cv.line(l.left, l.y(e), l.left + pw, l.y(e), grid);
    const std::string s = formatTick(e);
    cv.text(l.left - 6 - Canvas::textWidth(s), l.y(e) - 3, s, black);
  }
  cv.line(l.left, l.top, l.left + pw, l.top, black);
  cv.line(l.left, l.top + ph, l.left + pw, l.top + ph, black);
  cv.line(l.left, l.top, l.left, l.top + ph, black);
  cv.line(l.left + pw, l.top, l.left + pw, l.top + ph, black);
  const std::string xLabel = l.xLabel(plot);
  cv.text(l.left + pw / 2 - Canvas::textWidth(xLabel) / 2, l.height - 20, xLabel, black);
  cv.text(14, l.top + ph / 2 + Canvas::textWidth(plot.yLabel) / 2, plot.yLabel, black, 1, true);
  for (size_t s = 0; s < plot.series.size(); ++s) {
    const PlotSeries& ser = plot.series[s];
    const Rgb c = parseColour(seriesColour(s));
    for (size_t k = 1; k < ser.points.size(); ++k)
      cv.line(l.x(ser.points[k - 1].time), l.y(ser.points[k - 1].error), l.x(ser.points[k].time),
              l.y(ser.points[k].error), c, 1.5);
    for (size_t k = 0; k < ser.points.size(); ++k) {
      const PlotPoint& p = ser.points[k];
      const double x = l.x(p.time), y = l.y(p.error);
      cv.line(l.x(p.timeLo), y, l.x(p.timeHi), y, c);
      cv.line(l.x(p.timeLo), y - 4, l.x(p.timeLo), y + 4, c);
      cv.line(l.x(p.timeHi), y - 4, l.x(p.timeHi), y + 4, c);
      cv.disc(x, y, 3.5, c);
      if (!l.labelShown[s][k]) continue;
      cv.text(x + 6, y - 13, p.label, c);
      cv.text(x + 6, y + 6, pointValues(p), grey);
    }
    const double ly = l.top + 10 + 18 * double(s);
    cv.line(l.left + pw + 12, ly, l.left + pw + 32, ly, c, 2.0);
    cv.text(l.left + pw + 36, ly - 3, ser.name, black);
  }
  for (size_t k = 0; k < plot.front.size(); ++k) {
    const PlotPoint& p = plot.front[k];
    if (k > 0) {
      const double yPrev = l.y(plot.front[k - 1].error);
      cv.line(l.x(plot.front[k - 1].time), yPrev, l.x(p.time), yPrev, black, 1.0, 4.0);
      cv.line(l.x(p.time), yPrev, l.x(p.time), l.y(p.error), black, 1.0, 4.0);
    }
    cv.ring(l.x(p.time), l.y(p.error), 7.0, black);
  }
  if (!plot.front.empty()) {
    const double ly = l.top + 10 + 18 * double(plot.series.size());
    cv.ring(l.left + pw + 22, ly, 6.0, black);
    cv.text(l.left + pw + 36, ly - 3, "Pareto front", black);
  }
  return cv.take();
}

}  // namespace gi::bench
