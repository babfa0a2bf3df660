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
#include <set>
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

// ---- Configurations -----------------------------------------------------------------------------

struct Grid {
  std::string effect, key;  // "ssao", "samples"
  std::vector<std::string> values;
};

struct Config {
  size_t scene = 0;
  std::vector<std::string> effectSet;
  std::string effectLabel, preset, params, series, gridKey;
  double gridValue = 0.0;
  const gi::Preset* presetPtr = nullptr;
  // The effects and engine settings (preset, scene "engine" entries, grid --set), as every app
  // resolves them (gi::configureRender); size and timing options are set when measured.
  gi::RenderSettings settings;
  Comparison comparison;
};

std::vector<Grid> parseGrids(const Options& o, const gi::EffectRegistry& registry,
                             const std::vector<std::string>& items) {
  std::vector<std::string> grids = o.grids;
  if (o.quick && grids.empty() && std::find(items.begin(), items.end(), "ssao") != items.end())
    grids.push_back("ssao.samples=4,16");
  std::vector<Grid> out;
  for (const std::string& g : grids) {
    const size_t dot = g.find('.'), eq = g.find('=');
    if (dot == std::string::npos || eq == std::string::npos || dot > eq || dot == 0 ||
        eq == dot + 1)
      usageError("--grid", "'" + g + "': expected EFFECT.KEY=V1,V2,...");
    Grid grid{g.substr(0, dot), g.substr(dot + 1, eq - dot - 1),
              gi::cli::splitList("--grid", g.substr(eq + 1))};
    if (grid.values.empty()) usageError("--grid", "'" + g + "': no values");
    if (!registry.has(grid.effect))
      usageError("--grid", "'" + g + "': unknown effect '" + grid.effect +
                               "' (known: " + knownEffects(registry) + ")");
    bool swept = false;
    for (const auto& item : items)
      for (const auto& e : splitPlus(item)) swept |= e == grid.effect;
    if (!swept)
      usageError("--grid", "'" + g + "': effect '" + grid.effect + "' is not in --effects");
    registry.defaultSettings(grid.effect).desc(grid.key);  // throws for an unknown key
    for (const auto& v : grid.values) {                    // throws for a bad value
      gi::SettingValues probe = registry.defaultSettings(grid.effect);
      probe.setFromString(grid.key, v, "--grid " + g);
    }
    out.push_back(std::move(grid));
  }
  return out;
}

std::vector<Config> buildConfigs(const Options& o, const Setup& s,
                                 const std::vector<std::string>& items,
                                 const std::vector<Grid>& grids) {
  std::vector<Config> configs;
  // --effects all: each preset with the effects it configures (its platform-profile column).
  const bool everyEffect =
      o.effects && std::find(o.effects->begin(), o.effects->end(), "all") != o.effects->end();
  for (size_t si = 0; si < s.scenes.size(); ++si)
    for (const std::string& item : items)
      for (size_t pi = 0; pi < s.presets.size(); ++pi) {
        std::vector<std::string> set = splitPlus(item);
        std::string label = item;
        if (item == "recommended") {  // the preset's own combination (recommended_effects)
          if (!s.presets[pi] || s.presets[pi]->recommendedEffects.empty()) {
            if (si == 0)
              std::fprintf(stderr,
                           "gi-bench: preset '%s' recommends no effects: no "
                           "'recommended' row for it\n",
                           s.presetNames[pi].c_str());
            continue;
          }
          set = s.presets[pi]->recommendedEffects;
          label = "recommended (";
          for (size_t k = 0; k < set.size(); ++k) label += (k ? "+" : "") + set[k];
          label += ")";
        }
        if (everyEffect && s.presets[pi] &&
            std::none_of(set.begin(), set.end(),
                         [&](const std::string& e) { return s.presets[pi]->effects.count(e); }))
          continue;
        std::vector<const Grid*> active;
        for (const Grid& g : grids)
          if (std::find(set.begin(), set.end(), g.effect) != set.end()) active.push_back(&g);
        std::vector<size_t> idx(active.size(), 0);
        for (;;) {
          Config c;
          c.scene = si;
          c.effectSet = set;
          c.effectLabel = label;
          c.preset = s.presetNames[pi];
          c.presetPtr = s.presets[pi].get();
          gi::EffectOverrides ov;
          ov.effects = set;
          c.series = c.preset;
          for (size_t k = 0; k < active.size(); ++k) {
            const std::string kv =
                active[k]->effect + "." + active[k]->key + "=" + active[k]->values[idx[k]];
            ov.sets.push_back(kv);
            c.params += (c.params.empty() ? "" : " ") + kv;
            if (k == 0) {
              c.gridKey = active[k]->effect + "." + active[k]->key;
              c.gridValue = std::strtod(active[k]->values[idx[k]].c_str(), nullptr);
              if (active[k]->values[idx[k]] == "true") c.gridValue = 1;
            } else {
              c.series += " " + kv;
            }
          }
          c.settings =
              gi::configureRender(s.scenes[si].scene, s.registry, c.presetPtr, {.overrides = ov});
          c.comparison = comparisonFor(c.settings.effects, s.registry, o.aoSplit);
          if (o.target) c.comparison = litAgainst(c.comparison, *o.target);
          // The reference renders the scene's environment as it is: a scaled one would be
          // compared with the wrong ground truth.
          if (c.settings.environmentIntensity != 1.0f &&
              !gi::bench::isAoLike(c.comparison.target.quantity))
            throw gi::Error(gi::ErrorKind::Usage, "",
                            "engine.environment_intensity must be 1 when lit images are "
                            "compared with the reference (preset '" +
                                c.preset + "')");
          configs.push_back(std::move(c));
          size_t k = 0;
          for (; k < idx.size(); ++k) {
            if (++idx[k] < active[k]->values.size()) break;
            idx[k] = 0;
          }
          if (k == idx.size()) break;
        }
      }
  return configs;
}

void checkFinite(const Row& r) {
  const Row::AoSplit& s = r.split;
  for (double v : {r.totalMs,         r.effectMs,          r.floorMs,        r.wallMs,
                   r.totalCi.lo,      r.totalCi.hi,        r.nrmse,          r.ssim,
                   r.declaredNrmse,   r.declaredSsim,      r.gapNrmse,       r.gapShare,
                   s.limitNrmse,      s.offscreenNrmse,    s.hiddenNrmse,    s.estimatorNrmse,
                   s.visibleFraction, s.offscreenFraction, s.hiddenFraction, s.shareOffscreen,
                   s.shareHidden,     s.shareEstimator})
    if (!std::isfinite(v))
      throw gi::Error(gi::ErrorKind::NonFinite, r.scene,
                      "non-finite measurement for " + r.effect + " " + r.params);
}

// A reference's noise is part of every error measured against it: NRMSE^2 is about the
// renderer's own error^2 plus the noise floor^2. Each reference is rendered again with more
// samples (noise ~ 1 / sqrt(spp)) until its floor is at most a quarter of the smallest NRMSE
// it scores (the floor then adds at most 3% to that NRMSE), or o.refSppMax; `rescore(i)`
// scores configuration i again. Returns the references that stopped at the cap.
std::set<ReferenceKey> refineReferences(const Options& o, const Setup& s,
                                        const std::vector<Config>& configs,
                                        std::map<ReferenceKey, Reference>& refs,
                                        const std::vector<Scores>& vsTargets,
                                        const std::vector<Scores>& vsDeclareds,
                                        const std::function<void(size_t)>& rescore) {
  std::set<ReferenceKey> capped;
  for (int round = 0; round < 4; ++round) {
    // Per reference: the smallest NRMSE it scores and its noise floor there.
    std::map<ReferenceKey, std::pair<double, double>> worst;  // key -> (min nrmse, floor)
    for (size_t i = 0; i < configs.size(); ++i)
      for (const auto& [spec, sc] : {std::pair{configs[i].comparison.target, &vsTargets[i]},
                                     std::pair{configs[i].comparison.declared, &vsDeclareds[i]}}) {
        const ReferenceKey k{configs[i].scene, spec};
        auto [it, added] = worst.try_emplace(k, sc->metrics.nrmse, sc->metrics.noiseFloor);
        if (!added && sc->metrics.nrmse < it->second.first)
          it->second = {sc->metrics.nrmse, sc->metrics.noiseFloor};
      }
    std::set<ReferenceKey> renewed;
    for (const auto& [k, v] : worst) {
      const auto [nrmse, floor] = v;
      Reference& r = refs.at(k);
      if (!(floor > 0.25 * nrmse)) {
        capped.erase(k);
        continue;
      }
      if (r.spp >= o.refSppMax) {
        capped.insert(k);
        continue;
      }
      // (floor / target)^2 more samples, 10% beyond, in whole powers of two of the base.
      const double target = std::max(0.25 * nrmse, 1e-9);
      const double want = double(r.spp) * std::pow(floor / target, 2.0) * 1.1;
      uint32_t spp = r.spp;
      while (double(spp) < want && spp < o.refSppMax) spp = std::min(spp * 2, o.refSppMax);
      std::fprintf(stderr,
                   "gi-bench: %s %s: reference noise %.4f > 1/4 of the smallest NRMSE %.4f: "
                   "%u -> %u spp\n",
                   s.scenes[k.scene].name.c_str(), gi::bench::label(k.spec).c_str(), floor, nrmse,
                   r.spp, spp);
      r = computeReference(o, s.scenes[k.scene], k, spp);
      renewed.insert(k);
    }
    if (renewed.empty()) break;
    for (size_t i = 0; i < configs.size(); ++i)
      if (renewed.count({configs[i].scene, configs[i].comparison.target}) ||
          renewed.count({configs[i].scene, configs[i].comparison.declared}))
        rescore(i);
  }
  for (const ReferenceKey& k : capped)
    std::fprintf(stderr,
                 "gi-bench: warning: %s %s: the reference stopped at --ref-spp-max %u samples with "
                 "its noise floor above a quarter of the smallest NRMSE it scores\n",
                 s.scenes[k.scene].name.c_str(), gi::bench::label(k.spec).c_str(), o.refSppMax);
  return capped;
}

}  // namespace

int runSweep(const Options& o) {
  const auto start = std::chrono::steady_clock::now();
  const double loadStart = gi::bench::loadAverage();
  Setup s;
  loadInputs(o, s);
  const std::vector<std::string> items = effectItems(o, s.registry);
  const std::vector<Grid> grids = parseGrids(o, s.registry, items);
  const std::vector<Config> configs = buildConfigs(o, s, items, grids);
  // Everything is validated; now the work.
  std::vector<ReferenceKey> keys;
  for (const Config& c : configs)
    for (const ReferenceSpec& spec : {c.comparison.target, c.comparison.declared}) {
      const ReferenceKey k{c.scene, spec};
      if (std::find_if(keys.begin(), keys.end(),
                       [&](const ReferenceKey& x) { return !(x < k) && !(k < x); }) == keys.end())
        keys.push_back(k);
    }
  std::map<ReferenceKey, Reference> refs = computeReferences(o, s, keys);
  gi::vk::Context ctx = makeContext(o);
  std::vector<RenderJob> jobs;
  for (const Config& c : configs)
    jobs.push_back({&s.scenes[c.scene].scene, &c.settings, c.comparison.resource});
  ProgressBar bar(o.progress, "configurations", configs.size());
  std::vector<Scores> vsTargets(configs.size()), vsDeclareds(configs.size());
  std::vector<std::optional<gi::bench::QuantityGap>> gaps(configs.size());
  std::vector<std::vector<Row::RegionScore>> regions(configs.size());
  // The images scores are made from, kept while a reference may still be refined.
  std::vector<Measurement> images(configs.size());
  auto scoreConfig = [&](size_t i, const Measurement& m) {
    const Config& c = configs[i];
    const std::string& scene = s.scenes[c.scene].name;
    vsTargets[i] = score(m, c.comparison.target,
                         refs.at(ReferenceKey{c.scene, c.comparison.target}), o, scene);
    vsDeclareds[i] = score(m, c.comparison.declared,
                           refs.at(ReferenceKey{c.scene, c.comparison.declared}), o, scene);
    gaps[i] = gapOf(m, c.comparison, refs.at(ReferenceKey{c.scene, c.comparison.target}),
                    refs.at(ReferenceKey{c.scene, c.comparison.declared}), o);
    regions[i] =
        regionScores(m, c.comparison.target, refs.at(ReferenceKey{c.scene, c.comparison.target}), o,
                     s.scenes[c.scene].scene);
  };
  const bool refine = o.refSppMax > o.refSpp;
  const std::vector<Measurement> measured =
      measureAll(ctx, s.registry, jobs, o, true, [&](size_t i, const Measurement& m) {
        scoreConfig(i, m);
        if (refine) {
          images[i].out = m.out;
          images[i].depth = m.depth;
          images[i].emission = m.emission;
        }
        bar.step(s.scenes[configs[i].scene].name + " " + configs[i].effectLabel + " " +
                 configs[i].params);
      });
  const std::set<ReferenceKey> capped =
      refine ? refineReferences(o, s, configs, refs, vsTargets, vsDeclareds,
                                [&](size_t i) { scoreConfig(i, images[i]); })
             : std::set<ReferenceKey>{};
  images.clear();
  std::vector<Row> rows;
  for (size_t i = 0; i < configs.size(); ++i) {
    const Config& c = configs[i];
    const Measurement& m = measured[i];
    const Reference& target = refs.at(ReferenceKey{c.scene, c.comparison.target});
    const Reference& declared = refs.at(ReferenceKey{c.scene, c.comparison.declared});
    const Scores& vsTarget = vsTargets[i];
    const Scores& vsDeclared = vsDeclareds[i];
    Row r;
    r.scene = s.scenes[c.scene].name;
    r.effect = c.effectLabel;
    r.preset = c.preset;
    r.params = c.params;
    if (c.presetPtr)
      for (const std::string& e : c.effectSet) {
        auto it = c.presetPtr->effects.find(e);
        if (it == c.presetPtr->effects.end()) continue;
        for (const auto& [key, value] : it->second.items())
          r.presetSettings += (r.presetSettings.empty() ? "" : ", ") + key + " " + value.dump();
      }
    r.series = c.series;
    r.gridKey = c.gridKey;
    r.gridValue = c.gridValue;
    r.width = o.width;
    r.height = o.height;
    r.frames = o.frames;
    r.reps = o.reps;
    r.passes = m.passes;
    r.totalCi = m.total;
    r.effectCi = m.effect;
    r.floorCi = m.floor;
    r.wallCi = m.wall;
    r.effectReps = m.effectReps;
    r.effectRepsMin = m.effectRepsMin;
    r.effectRepsCpu = m.effectRepsCpu;
    r.batch = m.batch;
    r.floorReps = m.floorReps;
    r.totalMs = m.total.median;
    r.effectMs = m.effect.median;
    r.floorMs = m.floor.median;
    r.wallMs = m.wall.median;
    r.compared = c.comparison.resource;
    r.reference = referenceLabel(c.comparison.target, target.spp, o);
    r.referenceSpp = target.spp;
    r.referenceStdError = target.meanStdError;
    r.nrmse = vsTarget.metrics.nrmse;
    r.noiseFloor = vsTarget.metrics.noiseFloor;
    r.noiseCapped = capped.count(ReferenceKey{c.scene, c.comparison.target}) > 0;
    r.regions = regions[i];
    r.testMean = vsTarget.metrics.testMean;
    r.targetMean = vsTarget.metrics.referenceMean;
    r.declaredMean = vsDeclared.metrics.referenceMean;
    r.normaliser = vsTarget.metrics.normaliser;
    r.normaliserPixels = vsTarget.metrics.normaliserPixels;
    r.ssim = vsTarget.metrics.ssim;
    r.pixels = vsTarget.metrics.pixels;
    r.referenceSeconds = target.seconds;
    r.split = vsTarget.split;
    r.declared = referenceLabel(c.comparison.declared, declared.spp, o);
    r.declaredStdError = declared.meanStdError;
    r.declaredNrmse = vsDeclared.metrics.nrmse;
    if (gaps[i]) {
      r.gapPresent = true;
      r.gapNrmse = gaps[i]->gapNrmse;
      r.gapShare = gaps[i]->gapShare;
    }
    r.declaredSsim = vsDeclared.metrics.ssim;
    checkFinite(r);
    rows.push_back(std::move(r));
  }
  if (ctx.validationErrors() > 0) {
    std::fprintf(stderr, "gi-bench: error: %u Vulkan validation error(s)\n",
                 ctx.validationErrors());
    return 3;
  }
  gi::bench::fillRecovered(rows);
  gi::bench::RunInfo info{
      ctx.deviceName(),
      o.commandLine,
      nowString(),
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count(),
      loadStart,
      gi::bench::loadAverage()};
  gi::bench::writeResults(o.out, rows, info);
  std::printf("%zu configuration(s) in %.1f s -> %s/report.md\n", rows.size(), info.seconds,
              o.out.c_str());
  return 0;
}

}  // namespace gi_bench
