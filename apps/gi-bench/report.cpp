// gi-bench outputs: CSV, JSON, a Markdown report and SVG + PNG plots (written by hand, no
// plotting library): NRMSE against time per scene and effect, one polyline per series, error
// bars, the Pareto front.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <set>
#include <sstream>
#include <tuple>

#include <nlohmann/json.hpp>

#include "bench.h"
#include "cli.h"
#include "gi/errors.h"
#include "gi/image_io.h"
#include "plot.h"
#include "stats.h"

namespace gi::bench {

namespace fs = std::filesystem;

using gi::cli::writeFileAtomic;

double plotTime(const Row& row) {
  return row.effectMs > 0.0 ? row.effectMs : row.totalMs;
}

Interval plotInterval(const Row& row) {
  return row.effectMs > 0.0 ? row.effectCi : row.totalCi;
}

std::vector<size_t> paretoFront(const std::vector<const Row*>& rows) {
  std::vector<TradeoffPoint> points;
  for (const Row* r : rows) points.push_back({plotInterval(*r), r->nrmse});
  return paretoFront(points);
}

double loadAverage() {
  std::ifstream in("/proc/loadavg");
  double load = -1.0;
  if (!(in >> load)) return -1.0;
  return load;
}

void fillRecovered(std::vector<Row>& rows) {
  auto startsWith = [](const std::string& s, const char* p) { return s.rfind(p, 0) == 0; };
  for (Row& r : rows) {
    const auto alone = std::find_if(rows.begin(), rows.end(), [&](const Row& n) {
      return n.effect == "none" && n.params.empty() && n.scene == r.scene && n.preset == r.preset &&
             n.width == r.width && n.height == r.height && n.reference == r.reference;
    });
    if (alone == rows.end()) continue;
    r.recoveredPresent = true;
    r.aloneNrmse = alone->nrmse;
    r.errorRemoved = alone->nrmse > 0.0 ? 1.0 - r.nrmse / alone->nrmse : 0.0;
    // The reference's indirect light: the target minus the direct reference the engine alone
    // declares, both over the scored pixels.
    const double indirect = alone->targetMean - alone->declaredMean;
    if (startsWith(r.reference, "direct+indirect") && startsWith(alone->declared, "direct ") &&
        indirect > 1e-9) {
      r.indirectPresent = true;
      r.indirectDelivered = (r.testMean - alone->testMean) / indirect;
    }
  }
}

namespace {

std::string fmt(double v, int digits = 4) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.*g", digits, v);
  return buf;
}

std::string csvField(const std::string& s) {
  if (s.find_first_of(",\"\n") == std::string::npos) return s;
  std::string out = "\"";
  for (char c : s) out += c == '"' ? std::string("\"\"") : std::string(1, c);
  return out + "\"";
}

// "gbuffer=1.2[1.1,1.3] ssao=3.4[3.3,3.6]": median and interval per pass.
std::string passList(const Row& r) {
  std::string s;
  for (const PassTime& p : r.passes)
    s += (s.empty() ? "" : " ") + p.name + "=" + fmt(p.ms.median) + "[" + fmt(p.ms.lo) + "," +
         fmt(p.ms.hi) + "]";
  return s;
}

std::string withInterval(const Interval& i, int digits = 4) {
  return fmt(i.median, digits) + " [" + fmt(i.lo, digits) + ", " + fmt(i.hi, digits) + "]";
}

std::string fileSafe(const std::string& s) {
  std::string out;
  for (char c : s) out += std::isalnum(static_cast<unsigned char>(c)) ? c : '_';
  return out;
}

bool anySplit(const std::vector<Row>& rows) {
  return std::any_of(rows.begin(), rows.end(), [](const Row& r) { return r.split.present; });
}

// One line per configuration and repetition: repetition r of every configuration ran in the
// same round-robin round, so a ratio of two configurations' times can be formed round by round
// (paired), which cancels load that drifts between rounds; only within one interleave batch
// (`batch`: at most 16 configurations are alive, and measured round-robin, at once).
std::string repetitionsCsv(const std::vector<Row>& rows) {
  std::ostringstream o;
  o << "scene,effect,preset,params,batch,rep,effect_ms,floor_ms,passes_ms,effect_min_ms,"
       "passes_min_ms,effect_cpu_ms,passes_cpu_ms\n";
  for (const Row& r : rows)
    for (size_t k = 0; k < r.effectReps.size(); ++k) {
      std::string passes, mins, cpu;
      for (const PassTime& p : r.passes) {
        if (k < p.reps.size())
          passes += (passes.empty() ? "" : " ") + p.name + "=" + fmt(p.reps[k], 6);
        if (k < p.repsMin.size())
          mins += (mins.empty() ? "" : " ") + p.name + "=" + fmt(p.repsMin[k], 6);
        if (k < p.repsCpu.size())
          cpu += (cpu.empty() ? "" : " ") + p.name + "=" + fmt(p.repsCpu[k], 6);
      }
      o << csvField(r.scene) << ',' << csvField(r.effect) << ',' << csvField(r.preset) << ','
        << csvField(r.params) << ',' << r.batch << ',' << k << ',' << fmt(r.effectReps[k], 6) << ','
        << fmt(k < r.floorReps.size() ? r.floorReps[k] : 0.0, 6) << ',' << csvField(passes) << ','
        << fmt(k < r.effectRepsMin.size() ? r.effectRepsMin[k] : 0.0, 6) << ',' << csvField(mins)
        << ',' << fmt(k < r.effectRepsCpu.size() ? r.effectRepsCpu[k] : -1.0, 6) << ','
        << csvField(cpu) << '\n';
    }
  return o.str();
}

std::string csv(const std::vector<Row>& rows) {
  std::ostringstream o;
  const bool split = anySplit(rows);
  o << "scene,effect,preset,params,width,height,frames,reps,passes_ms,total_ms,total_lo_ms,"
       "total_hi_ms,effect_ms,effect_lo_ms,effect_hi_ms,interval_coverage,floor_ms,"
       "total_over_floor,effect_over_floor,wall_ms,compared,reference,reference_spp,"
       "reference_stderr,pixels,nrmse,ssim,declared,declared_stderr,declared_nrmse,"
       "declared_ssim,gap_nrmse,gap_share,noise_floor,normaliser,normaliser_pixels,noise_capped,"
       "error_removed,indirect_delivered";
  // --ao-split runs only, so that other runs keep their columns.
  if (split)
    o << ",reference_seconds,limit_nrmse,offscreen_nrmse,hidden_nrmse,estimator_nrmse,"
         "visible_fraction,offscreen_fraction,hidden_fraction,share_offscreen,share_hidden,"
         "share_estimator";
  o << '\n';
  for (const Row& r : rows) {
    o << csvField(r.scene) << ',' << csvField(r.effect) << ',' << csvField(r.preset) << ','
      << csvField(r.params) << ',' << r.width << ',' << r.height << ',' << r.frames << ',' << r.reps
      << ',' << csvField(passList(r)) << ',' << fmt(r.totalMs, 6) << ',' << fmt(r.totalCi.lo, 6)
      << ',' << fmt(r.totalCi.hi, 6) << ',' << fmt(r.effectMs, 6) << ',' << fmt(r.effectCi.lo, 6)
      << ',' << fmt(r.effectCi.hi, 6) << ',' << fmt(r.totalCi.coverage, 6) << ','
      << fmt(r.floorMs, 6) << ',' << fmt(r.floorMs > 0 ? r.totalMs / r.floorMs : 0.0, 6) << ','
      << fmt(r.floorMs > 0 ? r.effectMs / r.floorMs : 0.0, 6) << ',' << fmt(r.wallMs, 6) << ','
      << r.compared << ',' << csvField(r.reference) << ',' << r.referenceSpp << ','
      << fmt(r.referenceStdError, 6) << ',' << r.pixels << ',' << fmt(r.nrmse, 6) << ','
      << fmt(r.ssim, 6) << ',' << csvField(r.declared) << ',' << fmt(r.declaredStdError, 6) << ','
      << fmt(r.declaredNrmse, 6) << ',' << fmt(r.declaredSsim, 6) << ','
      << (r.gapPresent ? fmt(r.gapNrmse, 6) : std::string()) << ','
      << (r.gapPresent ? fmt(r.gapShare, 6) : std::string()) << ',' << fmt(r.noiseFloor, 6) << ','
      << fmt(r.normaliser, 6) << ',' << r.normaliserPixels << ',' << (r.noiseCapped ? 1 : 0) << ','
      << (r.recoveredPresent ? fmt(r.errorRemoved, 6) : std::string()) << ','
      << (r.indirectPresent ? fmt(r.indirectDelivered, 6) : std::string());
    if (split) {
      const Row::AoSplit& s = r.split;
      o << ',' << fmt(r.referenceSeconds, 6);
      for (double v : {s.limitNrmse, s.offscreenNrmse, s.hiddenNrmse, s.estimatorNrmse,
                       s.visibleFraction, s.offscreenFraction, s.hiddenFraction, s.shareOffscreen,
                       s.shareHidden, s.shareEstimator})
        o << ',' << (s.present ? fmt(v, 6) : std::string());
    }
    o << '\n';
  }
  return o.str();
}

std::string json(const std::vector<Row>& rows, const RunInfo& info) {
  nlohmann::json j;
  j["device"] = info.device;
  j["command"] = info.commandLine;
  j["date"] = info.date;
  j["seconds"] = info.seconds;
  j["results"] = nlohmann::json::array();
  for (const Row& r : rows) {
    nlohmann::json p = nlohmann::json::object(), passes = nlohmann::json::array();
    auto ci = [](const Interval& i) {
      return nlohmann::json{{"median", i.median},     {"lo", i.lo},        {"hi", i.hi},
                            {"coverage", i.coverage}, {"reps", i.samples}, {"values", i.values}};
    };
    for (const PassTime& pt : r.passes)
      passes.push_back({{"pass", pt.name}, {"ms", pt.ms.median}, {"interval", ci(pt.ms)}});
    j["results"].push_back({{"scene", r.scene},
                            {"effect", r.effect},
                            {"preset", r.preset},
                            {"params", r.params},
                            {"width", r.width},
                            {"height", r.height},
                            {"frames", r.frames},
                            {"reps", r.reps},
                            {"passes", passes},
                            {"total_ms", r.totalMs},
                            {"total_interval", ci(r.totalCi)},
                            {"effect_interval", ci(r.effectCi)},
                            {"floor_interval", ci(r.floorCi)},
                            {"wall_interval", ci(r.wallCi)},
                            {"effect_ms", r.effectMs},
                            {"floor_ms", r.floorMs},
                            {"total_over_floor", r.floorMs > 0 ? r.totalMs / r.floorMs : 0.0},
                            {"effect_over_floor", r.floorMs > 0 ? r.effectMs / r.floorMs : 0.0},
                            {"wall_ms", r.wallMs},
                            {"compared", r.compared},
                            {"reference", r.reference},
                            {"reference_spp", r.referenceSpp},
                            {"reference_stderr", r.referenceStdError},
                            {"pixels", r.pixels},
                            {"nrmse", r.nrmse},
                            {"noise_floor", r.noiseFloor},
                            {"noise_capped", r.noiseCapped},
                            {"normaliser", r.normaliser},
                            {"normaliser_pixels", r.normaliserPixels},
                            {"ssim", r.ssim},
                            {"declared", r.declared},
                            {"declared_stderr", r.declaredStdError},
                            {"declared_nrmse", r.declaredNrmse},
                            {"declared_ssim", r.declaredSsim},
                            {"reference_seconds", r.referenceSeconds}});
    if (r.gapPresent)
      j["results"].back()["quantity_gap"] = {{"gap_nrmse", r.gapNrmse}, {"gap_share", r.gapShare}};
    for (const Row::RegionScore& g : r.regions)
      j["results"].back()["regions"].push_back(
          {{"name", g.name}, {"nrmse", g.nrmse}, {"pixels", g.pixels}});
    if (r.recoveredPresent) j["results"].back()["error_removed"] = r.errorRemoved;
    if (r.indirectPresent) j["results"].back()["indirect_delivered"] = r.indirectDelivered;
    if (r.split.present) {
      const Row::AoSplit& s = r.split;
      j["results"].back()["ao_split"] = {
          {"limit_nrmse", s.limitNrmse},           {"offscreen_nrmse", s.offscreenNrmse},
          {"hidden_nrmse", s.hiddenNrmse},         {"estimator_nrmse", s.estimatorNrmse},
          {"visible_fraction", s.visibleFraction}, {"offscreen_fraction", s.offscreenFraction},
          {"hidden_fraction", s.hiddenFraction},   {"share_offscreen", s.shareOffscreen},
          {"share_hidden", s.shareHidden},         {"share_estimator", s.shareEstimator}};
    }
  }
  return j.dump(2) + "\n";
}

std::string percent(double v) {
  return fmt(100.0 * v, 3) + "%";
}

// "Nice" axis ticks covering [0, hi].
std::vector<double> ticks(double hi) {
  if (!(hi > 0) || !std::isfinite(hi)) hi = 1;
  const double raw = hi / 5.0, mag = std::pow(10.0, std::floor(std::log10(raw)));
  const double step = raw / mag < 1.5   ? mag
                      : raw / mag < 3.5 ? 2 * mag
                      : raw / mag < 7.5 ? 5 * mag
                                        : 10 * mag;
  std::vector<double> t;
  for (double v = 0; v <= hi * 1.0001 + step * 1e-9; v += step) t.push_back(v);
  if (t.back() < hi) t.push_back(t.back() + step);
  return t;
}

std::string xmlEscape(const std::string& s) {
  std::string o;
  for (char c : s)
    o += c == '<' ? "&lt;" : c == '>' ? "&gt;" : c == '&' ? "&amp;" : std::string(1, c);
  return o;
}

// Rows of one scene and effect as a plot: series by `Row::series`, points in swept-value
// order, labelled by the swept setting ("ssao.samples=16"), error bars from the intervals.
// `declared`: each row's error against the quantity its effect declares instead of the
// target (no Pareto front: the rows' quantities may differ).
Plot buildPlot(const std::string& title, const std::vector<const Row*>& rows,
               bool seriesByEffect = false, bool declared = false) {
  Plot p;
  p.title = title;
  const bool effectTime = !rows.empty() && rows.front()->effectMs > 0.0;
  p.xLabel = std::string(effectTime ? "effect" : "frame") + " GPU time, ms (median; bars: " +
             (rows.empty() ? std::string("-") : percent(rows.front()->totalCi.coverage)) +
             " interval)";
  p.yLabel = "NRMSE vs " + (rows.empty() ? std::string("reference")
                            : declared   ? std::string("each effect's declared quantity")
                                         : rows.front()->reference);
  const std::vector<size_t> front = declared ? std::vector<size_t>{} : paretoFront(rows);
  std::set<const Row*> onFront;
  for (size_t i : front) onFront.insert(rows[i]);
  auto point = [&](const Row* r) {
    const Interval t = plotInterval(*r);
    PlotPoint pt{
        t.median, t.lo, t.hi, declared ? r->declaredNrmse : r->nrmse, "", onFront.count(r) > 0};
    pt.label = r->gridKey.empty() ? (r->params.empty() ? r->preset : r->params)
                                  : r->gridKey + "=" + fmt(r->gridValue);
    return pt;
  };
  if (seriesByEffect) {  // one series per effect, points in time order: methods side by side
    std::map<std::string, size_t> index;
    for (const Row* r : rows) {
      if (!index.count(r->effect)) {
        index[r->effect] = p.series.size();
        p.series.push_back({r->effect, {}});
      }
    }
    for (auto& [effect, i] : index) {
      std::vector<const Row*> pts;
      for (const Row* r : rows)
        if (r->effect == effect) pts.push_back(r);
      std::stable_sort(pts.begin(), pts.end(),
                       [](const Row* a, const Row* b) { return plotTime(*a) < plotTime(*b); });
      for (const Row* r : pts) p.series[i].points.push_back(point(r));
    }
    for (size_t i : front) p.front.push_back(point(rows[i]));
    return p;
  }
  std::map<std::string, size_t> index;
  for (const Row* r : rows) {
    if (!index.count(r->series)) {
      index[r->series] = p.series.size();
      std::string name = r->series.empty() ? "default" : r->series;
      if (!r->gridKey.empty()) name += " (" + r->gridKey + ")";
      p.series.push_back({name, {}});
    }
  }
  for (auto& [key, i] : index) {
    std::vector<const Row*> pts;
    for (const Row* r : rows)
      if (r->series == key) pts.push_back(r);
    std::stable_sort(pts.begin(), pts.end(),
                     [](const Row* a, const Row* b) { return a->gridValue < b->gridValue; });
    for (const Row* r : pts) p.series[i].points.push_back(point(r));
  }
  for (size_t i : front) p.front.push_back(point(rows[i]));
  return p;
}

}  // namespace

double PlotLayout::x(double t) const {
  const double pw = width - left - right;
  if (!logX) return left + pw * t / xMax;
  const double lt = std::log10(std::max(t, xMin));
  return left + pw * (lt - std::log10(xMin)) / (std::log10(xMax) - std::log10(xMin));
}

std::string PlotLayout::xLabel(const Plot& plot) const {
  return plot.xLabel + (logX ? ", log scale" : "");
}

PlotLayout layoutFor(const Plot& plot) {
  PlotLayout l;
  double tmax = 0, tmin = INFINITY, emax = 0;
  for (const PlotSeries& s : plot.series)
    for (const PlotPoint& p : s.points) {
      tmax = std::max(tmax, std::max(p.time, p.timeHi));
      if (p.time > 0.0) tmin = std::min(tmin, std::min(p.time, p.timeLo > 0.0 ? p.timeLo : p.time));
      emax = std::max(emax, p.error);
    }
  if (std::isfinite(tmin) && tmin > 0.0 && tmax > 10.0 * tmin) {
    l.logX = true;
    l.xMin = std::pow(10.0, std::floor(std::log10(tmin)));
    l.xMax = std::pow(10.0, std::ceil(std::log10(tmax)));
    const int first = int(std::lround(std::log10(l.xMin))),
              last = int(std::lround(std::log10(l.xMax)));
    for (int e = first; e <= last; ++e)
      for (double m : {1.0, 2.0, 5.0})
        if (e < last || m == 1.0) l.xTicks.push_back(m * std::pow(10.0, double(e)));
  } else {
    l.xTicks = ticks(tmax);
    l.xMax = l.xTicks.back();
  }
  l.yTicks = ticks(emax);
  l.yMax = l.yTicks.back();
  // Labels: a box of ~6 px per character (both renderings' fonts), the label above the point
  // and its values below.
  struct Box {
    double x0, y0, x1, y1;
  };
  std::vector<Box> placed;
  for (const PlotSeries& s : plot.series) {
    l.labelShown.emplace_back();
    for (const PlotPoint& p : s.points) {
      const double x = l.x(p.time), y = l.y(p.error);
      const double w = 6.0 * double(std::max(p.label.size(), pointValues(p).size()));
      const Box b{x + 4, y - 16, x + 8 + w, y + 16};
      const bool free = std::none_of(placed.begin(), placed.end(), [&](const Box& o) {
        return b.x0 < o.x1 && o.x0 < b.x1 && b.y0 < o.y1 && o.y0 < b.y1;
      });
      l.labelShown.back().push_back(free);
      if (free) placed.push_back(b);
    }
  }
  return l;
}

const char* seriesColour(size_t i) {
  static const char* colours[] = {"#1f77b4", "#ff7f0e", "#2ca02c", "#d62728", "#9467bd",
                                  "#8c564b", "#e377c2", "#7f7f7f", "#bcbd22", "#17becf"};
  return colours[i % 10];
}

std::string formatTick(double v) {
  // Whole numbers as such (a log axis reaches 1000: "1000", not "1e+03").
  if (v >= 1.0 && v < 1e7 && v == std::floor(v)) return std::to_string(int64_t(v));
  return fmt(v, 3);
}

std::string pointValues(const PlotPoint& p) {
  return fmt(p.time, 3) + " ms, " + fmt(p.error, 3);
}

std::string svgPlot(const Plot& plot) {
  const PlotLayout l = layoutFor(plot);
  const double pw = l.width - l.left - l.right, ph = l.height - l.top - l.bottom;
  std::ostringstream o;
  o << "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"" << l.width << "\" height=\"" << l.height
    << "\" viewBox=\"0 0 " << l.width << ' ' << l.height
    << "\" font-family=\"sans-serif\" font-size=\"12\">\n"
    << "<rect width=\"100%\" height=\"100%\" fill=\"white\"/>\n"
    << "<text x=\"" << l.left << "\" y=\"22\" font-size=\"15\">" << xmlEscape(plot.title)
    << "</text>\n";
  for (double t : l.xTicks)
    o << "<line x1=\"" << l.x(t) << "\" y1=\"" << l.top << "\" x2=\"" << l.x(t) << "\" y2=\""
      << l.top + ph << "\" stroke=\"#ddd\"/><text x=\"" << l.x(t) << "\" y=\"" << l.top + ph + 16
      << "\" text-anchor=\"middle\">" << formatTick(t) << "</text>\n";
  for (double e : l.yTicks)
    o << "<line x1=\"" << l.left << "\" y1=\"" << l.y(e) << "\" x2=\"" << l.left + pw << "\" y2=\""
      << l.y(e) << "\" stroke=\"#ddd\"/><text x=\"" << l.left - 6 << "\" y=\"" << l.y(e) + 4
      << "\" text-anchor=\"end\">" << formatTick(e) << "</text>\n";
  o << "<rect x=\"" << l.left << "\" y=\"" << l.top << "\" width=\"" << pw << "\" height=\"" << ph
    << "\" fill=\"none\" stroke=\"black\"/>\n"
    << "<text x=\"" << l.left + pw / 2 << "\" y=\"" << l.height - 12 << "\" text-anchor=\"middle\">"
    << xmlEscape(l.xLabel(plot)) << "</text>\n"
    << "<text transform=\"translate(18," << l.top + ph / 2
    << ") rotate(-90)\" text-anchor=\"middle\">" << xmlEscape(plot.yLabel) << "</text>\n";
  for (size_t s = 0; s < plot.series.size(); ++s) {
    const PlotSeries& ser = plot.series[s];
    const char* c = seriesColour(s);
    o << "<polyline fill=\"none\" stroke=\"" << c << "\" stroke-width=\"1.5\" points=\"";
    for (const PlotPoint& p : ser.points) o << l.x(p.time) << ',' << l.y(p.error) << ' ';
    o << "\"/>\n";
    for (size_t k = 0; k < ser.points.size(); ++k) {
      const PlotPoint& p = ser.points[k];
      const double x = l.x(p.time), y = l.y(p.error);
      // Error bar: the time interval, with end ticks.
      o << "<path d=\"M" << l.x(p.timeLo) << ' ' << y << "H" << l.x(p.timeHi) << "M"
        << l.x(p.timeLo) << ' ' << y - 4 << "v8M" << l.x(p.timeHi) << ' ' << y - 4
        << "v8\" stroke=\"" << c << "\" fill=\"none\"/>\n";
      o << "<circle cx=\"" << x << "\" cy=\"" << y << "\" r=\"3.5\" fill=\"" << c << "\"><title>"
        << xmlEscape(p.label) << ": " << fmt(p.time) << " ms [" << fmt(p.timeLo) << ", "
        << fmt(p.timeHi) << "], NRMSE " << fmt(p.error) << "</title></circle>\n";
      if (l.labelShown[s][k])
        o << "<text x=\"" << x + 6 << "\" y=\"" << y - 6 << "\" font-size=\"10\" fill=\"" << c
          << "\">" << xmlEscape(p.label) << "</text><text x=\"" << x + 6 << "\" y=\"" << y + 12
          << "\" font-size=\"9\" fill=\"#555\">" << xmlEscape(pointValues(p)) << "</text>\n";
    }
    const double ly = l.top + 10 + 18 * double(s);
    o << "<line x1=\"" << l.left + pw + 12 << "\" y1=\"" << ly << "\" x2=\"" << l.left + pw + 32
      << "\" y2=\"" << ly << "\" stroke=\"" << c << "\" stroke-width=\"2\"/><text x=\""
      << l.left + pw + 36 << "\" y=\"" << ly + 4 << "\">" << xmlEscape(ser.name) << "</text>\n";
  }
  // Pareto front: dashed staircase and rings.
  if (!plot.front.empty()) {
    o << "<polyline fill=\"none\" stroke=\"black\" stroke-dasharray=\"4 3\" points=\"";
    for (size_t k = 0; k < plot.front.size(); ++k) {
      const PlotPoint& p = plot.front[k];
      if (k > 0) o << l.x(p.time) << ',' << l.y(plot.front[k - 1].error) << ' ';
      o << l.x(p.time) << ',' << l.y(p.error) << ' ';
    }
    o << "\"/>\n";
    for (const PlotPoint& p : plot.front)
      o << "<circle cx=\"" << l.x(p.time) << "\" cy=\"" << l.y(p.error)
        << "\" r=\"7\" fill=\"none\" stroke=\"black\"/>\n";
    const double ly = l.top + 10 + 18 * double(plot.series.size());
    o << "<circle cx=\"" << l.left + pw + 22 << "\" cy=\"" << ly
      << "\" r=\"6\" fill=\"none\" stroke=\"black\"/><text x=\"" << l.left + pw + 36 << "\" y=\""
      << ly + 4 << "\">Pareto front (beyond the intervals)</text>\n";
  }
  o << "</svg>\n";
  return o.str();
}

namespace {

// "Where screen-space AO cannot converge" (--ao-split): per scene and AO effect, the reference's
// occlusion split by occluder class and the decomposition of the effect's error at its most
// expensive grid point, then the decomposition for every configuration.
std::string splitSection(const std::vector<Row>& rows) {
  std::ostringstream o;
  o << "\n## Where screen-space AO cannot converge\n\n"
    << "The ao-split reference (gi-reference `--quantity ao-split`, same rays as the AO "
       "reference) classifies every occluded AO direction: *visible* when a surface of the "
       "depth layer (the primary hits: what the depth buffer holds) lies on it within r, "
       "otherwise *off-screen* when its first hit is outside the view frustum, otherwise "
       "*hidden* (inside the frame, behind the visible surface there). The fractions are the "
       "shares of the cosine-weighted hemisphere each class occludes (so 1 - AO_full = visible "
       "+ off-screen + hidden), averaged over the compared pixels. AO_visible = 1 - visible "
       "fraction is the AO of the depth layer alone: the best a single-layer screen-space "
       "method can converge to. *Limit* is NRMSE(AO_visible vs AO_full) = RMS(O + H) / "
       "mean(AO_full), with O and H the per-pixel off-screen and hidden fractions; *off-screen "
       "alone* and *hidden alone* are RMS(O) and RMS(H) over the same mean (the NRMSE of an "
       "otherwise perfect method missing only that part). The effect's error e = SSAO - "
       "AO_full is exactly the sum O + H + E with E = SSAO - AO_visible (the estimator's own "
       "error against what it could reach); its mean squared error is split as mean(e O) + "
       "mean(e H) + mean(e E), each divided by mean(e^2): the shares sum to 100%, and a "
       "negative share means that part cancels some of the others (e.g. an estimator darker "
       "than AO_visible offsetting missing occluders). The reference time is the wall time of "
       "the split reference on this machine (cached runs repeat the time it took when "
       "computed).\n\n";
  std::vector<std::pair<std::string, std::string>> order;
  std::map<std::pair<std::string, std::string>, const Row*> top;
  for (const Row& r : rows) {
    if (!r.split.present) continue;
    const auto key = std::make_pair(r.scene, r.effect);
    if (!top.count(key)) order.push_back(key);
    if (!top.count(key) || r.gridValue >= top[key]->gridValue) top[key] = &r;
  }
  o << "| scene | reference | occluded: visible / off-screen / hidden | limit NRMSE "
       "(AO_visible vs AO_full) | off-screen alone | hidden alone | effect | NRMSE vs AO_full | "
       "NRMSE vs AO_visible (estimator) | share of MSE: off-screen / hidden / estimator |\n"
    << "|---|---|---|---:|---:|---:|---|---:|---:|---|\n";
  for (const auto& key : order) {
    const Row& r = *top[key];
    const Row::AoSplit& s = r.split;
    o << "| " << r.scene << " | " << r.referenceSpp << " spp, " << fmt(r.referenceSeconds, 3)
      << " s | " << percent(s.visibleFraction) << " / " << percent(s.offscreenFraction) << " / "
      << percent(s.hiddenFraction) << " | " << fmt(s.limitNrmse, 4) << " | "
      << fmt(s.offscreenNrmse, 4) << " | " << fmt(s.hiddenNrmse, 4) << " | " << r.effect
      << (r.params.empty() ? "" : " " + r.params) << " | " << fmt(r.nrmse, 4) << " | "
      << fmt(s.estimatorNrmse, 4) << " | " << percent(s.shareOffscreen) << " / "
      << percent(s.shareHidden) << " / " << percent(s.shareEstimator) << " |\n";
  }
  o << "\nEvery configuration:\n\n"
    << "| scene | effect | preset / params | NRMSE vs AO_full | NRMSE vs AO_visible | share of "
       "MSE: off-screen / hidden / estimator |\n"
    << "|---|---|---|---:|---:|---|\n";
  for (const Row& r : rows) {
    if (!r.split.present) continue;
    const Row::AoSplit& s = r.split;
    o << "| " << r.scene << " | " << r.effect << " | " << r.preset
      << (r.params.empty() ? "" : " " + r.params) << " | " << fmt(r.nrmse, 4) << " | "
      << fmt(s.estimatorNrmse, 4) << " | " << percent(s.shareOffscreen) << " / "
      << percent(s.shareHidden) << " / " << percent(s.shareEstimator) << " |\n";
  }
  return o.str();
}

// "0.58-1.66": the floor pass's medians over the rows (how much the cost unit itself varied).
std::string floorRange(const std::vector<Row>& rows) {
  double lo = INFINITY, hi = 0.0;
  for (const Row& r : rows) {
    lo = std::min(lo, r.floorMs);
    hi = std::max(hi, r.floorMs);
  }
  return rows.empty() ? std::string("-") : fmt(lo, 3) + "-" + fmt(hi, 3);
}

// Rows whose declared quantity is not their target: how much of the error against the target
// is the declared quantity's own distance from it (no estimator can remove that part).
std::string gapSection(const std::vector<Row>& rows) {
  std::ostringstream o;
  for (const Row& r : rows) {
    if (!r.gapPresent) continue;
    if (o.tellp() == 0)
      o << "\n## The declared quantity against the target\n\n"
           "e = effect - target = (effect - declared) + (declared - target). *Gap NRMSE* is "
           "NRMSE(declared vs target): the error against the target of a perfect estimator of "
           "what the effect declares. *Share of MSE* is mean(e (declared - target)) / mean(e^2): "
           "the part of this row's squared error against the target that the choice of "
           "quantity explains; the rest is the estimator's (sampling, screen-space limits, "
           "bias) against its own quantity.\n\n"
           "| scene | effect | preset / params | declared | target | NRMSE vs target | NRMSE vs "
           "declared | gap NRMSE | share of MSE: quantity gap / estimator |\n"
           "|---|---|---|---|---|---:|---:|---:|---|\n";
    o << "| " << r.scene << " | " << r.effect << " | " << r.preset
      << (r.params.empty() ? "" : " " + r.params) << " | " << r.declared << " | " << r.reference
      << " | " << fmt(r.nrmse, 4) << " | " << fmt(r.declaredNrmse, 4) << " | " << fmt(r.gapNrmse, 4)
      << " | " << fmt(100.0 * r.gapShare, 3) << "% / " << fmt(100.0 * (1.0 - r.gapShare), 3)
      << "% |\n";
  }
  return o.str();
}

// A warning listing the rows whose time interval is wider than their median: on a loaded
// machine such a time is no basis for a comparison (per-pass CPU time, --isolate-passes, is).
std::string wideIntervals(const std::vector<Row>& rows) {
  std::string list;
  size_t n = 0;
  for (const Row& r : rows) {
    const Interval& i = r.effectMs > 0.0 ? r.effectCi : r.totalCi;
    if (!(i.hi - i.lo > i.median)) continue;
    if (n++ < 12)
      list += (list.empty() ? "" : ", ") + r.scene + " " + r.effect + " " + r.preset +
              (r.params.empty() ? "" : " " + r.params);
  }
  if (n == 0) return "";
  return "**Warning:** " + std::to_string(n) + " of " + std::to_string(rows.size()) +
         " time intervals are wider than their median (" + list + (n > 12 ? ", ..." : "") +
         "): those times are inside the machine's noise; compare them by per-pass CPU time "
         "(--isolate-passes, repetitions.csv).\n\n";
}

// The effect passes' process CPU ms (median over repetitions) beside their GPU time, when
// measured (--isolate-passes): it stays within a few percent on a loaded machine.
std::string cpuCell(const Row& r) {
  std::vector<double> cpu;
  for (double v : r.effectRepsCpu)
    if (v >= 0.0) cpu.push_back(v);
  if (cpu.empty()) return "";
  return " (CPU " + fmt(median(cpu), 3) + ")";
}

// Per scene that defines regions: a row per configuration, a column per region.
std::string regionSection(const std::vector<Row>& rows) {
  std::ostringstream o;
  std::vector<std::string> scenes;
  for (const Row& r : rows)
    if (!r.regions.empty() && std::find(scenes.begin(), scenes.end(), r.scene) == scenes.end())
      scenes.push_back(r.scene);
  if (scenes.empty()) return "";
  o << "\n## Errors by region\n\nNRMSE against the target within each region the scene "
       "defines (its reference pixels whose surface lies in the region's box; normalised by the "
       "region's own mean), with the region's pixel count in the header; - where the region is "
       "not seen.\n";
  for (const std::string& scene : scenes) {
    const Row* first = nullptr;
    for (const Row& r : rows)
      if (r.scene == scene && !r.regions.empty()) {
        first = &r;
        break;
      }
    o << "\n### " << scene << "\n\n| effect | preset / params | whole image |";
    for (const Row::RegionScore& g : first->regions)
      o << ' ' << g.name << " (" << g.pixels << " px) |";
    o << "\n|---|---|---:|";
    for (size_t k = 0; k < first->regions.size(); ++k) o << "---:|";
    o << "\n";
    for (const Row& r : rows) {
      if (r.scene != scene) continue;
      o << "| " << r.effect << " | " << r.preset << (r.params.empty() ? "" : " " + r.params)
        << " | " << fmt(r.nrmse, 4) << " |";
      for (const Row::RegionScore& g : r.regions)
        o << ' ' << (g.pixels > 0 ? fmt(g.nrmse, 4) : std::string("-")) << " |";
      o << "\n";
    }
  }
  return o.str();
}

// What each configuration recovers of what the engine alone misses (fillRecovered).
std::string recoveredSection(const std::vector<Row>& rows) {
  std::ostringstream o;
  for (const Row& r : rows) {
    if (!r.recoveredPresent || r.effect == "none") continue;
    if (o.tellp() == 0)
      o << "\n## Missing light recovered\n\n"
           "Against the engine alone (the `none` row of the same scene and preset, scored against "
           "the same reference): *error removed* = 1 - NRMSE / NRMSE(engine alone), the share of "
           "its error this configuration takes away (negative: it adds error); *indirect "
           "delivered* = (mean of this image - mean of the engine alone's) / (mean of the "
           "direct+indirect reference - mean of the direct reference), over the scored pixels: "
           "the share of the reference's indirect light it adds, net: AO effects remove light and "
           "score below 0, and so may an effect that also shadows the environment term (ISM's "
           "environment VPLs). A difference of NRMSE inside the reference noise is no result.\n\n"
           "| scene | effect | preset / params | effect ms [interval] | NRMSE | engine alone | "
           "reference noise | error removed | indirect delivered |\n"
           "|---|---|---|---:|---:|---:|---:|---:|---:|\n";
    o << "| " << r.scene << " | " << r.effect << " | " << r.preset
      << (r.params.empty() ? "" : " " + r.params) << " | " << withInterval(r.effectCi, 3) << " | "
      << fmt(r.nrmse, 4) << " | " << fmt(r.aloneNrmse, 4) << " | " << fmt(r.noiseFloor, 4) << " | "
      << percent(r.errorRemoved) << " | "
      << (r.indirectPresent ? percent(r.indirectDelivered) : std::string("-")) << " |\n";
  }
  return o.str();
}

// With several presets and no grid: one table per scene shaped like seed 003's Table 1, a
// column per preset (platform profile), for each effect the settings its preset sets, its time
// and its errors against the target and against its declared quantity.
std::string profileTable(const std::vector<Row>& rows) {
  std::vector<std::string> presets, scenes, effects;
  auto addUnique = [](std::vector<std::string>& v, const std::string& s) {
    if (std::find(v.begin(), v.end(), s) == v.end()) v.push_back(s);
  };
  std::map<std::tuple<std::string, std::string, std::string>, const Row*> cell;
  for (const Row& r : rows) {
    if (!r.params.empty()) continue;
    addUnique(presets, r.preset);
    addUnique(scenes, r.scene);
    addUnique(effects, r.effect);
    cell[{r.scene, r.effect, r.preset}] = &r;
  }
  if (presets.size() < 2) return "";
  std::ostringstream o;
  o << "\n## Platform profiles\n\nOne column per preset (a platform profile, after seed 003's "
       "Table 1): the settings the preset gives each effect, the effect's GPU time [interval] "
       "and its NRMSE against the target and against its declared quantity.\n";
  for (const std::string& scene : scenes) {
    o << "\n### " << scene << "\n\n| effect | |";
    for (const std::string& p : presets) o << " " << p << " |";
    o << "\n|---|---|";
    for (size_t i = 0; i < presets.size(); ++i) o << "---|";
    o << "\n";
    for (const std::string& e : effects) {
      auto line = [&](const char* what, auto text) {
        o << "| " << e << " | " << what << " |";
        for (const std::string& p : presets) {
          auto it = cell.find({scene, e, p});
          o << " " << (it == cell.end() ? std::string("-") : text(*it->second)) << " |";
        }
        o << "\n";
      };
      line("settings", [](const Row& r) {
        return r.presetSettings.empty() ? std::string("defaults") : r.presetSettings;
      });
      line("effect ms", [](const Row& r) { return withInterval(r.effectCi, 3); });
      line("NRMSE vs target", [](const Row& r) { return fmt(r.nrmse, 3); });
      line("reference noise", [](const Row& r) { return fmt(r.noiseFloor, 3); });
      line("error of the engine alone removed", [](const Row& r) {
        return r.recoveredPresent ? percent(r.errorRemoved) : std::string("-");
      });
      line("indirect light delivered", [](const Row& r) {
        return r.indirectPresent ? percent(r.indirectDelivered) : std::string("-");
      });
      line("NRMSE vs declared", [](const Row& r) { return fmt(r.declaredNrmse, 3); });
    }
  }
  return o.str();
}

std::string markdown(const std::vector<Row>& rows, const RunInfo& info,
                     const std::vector<std::pair<std::string, std::string>>& plots) {
  std::ostringstream o;
  o << "# gi-bench report\n\n"
    << "Device: " << info.device << "  \nCommand: `" << info.commandLine
    << "`  \nDate: " << info.date << " (" << fmt(info.seconds, 3)
    << " s)  \nLoad average "
       "(1 min) at the start and end: "
    << (info.loadStart >= 0 ? fmt(info.loadStart, 3) : std::string("unknown")) << ", "
    << (info.loadEnd >= 0 ? fmt(info.loadEnd, 3) : std::string("unknown")) << "\n\n"
    << wideIntervals(rows)
    << "GPU times come from Vulkan timestamp queries. Each configuration is measured in "
    << (rows.empty() ? 0 : rows.front().reps)
    << " repetitions, interleaved round-robin across configurations (repetition 1 of all, "
       "then repetition 2, ...) so that drift hits all alike; a repetition's value is the "
       "median over its "
    << (rows.empty() ? 0 : rows.front().frames)
    << " frames. Times are the median over the repetitions with a confidence interval "
       "[lo, hi] of the median from order statistics (binomial, distribution-free; coverage "
    << (rows.empty() ? std::string("-") : percent(rows.front().totalCi.coverage))
    << ": 95% needs at least 6 repetitions, fewer give [min, max]). *total* sums the "
       "frame's passes (the floor pass excluded), *effect* the passes that are not the engine's, "
       "and *x floor* divides them by the floor pass (a fixed full-screen pass, one fetch and "
       "one store per pixel, measured in the same frame: a unit of this device's full-screen "
       "cost, not a portable one; its own median ranged "
    << floorRange(rows)
    << " ms across this run's configurations for identical work). NRMSE (RMSE / mean of the "
       "reference over the scored pixels, emitters left out of that mean for light: the "
       "*normaliser* column gives it and its pixels) and "
       "SSIM compare the effect's output with CPU ray-traced references over the pixels that "
       "show geometry in both, twice: against the *target* (the physically meaningful quantity: "
       "AO of the effect's radius for AO-like effects, direct + indirect light for GI effects) "
       "and against the quantity the effect *declares* it estimates with these settings "
       "(obscurance with a membership, the Alchemy integral, ...; equal to the target when the "
       "effect declares nothing else). *Reference noise* is the target reference's own "
       "error on the NRMSE scale (RMS of its per-pixel standard error / the normaliser): a "
       "perfect renderer would score about that, so a difference between rows smaller than it "
       "is no result. References are rendered with more samples until it is at most a "
       "quarter of the smallest NRMSE they score, up to --ref-spp-max; *(cap)* marks one that "
       "stopped there. Rows on the Pareto front of (time, NRMSE vs target) "
       "within their scene and effect are marked *; a time difference inside the intervals "
       "does not keep a less accurate row on the front.\n\n";
  std::set<const Row*> onFront;
  std::map<std::pair<std::string, std::string>, std::vector<const Row*>> groups;
  for (const Row& r : rows) groups[{r.scene, r.effect}].push_back(&r);
  for (const auto& [key, g] : groups)
    for (size_t i : paretoFront(g)) onFront.insert(g[i]);
  o << "| scene | effect | preset / params | GPU ms per pass [interval] (CPU ms with "
       "--isolate-passes) | total ms [interval] | "
       "effect ms [interval] (CPU ms with --isolate-passes) | total x floor | effect x floor | "
       "target | NRMSE vs target | "
       "reference noise | normaliser (pixels of scored) | SSIM vs target | declared | NRMSE vs "
       "declared | SSIM vs declared |\n"
    << "|---|---|---|---|---:|---:|---:|---:|---|---:|---:|---:|---:|---|---:|---:|\n";
  for (const Row& r : rows) {
    std::string passes;
    for (const PassTime& p : r.passes) {
      passes += (passes.empty() ? "" : ", ") + p.name + " " + withInterval(p.ms, 3);
      std::vector<double> cpu;  // --isolate-passes: the pass's process CPU ms beside it
      for (double v : p.repsCpu)
        if (v >= 0.0) cpu.push_back(v);
      if (!cpu.empty()) passes += " (CPU " + fmt(median(cpu), 3) + ")";
    }
    std::string pp = r.preset + (r.params.empty() ? "" : " " + r.params);
    o << "| " << r.scene << " | " << r.effect << " | " << pp << (onFront.count(&r) ? " *" : "")
      << " | " << passes << " | " << withInterval(r.totalCi) << " | " << withInterval(r.effectCi)
      << cpuCell(r) << " | " << fmt(r.floorMs > 0 ? r.totalMs / r.floorMs : 0.0, 3) << " | "
      << fmt(r.floorMs > 0 ? r.effectMs / r.floorMs : 0.0, 3) << " | " << r.compared << " vs "
      << r.reference << " | " << fmt(r.nrmse, 4) << " | " << fmt(r.noiseFloor, 4)
      << (r.noiseCapped ? " (cap)" : "") << " | " << fmt(r.normaliser, 4) << " ("
      << r.normaliserPixels << " of " << r.pixels << ") | " << fmt(r.ssim, 4) << " | " << r.declared
      << " | " << fmt(r.declaredNrmse, 4) << " | " << fmt(r.declaredSsim, 4) << " |\n";
  }
  if (anySplit(rows)) o << splitSection(rows);
  o << gapSection(rows);
  o << recoveredSection(rows);
  o << regionSection(rows);
  o << profileTable(rows);
  if (!plots.empty()) {
    o << "\n## Error against time\n\n";
    // The PNG shows in any viewer; the SVG beside it has tooltips and scales.
    for (const auto& [title, file] : plots)
      o << "![" << title << "](" << file << ".png) ([SVG](" << file << ".svg))\n\n";
  }
  return o.str();
}

}  // namespace

void writeResults(const std::string& dir, const std::vector<Row>& rows, const RunInfo& info) {
  fs::create_directories(fs::path(dir) / "plots");
  std::map<std::pair<std::string, std::string>, std::vector<const Row*>> groups;
  std::vector<std::pair<std::string, std::string>> order;
  for (const Row& r : rows) {
    const auto key = std::make_pair(r.scene, r.effect);
    if (!groups.count(key)) order.push_back(key);
    groups[key].push_back(&r);
  }
  std::vector<std::pair<std::string, std::string>> plots;
  auto write = [&](const std::string& file, const Plot& plot) {
    writeFileAtomic((fs::path(dir) / (file + ".svg")).string(), svgPlot(plot));
    writePng((fs::path(dir) / (file + ".png")).string(), rasterPlot(plot));  // atomic, checked
    plots.emplace_back(plot.title, file);
  };
  // A scene swept with several effects first gets one chart of all of them against the same
  // target: which method buys the most accuracy per millisecond.
  std::map<std::string, std::vector<const Row*>> byScene;
  std::vector<std::string> sceneOrder;
  for (const Row& r : rows) {
    if (!byScene.count(r.scene)) sceneOrder.push_back(r.scene);
    byScene[r.scene].push_back(&r);
  }
  for (const std::string& scene : sceneOrder) {
    const std::vector<const Row*>& g = byScene[scene];
    std::set<std::string> effects, targets;
    for (const Row* r : g) effects.insert(r->effect), targets.insert(r->reference);
    if (effects.size() < 2 || targets.size() != 1) continue;
    const std::string stem = fs::path(scene).stem().string();
    write("plots/" + fileSafe(stem) + "_all",
          buildPlot(
              stem + ": every effect (" + g.front()->compared + " vs " + g.front()->reference + ")",
              g, true));
    // The same rows, each against the quantity its effect declares (where any differs from
    // the target): how well each estimates what it claims to.
    if (std::any_of(g.begin(), g.end(), [](const Row* r) { return r->declared != r->reference; }))
      write("plots/" + fileSafe(stem) + "_all_declared",
            buildPlot(stem + ": every effect, each against its declared quantity", g, true, true));
  }
  for (const auto& key : order) {
    const std::string stem = fs::path(key.first).stem().string();
    const std::string file = "plots/" + fileSafe(stem) + "_" + fileSafe(key.second);
    const std::string title = stem + ": " + key.second + " (" + groups[key].front()->compared +
                              " vs " + groups[key].front()->reference + ")";
    write(file, buildPlot(title, groups[key]));
  }
  writeFileAtomic((fs::path(dir) / "results.csv").string(), csv(rows));
  writeFileAtomic((fs::path(dir) / "repetitions.csv").string(), repetitionsCsv(rows));
  writeFileAtomic((fs::path(dir) / "results.json").string(), json(rows, info));
  writeFileAtomic((fs::path(dir) / "report.md").string(), markdown(rows, info, plots));
}

}  // namespace gi::bench
