// One error-against-time plot of gi-bench, as data, drawn twice: as SVG (report.cpp) and as
// PNG by a small rasteriser of its own (plot_raster.cpp: lines, discs, a 5x7 bitmap font), so
// the report shows in any viewer. Both share the layout below.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "gi/image_io.h"

namespace gi::bench {

struct PlotPoint {
  double time = 0.0, timeLo = 0.0, timeHi = 0.0;  // median ms and its interval (error bar)
  double error = 0.0;                             // NRMSE
  std::string label;                              // "ssao.samples=16" (the swept setting)
  bool front = false;                             // on the Pareto front
};
struct PlotSeries {
  std::string name;               // the legend: preset and the other grid settings
  std::vector<PlotPoint> points;  // in swept-value order
};
struct Plot {
  std::string title, xLabel, yLabel;
  std::vector<PlotSeries> series;
  std::vector<PlotPoint> front;  // the Pareto front in time order (a staircase)
};

// Layout shared by both renderings (pixels). The error axis runs from 0; the time axis too,
// unless the times span more than 10x: then it is logarithmic over whole decades
// [xMin, xMax] (ticks 1, 2, 5 per decade), so a 12 ms and a 700 ms point both stay readable.
struct PlotLayout {
  double width = 760, height = 480, left = 70, right = 230, top = 40, bottom = 50;
  double xMin = 0, xMax = 1, yMax = 1;  // axis ranges from "nice" ticks
  bool logX = false;
  std::vector<double> xTicks, yTicks;
  double x(double t) const;
  double y(double e) const { return top + (height - top - bottom) * (1.0 - e / yMax); }
  // Per series, per point: whether its label and values are drawn. A label that would overlap
  // one already placed (series in order, points in order) is left out; the SVG keeps every
  // point's values in its tooltip.
  std::vector<std::vector<bool>> labelShown;
  std::string xLabel(const Plot& plot) const;  // the plot's, with ", log scale" when logX
};
PlotLayout layoutFor(const Plot& plot);
const char* seriesColour(size_t i);  // "#rrggbb"
std::string formatTick(double v);
std::string pointValues(const PlotPoint& p);  // "2.1 ms, 0.123"

std::string svgPlot(const Plot& plot);
ImageRGBA8 rasterPlot(const Plot& plot);

}  // namespace gi::bench
