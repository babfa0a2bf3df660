// gi-bench outputs: CSV, JSON, a Markdown report and SVG plots (written by hand, no plotting
// library): NRMSE against time per scene and effect, one polyline per series, Pareto front.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <set>
#include <sstream>

#include <nlohmann/json.hpp>

#include "bench.h"
#include "gi/errors.h"

namespace gi::bench {

namespace fs = std::filesystem;

void writeFileAtomic(const std::string& path, const std::string& text) {
  const std::string tmp = path + ".partial";
  {
    std::ofstream out(tmp, std::ios::binary);
    out << text;
    out.flush();
    if (!out) {
      std::error_code ec;
      fs::remove(tmp, ec);
      throw Error(ErrorKind::FileNotFound, path, "cannot write file");
    }
  }
  fs::rename(tmp, path);
}

double plotTime(const Row& row) {
  return row.effectMs > 0.0 ? row.effectMs : row.totalMs;
}

std::vector<size_t> paretoFront(const std::vector<const Row*>& rows) {
  std::vector<size_t> order(rows.size());
  for (size_t i = 0; i < order.size(); ++i) order[i] = i;
  std::sort(order.begin(), order.end(), [&](size_t a, size_t b) {
    const double ta = plotTime(*rows[a]), tb = plotTime(*rows[b]);
    return ta != tb ? ta < tb : rows[a]->nrmse < rows[b]->nrmse;
  });
  std::vector<size_t> front;
  double best = INFINITY;
  for (size_t i : order)
    if (rows[i]->nrmse < best) {
      best = rows[i]->nrmse;
      front.push_back(i);
    }
  return front;
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

std::string passList(const Row& r) {
  std::string s;
  for (const auto& [name, ms] : r.passes) s += (s.empty() ? "" : " ") + name + "=" + fmt(ms);
  return s;
}

std::string fileSafe(const std::string& s) {
  std::string out;
  for (char c : s) out += std::isalnum(static_cast<unsigned char>(c)) ? c : '_';
  return out;
}

bool anySplit(const std::vector<Row>& rows) {
  return std::any_of(rows.begin(), rows.end(), [](const Row& r) { return r.split.present; });
}

std::string csv(const std::vector<Row>& rows) {
  std::ostringstream o;
  const bool split = anySplit(rows);
  o << "scene,effect,preset,params,width,height,frames,passes_ms,total_ms,effect_ms,floor_ms,"
       "total_over_floor,effect_over_floor,wall_ms,compared,reference,reference_spp,"
       "reference_stderr,pixels,nrmse,ssim";
  // --ao-split runs only, so that other runs keep their columns.
  if (split)
    o << ",reference_seconds,limit_nrmse,offscreen_nrmse,hidden_nrmse,estimator_nrmse,"
         "visible_fraction,offscreen_fraction,hidden_fraction,share_offscreen,share_hidden,"
         "share_estimator";
  o << '\n';
  for (const Row& r : rows) {
    o << csvField(r.scene) << ',' << csvField(r.effect) << ',' << csvField(r.preset) << ','
      << csvField(r.params) << ',' << r.width << ',' << r.height << ',' << r.frames << ','
      << csvField(passList(r)) << ',' << fmt(r.totalMs, 6) << ',' << fmt(r.effectMs, 6) << ','
      << fmt(r.floorMs, 6) << ',' << fmt(r.floorMs > 0 ? r.totalMs / r.floorMs : 0.0, 6) << ','
      << fmt(r.floorMs > 0 ? r.effectMs / r.floorMs : 0.0, 6) << ',' << fmt(r.wallMs, 6) << ','
      << r.compared << ',' << csvField(r.reference) << ',' << r.referenceSpp << ','
      << fmt(r.referenceStdError, 6) << ',' << r.pixels << ',' << fmt(r.nrmse, 6) << ','
      << fmt(r.ssim, 6);
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
    for (const auto& [name, ms] : r.passes) passes.push_back({{"pass", name}, {"ms", ms}});
    j["results"].push_back({{"scene", r.scene},
                            {"effect", r.effect},
                            {"preset", r.preset},
                            {"params", r.params},
                            {"width", r.width},
                            {"height", r.height},
                            {"frames", r.frames},
                            {"passes", passes},
                            {"total_ms", r.totalMs},
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
                            {"ssim", r.ssim},
                            {"reference_seconds", r.referenceSeconds}});
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

// "Nice" axis ticks covering [0, hi].
std::vector<double> ticks(double hi) {
  if (!(hi > 0)) hi = 1;
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

std::string svgPlot(const std::string& title, const std::vector<const Row*>& rows) {
  const double W = 720, H = 460, left = 70, right = 200, top = 40, bottom = 50;
  const double pw = W - left - right, ph = H - top - bottom;
  double tmax = 0, emax = 0;
  for (const Row* r : rows) {
    tmax = std::max(tmax, plotTime(*r));
    emax = std::max(emax, r->nrmse);
  }
  const std::vector<double> xt = ticks(tmax), yt = ticks(emax);
  const double xhi = xt.back(), yhi = yt.back();
  auto X = [&](double t) { return left + pw * t / xhi; };
  auto Y = [&](double e) { return top + ph * (1.0 - e / yhi); };
  const bool effectTime = !rows.empty() && rows.front()->effectMs > 0.0;
  std::ostringstream o;
  o << "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"" << W << "\" height=\"" << H
    << "\" viewBox=\"0 0 " << W << ' ' << H << "\" font-family=\"sans-serif\" font-size=\"12\">\n"
    << "<rect width=\"100%\" height=\"100%\" fill=\"white\"/>\n"
    << "<text x=\"" << left << "\" y=\"22\" font-size=\"15\">" << xmlEscape(title) << "</text>\n";
  for (double t : xt)
    o << "<line x1=\"" << X(t) << "\" y1=\"" << top << "\" x2=\"" << X(t) << "\" y2=\"" << top + ph
      << "\" stroke=\"#ddd\"/><text x=\"" << X(t) << "\" y=\"" << top + ph + 16
      << "\" text-anchor=\"middle\">" << fmt(t, 3) << "</text>\n";
  for (double e : yt)
    o << "<line x1=\"" << left << "\" y1=\"" << Y(e) << "\" x2=\"" << left + pw << "\" y2=\""
      << Y(e) << "\" stroke=\"#ddd\"/><text x=\"" << left - 6 << "\" y=\"" << Y(e) + 4
      << "\" text-anchor=\"end\">" << fmt(e, 3) << "</text>\n";
  o << "<rect x=\"" << left << "\" y=\"" << top << "\" width=\"" << pw << "\" height=\"" << ph
    << "\" fill=\"none\" stroke=\"black\"/>\n"
    << "<text x=\"" << left + pw / 2 << "\" y=\"" << H - 12 << "\" text-anchor=\"middle\">"
    << (effectTime ? "effect GPU time (ms, median)" : "frame GPU time (ms, median)") << "</text>\n"
    << "<text transform=\"translate(18," << top + ph / 2
    << ") rotate(-90)\" text-anchor=\"middle\">NRMSE vs reference</text>\n";
  // Series, in first-appearance order.
  std::vector<std::string> names;
  std::map<std::string, std::vector<const Row*>> series;
  for (const Row* r : rows) {
    if (!series.count(r->series)) names.push_back(r->series);
    series[r->series].push_back(r);
  }
  const char* colours[] = {"#1f77b4", "#ff7f0e", "#2ca02c", "#d62728", "#9467bd",
                           "#8c564b", "#e377c2", "#7f7f7f", "#bcbd22", "#17becf"};
  for (size_t s = 0; s < names.size(); ++s) {
    std::vector<const Row*> pts = series[names[s]];
    std::stable_sort(pts.begin(), pts.end(),
                     [](const Row* a, const Row* b) { return a->gridValue < b->gridValue; });
    const char* c = colours[s % 10];
    o << "<polyline fill=\"none\" stroke=\"" << c << "\" stroke-width=\"1.5\" points=\"";
    for (const Row* r : pts) o << X(plotTime(*r)) << ',' << Y(r->nrmse) << ' ';
    o << "\"/>\n";
    for (const Row* r : pts) {
      o << "<circle cx=\"" << X(plotTime(*r)) << "\" cy=\"" << Y(r->nrmse) << "\" r=\"3.5\" fill=\""
        << c << "\"><title>" << xmlEscape(r->params.empty() ? r->preset : r->params) << ": "
        << fmt(plotTime(*r)) << " ms, NRMSE " << fmt(r->nrmse) << "</title></circle>\n";
      if (!r->gridKey.empty())
        o << "<text x=\"" << X(plotTime(*r)) + 5 << "\" y=\"" << Y(r->nrmse) - 5
          << "\" font-size=\"10\" fill=\"" << c << "\">" << fmt(r->gridValue) << "</text>\n";
    }
    const double ly = top + 10 + 18 * double(s);
    o << "<line x1=\"" << left + pw + 12 << "\" y1=\"" << ly << "\" x2=\"" << left + pw + 32
      << "\" y2=\"" << ly << "\" stroke=\"" << c << "\" stroke-width=\"2\"/><text x=\""
      << left + pw + 36 << "\" y=\"" << ly + 4 << "\">"
      << xmlEscape(names[s].empty() ? "default" : names[s]) << "</text>\n";
  }
  // Pareto front: dashed staircase and rings.
  const std::vector<size_t> front = paretoFront(rows);
  if (!front.empty()) {
    o << "<polyline fill=\"none\" stroke=\"black\" stroke-dasharray=\"4 3\" points=\"";
    for (size_t k = 0; k < front.size(); ++k) {
      const Row& r = *rows[front[k]];
      if (k > 0) o << X(plotTime(r)) << ',' << Y(rows[front[k - 1]]->nrmse) << ' ';
      o << X(plotTime(r)) << ',' << Y(r.nrmse) << ' ';
    }
    o << "\"/>\n";
    for (size_t i : front)
      o << "<circle cx=\"" << X(plotTime(*rows[i])) << "\" cy=\"" << Y(rows[i]->nrmse)
        << "\" r=\"7\" fill=\"none\" stroke=\"black\"/>\n";
    const double ly = top + 10 + 18 * double(names.size());
    o << "<circle cx=\"" << left + pw + 22 << "\" cy=\"" << ly
      << "\" r=\"6\" fill=\"none\" stroke=\"black\"/><text x=\"" << left + pw + 36 << "\" y=\""
      << ly + 4 << "\">Pareto front</text>\n";
  }
  o << "</svg>\n";
  return o.str();
}

std::string percent(double v) {
  return fmt(100.0 * v, 3) + "%";
}

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

std::string markdown(const std::vector<Row>& rows, const RunInfo& info,
                     const std::vector<std::pair<std::string, std::string>>& plots) {
  std::ostringstream o;
  o << "# gi-bench report\n\n"
    << "Device: " << info.device << "  \nCommand: `" << info.commandLine
    << "`  \nDate: " << info.date << " (" << fmt(info.seconds, 3) << " s)\n\n"
    << "GPU times are medians over the frames of Vulkan timestamp queries; *total* sums the "
       "frame's passes (the floor pass excluded), *effect* the passes that are not the engine's, "
       "and *x floor* divides them by the floor pass (a fixed full-screen pass measured in the "
       "same frame: a device-independent cost unit). NRMSE (RMSE / mean of the reference) and "
       "SSIM compare the effect's output with the CPU ray-traced reference over the pixels that "
       "show geometry in both. Rows on the Pareto front of (time, NRMSE) within their scene and "
       "effect are marked *.\n\n";
  std::set<const Row*> onFront;
  std::map<std::pair<std::string, std::string>, std::vector<const Row*>> groups;
  for (const Row& r : rows) groups[{r.scene, r.effect}].push_back(&r);
  for (const auto& [key, g] : groups)
    for (size_t i : paretoFront(g)) onFront.insert(g[i]);
  o << "| scene | effect | preset / params | GPU ms per pass | total ms | effect ms | total x "
       "floor "
       "| effect x floor | compared with | NRMSE | SSIM |\n"
    << "|---|---|---|---|---:|---:|---:|---:|---|---:|---:|\n";
  for (const Row& r : rows) {
    std::string passes;
    for (const auto& [name, ms] : r.passes)
      passes += (passes.empty() ? "" : ", ") + name + " " + fmt(ms, 3);
    std::string pp = r.preset + (r.params.empty() ? "" : " " + r.params);
    o << "| " << r.scene << " | " << r.effect << " | " << pp << (onFront.count(&r) ? " *" : "")
      << " | " << passes << " | " << fmt(r.totalMs, 4) << " | " << fmt(r.effectMs, 4) << " | "
      << fmt(r.floorMs > 0 ? r.totalMs / r.floorMs : 0.0, 3) << " | "
      << fmt(r.floorMs > 0 ? r.effectMs / r.floorMs : 0.0, 3) << " | " << r.compared << " vs "
      << r.reference << " | " << fmt(r.nrmse, 4) << " | " << fmt(r.ssim, 4) << " |\n";
  }
  if (anySplit(rows)) o << splitSection(rows);
  if (!plots.empty()) {
    o << "\n## Error against time\n\n";
    for (const auto& [title, file] : plots) o << "![" << title << "](" << file << ")\n\n";
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
  for (const auto& key : order) {
    const std::string stem = fs::path(key.first).stem().string();
    const std::string file = "plots/" + fileSafe(stem) + "_" + fileSafe(key.second) + ".svg";
    const std::string title = stem + ": " + key.second + " (" + groups[key].front()->compared +
                              " vs " + groups[key].front()->reference + ")";
    writeFileAtomic((fs::path(dir) / file).string(), svgPlot(title, groups[key]));
    plots.emplace_back(title, file);
  }
  writeFileAtomic((fs::path(dir) / "results.csv").string(), csv(rows));
  writeFileAtomic((fs::path(dir) / "results.json").string(), json(rows, info));
  writeFileAtomic((fs::path(dir) / "report.md").string(), markdown(rows, info, plots));
}

}  // namespace gi::bench
