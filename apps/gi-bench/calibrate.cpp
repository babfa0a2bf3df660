#include "modes.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <functional>
#include <map>
#include <memory>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "cli.h"
#include "comparison.h"
#include "gi/effect_config.h"
#include "gi/errors.h"
#include "measure.h"
#include "progress.h"
#include "quantity.h"
#include "setup.h"
#include "stats.h"

namespace gi_bench {

namespace {

// The sample-count settings of an effect (SettingDesc::sampleCount: samples, directions,
// steps, slices ...).
std::vector<gi::SettingDesc> sampleSettings(const gi::EffectRegistry& registry,
                                            const std::string& effect) {
  std::vector<gi::SettingDesc> out;
  const gi::SettingValues defaults = registry.defaultSettings(effect);
  for (const auto& d : defaults.descs())
    if (d.sampleCount) out.push_back(d);
  return out;
}

std::vector<int> powersOfTwo(const gi::SettingDesc& d) {
  std::vector<int> v;
  const int lo = std::max(1, int(d.minValue)), hi = int(std::min(d.maxValue, 1024.0));
  for (int x = 1; x <= hi; x *= 2)
    if (x >= lo) v.push_back(x);
  if (v.empty() || v.back() != hi) v.push_back(hi);
  return v;
}

// One effect set calibrated on its own (effects a preset offers as alternatives are each given
// the whole budget; a '+' set runs together and shares it): its knobs, the candidates (the
// cartesian product of powers of two of every knob), their jobs' indices and the choice.
struct CalibrationItem {
  std::string label;
  std::vector<std::string> effects;
  struct Knob {
    std::string effect, key;
    std::vector<int> values;
  };
  std::vector<Knob> knobs;
  std::vector<std::vector<int>> candidates;
  std::vector<gi::RenderSettings> configs;  // one per candidate (gi::configureRender)
  std::vector<std::string> labels;
  Comparison cmp;
  size_t firstJob = 0;
  std::vector<Scores> scores;
  gi::bench::CalibrationChoice choice;
};

CalibrationItem calibrationItem(const std::string& label, const Setup& s) {
  CalibrationItem it;
  it.label = label;
  it.effects = splitPlus(label);
  for (const auto& e : it.effects)
    for (const auto& d : sampleSettings(s.registry, e))
      it.knobs.push_back({e, d.name, powersOfTwo(d)});
  if (it.knobs.empty())
    usageError(
        "--effects", "'" + label +
                         "' has no sample-count setting to calibrate (effects with one: " +
                         [&] {
                           std::vector<std::string> with;
                           for (const auto& n : s.registry.names())
                             if (!sampleSettings(s.registry, n).empty()) with.push_back(n);
                           return with.empty() ? std::string("none") : joinList(with);
                         }() +
                         ")");
  it.candidates.assign(1, {});
  for (const auto& k : it.knobs) {
    std::vector<std::vector<int>> next;
    for (const auto& c : it.candidates)
      for (int v : k.values) {
        next.push_back(c);
        next.back().push_back(v);
      }
    it.candidates = std::move(next);
  }
  const gi::Scene& scene = s.scenes[0].scene;
  gi::EffectOverrides base;
  base.effects = it.effects;
  it.cmp = comparisonFor(gi::configureRender(scene, s.registry, {.overrides = base}).effects,
                         s.registry, false);
  for (const auto& cand : it.candidates) {
    gi::EffectOverrides ov;
    ov.effects = it.effects;
    std::string text;
    for (size_t k = 0; k < it.knobs.size(); ++k) {
      ov.sets.push_back(it.knobs[k].effect + "." + it.knobs[k].key + "=" + std::to_string(cand[k]));
      text += (text.empty() ? "" : " ") + ov.sets.back();
    }
    it.configs.push_back(gi::configureRender(scene, s.registry, {.overrides = ov}));
    it.labels.push_back(text);
  }
  return it;
}

// Before any reference or sweep: each item's cheapest candidate (every sample count at its
// minimum; cost does not fall as a count rises) measured alone. When even its median is over
// the limit no candidate can fit, so the run stops at once instead of after the whole search.
void failFastWhenNothingFits(gi::vk::Context& ctx, const gi::EffectRegistry& registry,
                             const gi::Scene& scene, const std::vector<CalibrationItem>& items,
                             const Options& o, double limit) {
  std::vector<RenderJob> jobs;
  for (const CalibrationItem& it : items)
    jobs.push_back({&scene, &it.configs.front(), it.cmp.resource});  // the minimum
  const std::vector<Measurement> cheapest =
      measureAll(ctx, registry, jobs, o, false, [](size_t, const Measurement&) {});
  std::string unfit;
  for (size_t i = 0; i < items.size(); ++i) {
    const Interval& t = cheapest[i].total;
    if (t.median > limit)
      unfit += (unfit.empty() ? "" : "; ") + items[i].label + " at its cheapest (" +
               items[i].labels.front() + ") " + formatDouble(t.median) + " ms [" +
               formatDouble(t.lo) + ", " + formatDouble(t.hi) + "]";
  }
  if (!unfit.empty())
    throw gi::Error(gi::ErrorKind::InvalidData, o.out,
                    "no configuration can fit the budget of " + formatDouble(o.budgetMs) +
                        " ms (limit " + formatDouble(limit) + " ms after the headroom): " + unfit +
                        " at " + std::to_string(o.width) + "x" + std::to_string(o.height) +
                        "; stopped before the search: give a larger --budget-ms or a smaller "
                        "--width/--height; nothing written");
}

}  // namespace

int runCalibrate(const Options& o) {
  Setup s;
  loadInputs(o, s);
  if (s.scenes.size() != 1) usageError("--scene", "--calibrate measures one scene");
  // Without --effects, or with 'all': every effect that has a sample count; effects named
  // explicitly must have one.
  std::vector<std::string> labels;
  const bool every =
      !o.effects || std::find(o.effects->begin(), o.effects->end(), "all") != o.effects->end();
  for (const auto& item : o.effects ? effectItems(o, s.registry) : s.registry.names()) {
    const bool single = item.find('+') == std::string::npos;
    if (item == "none" || (every && single && sampleSettings(s.registry, item).empty())) continue;
    labels.push_back(item);
  }
  if (labels.empty())
    usageError("--calibrate", "no effect with a sample-count setting to calibrate (effects: " +
                                  knownEffects(s.registry) + ")");
  std::vector<CalibrationItem> items;
  for (const auto& l : labels) items.push_back(calibrationItem(l, s));
  const gi::Scene& scene = s.scenes[0].scene;
  gi::vk::Context ctx = makeContext(o);
  const double limit = o.budgetMs * (1.0 - o.headroom);
  failFastWhenNothingFits(ctx, s.registry, scene, items, o, limit);
  std::vector<ReferenceKey> keys;
  for (const auto& it : items) keys.push_back(ReferenceKey{0, it.cmp.target});
  const std::map<ReferenceKey, Reference> refs = computeReferences(o, s, keys);
  std::printf(
      "calibrating on %s: %s %ux%u, budget %.3f ms (the upper end of the measured "
      "time's interval must stay under %.3f); each effect set alone in the frame\n",
      ctx.deviceName().c_str(), s.scenes[0].name.c_str(), o.width, o.height, o.budgetMs, limit);
  // Every candidate of every item measured, repetitions interleaved across all of them.
  std::vector<RenderJob> jobs;
  std::vector<std::pair<size_t, size_t>> owner;  // job -> (item, candidate)
  for (size_t ii = 0; ii < items.size(); ++ii) {
    items[ii].firstJob = jobs.size();
    items[ii].scores.resize(items[ii].candidates.size());
    for (size_t ci = 0; ci < items[ii].configs.size(); ++ci) {
      jobs.push_back({&scene, &items[ii].configs[ci], items[ii].cmp.resource});
      owner.emplace_back(ii, ci);
    }
  }
  ProgressBar bar(o.progress, "candidates", jobs.size());
  const std::vector<Measurement> measured =
      measureAll(ctx, s.registry, jobs, o, false, [&](size_t j, const Measurement& m) {
        CalibrationItem& it = items[owner[j].first];
        it.scores[owner[j].second] =
            score(m, it.cmp.target, refs.at(ReferenceKey{0, it.cmp.target}), o, s.scenes[0].name);
        bar.step(it.labels[owner[j].second]);
      });
  const bool bySsim = o.metric == "ssim";
  char intervalHeader[32];
  std::snprintf(intervalHeader, sizeof intervalHeader, "%.4g%% interval",
                100.0 * (measured.empty() ? 0.0 : measured[0].total.coverage));
  std::string unfit;
  for (CalibrationItem& it : items) {
    std::vector<gi::bench::CalibrationCandidate> cands;
    double cheapest = INFINITY;
    for (size_t ci = 0; ci < it.candidates.size(); ++ci) {
      const gi::bench::Metrics& mt = it.scores[ci].metrics;
      const Interval& t = measured[it.firstJob + ci].total;
      cands.push_back({it.candidates[ci], t, bySsim ? -mt.ssim : mt.nrmse});
      cheapest = std::min(cheapest, t.median);
    }
    it.choice = gi::bench::chooseCalibrated(cands, limit);
    std::printf(
        "\n%s against %s\n%-40s %10s %21s %12s %10s %8s %5s\n", it.label.c_str(),
        referenceLabel(it.cmp.target, refs.at(ReferenceKey{0, it.cmp.target}).spp, o).c_str(),
        "settings", "frame ms", intervalHeader, "cost bound", "NRMSE", "SSIM", "fits");
    for (size_t ci = 0; ci < it.candidates.size(); ++ci) {
      const Interval& t = measured[it.firstJob + ci].total;
      std::printf("%-40s %10.3f [%8.3f, %8.3f] %12.3f %10.5f %8.5f %5s\n", it.labels[ci].c_str(),
                  t.median, t.lo, t.hi, it.choice.boundMs[ci], it.scores[ci].metrics.nrmse,
                  it.scores[ci].metrics.ssim, it.choice.boundMs[ci] <= limit ? "yes" : "no");
    }
    if (!it.choice.index) {
      unfit += (unfit.empty() ? "" : "; ") + it.label +
               " (cheapest measured: " + formatDouble(cheapest) + " ms)";
      continue;
    }
    const size_t b = *it.choice.index;
    std::printf(
        "%s: chose %s, margin kept %.3f ms under the limit %.3f (cost bound %.3f ms, of which "
        "%.3f ms above the median for noise and the monotone-cost assumption)\n",
        it.label.c_str(), it.labels[b].c_str(), it.choice.marginMs, limit, it.choice.boundMs[b],
        it.choice.noiseMarginMs);
  }
  if (!unfit.empty())
    throw gi::Error(gi::ErrorKind::InvalidData, o.out,
                    "no configuration fits the budget of " + formatDouble(o.budgetMs) + " ms for " +
                        unfit + " (upper ends of the intervals must fit); nothing written");
  // The preset, with the search and its margins recorded under "calibration".
  nlohmann::json preset, record = nlohmann::json::array();
  preset["name"] = fs::path(o.out).stem().string();
  std::string summary;
  preset["effects"] = nlohmann::json::object();
  for (const CalibrationItem& it : items) {
    const size_t b = *it.choice.index;
    const Interval& t = measured[it.firstJob + b].total;
    const gi::bench::Metrics& mt = it.scores[b].metrics;
    for (size_t k = 0; k < it.knobs.size(); ++k)
      preset["effects"][it.knobs[k].effect][it.knobs[k].key] = it.candidates[b][k];
    summary += (summary.empty() ? "" : "; ") + it.label + " " + formatDouble(t.median) +
               " ms, NRMSE " + formatDouble(mt.nrmse) + ", SSIM " + formatDouble(mt.ssim);
    nlohmann::json item;
    item["effects"] = it.label;
    item["reference"] =
        referenceLabel(it.cmp.target, refs.at(ReferenceKey{0, it.cmp.target}).spp, o);
    item["chosen"] = it.labels[b];
    item["margin_ms"] = it.choice.marginMs;
    item["noise_margin_ms"] = it.choice.noiseMarginMs;
    item["candidates"] = nlohmann::json::array();
    for (size_t ci = 0; ci < it.candidates.size(); ++ci) {
      const Interval& c = measured[it.firstJob + ci].total;
      item["candidates"].push_back({{"settings", it.labels[ci]},
                                    {"median_ms", c.median},
                                    {"interval_ms", {c.lo, c.hi}},
                                    {"cost_bound_ms", it.choice.boundMs[ci]},
                                    {"nrmse", it.scores[ci].metrics.nrmse},
                                    {"ssim", it.scores[ci].metrics.ssim},
                                    {"fits", it.choice.boundMs[ci] <= limit}});
    }
    record.push_back(item);
  }
  preset["description"] =
      "Calibrated by gi-bench on " + ctx.deviceName() + " with " + s.scenes[0].name + " at " +
      std::to_string(o.width) + "x" + std::to_string(o.height) + ", each effect set alone within " +
      formatDouble(o.budgetMs) + " ms per frame (medians of " + std::to_string(o.reps) +
      " repetitions; the sample counts of highest " + (bySsim ? "SSIM" : "NRMSE accuracy") +
      " whose cost bound fits): " + summary;
  preset["platform"] = ctx.deviceName();
  preset["target_ms"] = o.budgetMs;
  preset["reference_resolution"] = {o.width, o.height};
  preset["calibration"] = {
      {"command", o.commandLine},
      {"scene", s.scenes[0].name},
      {"budget_ms", o.budgetMs},
      {"headroom", o.headroom},
      {"limit_ms", limit},
      {"metric", o.metric},
      {"reps", o.reps},
      {"frames", o.frames},
      {"interval_coverage", measured.empty() ? 0.0 : measured[0].total.coverage},
      {"items", record}};
  // Written, then checked by the engine's own loader, then moved into place.
  const std::string tmp = o.out + ".check.json";
  gi::cli::writeFileAtomic(tmp, preset.dump(2) + "\n");
  try {
    gi::validatePreset(gi::loadPreset(tmp), s.registry);
  } catch (...) {
    fs::remove(tmp);
    throw;
  }
  fs::rename(tmp, o.out);
  std::printf("\nwrote %s: %s\n", o.out.c_str(), preset["effects"].dump().c_str());
  return 0;
}

}  // namespace gi_bench
