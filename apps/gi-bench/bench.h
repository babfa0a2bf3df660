// gi-bench's shared types: one measured configuration (a row of the results) and the writers
// of the results folder (results.csv, results.json, report.md, plots/*.svg).
#pragma once

#include <string>
#include <utility>
#include <vector>

#include "stats.h"

namespace gi::bench {

// GPU time of one pass: the median over repetitions of the per-repetition median over frames,
// and its confidence interval (stats.h).
struct PassTime {
  std::string name;
  Interval ms;
  std::vector<double> reps;     // each repetition's median over frames, in measurement order
  std::vector<double> repsMin;  // each repetition's fastest frame
  std::vector<double> repsCpu;  // each repetition's median process CPU ms (-1: not isolated)
};

struct Row {
  std::string scene, effect, preset;  // effect "none": engine only
  std::string params;                 // grid settings, "ssao.samples=16 ssao.radius=0.5"
  std::string series;                 // preset + grid settings other than the first grid key
  std::string presetSettings;         // what the preset sets for these effects: "samples 12, ..."
  std::string gridKey;                // first grid key ("" without --grid)
  double gridValue = 0.0;             // its value in this configuration
  unsigned width = 0, height = 0;
  int frames = 0;
  int reps = 0;                  // repetitions (each the median over `frames` frames)
  std::vector<PassTime> passes;  // GPU ms per pass, graph order
  // Medians over the repetitions; each repetition's total and effect time sum its pass
  // medians. The *Ci fields hold the same medians with their confidence intervals.
  double totalMs = 0.0;   // floor pass excluded
  double effectMs = 0.0;  // passes that are not the engine's (gbuffer, lighting, ...)
  double floorMs = 0.0;   // the engine's floor pass (a fixed full-screen cost baseline)
  double wallMs = 0.0;    // median CPU wall time of renderFrame() (submit + wait)
  Interval totalCi, effectCi, floorCi, wallCi;
  // Each repetition's effect and floor times, in order: repetition r of every configuration
  // ran in the same round, so ratios between configurations can be paired round by round
  // (repetitions.csv).
  std::vector<double> effectReps, floorReps;
  std::vector<double> effectRepsMin;  // each repetition's fastest frame per effect pass, summed
  std::vector<double> effectRepsCpu;  // each repetition's CPU ms of the effect passes (-1: none)
  size_t batch = 0;  // interleave batch (at most 16 configurations): rounds are shared within it
  std::string compared;  // "ao" or "lit"
  // Two scores: against the physical target (AO for AO-like effects, direct + indirect for GI
  // effects, else direct light) and against the quantity the effect declares it estimates
  // (Effect::estimatedQuantity, from its settings in this configuration).
  std::string reference;  // the target: "ao r=0.5 spp=256" ...
  unsigned referenceSpp = 0;
  double referenceStdError = 0.0;  // mean per-pixel standard error of the reference
  double nrmse = 0.0, ssim = 1.0;  // against the target
  // The target reference's own noise on NRMSE's scale (RMS standard error / normaliser over
  // the scored pixels: what a perfect renderer would score) and the normaliser: the mean target
  // over the scored pixels but emitters (lighting quantities), normaliserPixels of them.
  double noiseFloor = 0.0, normaliser = 1.0;
  size_t normaliserPixels = 0;
  bool noiseCapped = false;  // the target reference stopped at --ref-spp-max above 1/4 NRMSE
  // Means over the scored pixels: the compared image, the target and declared references.
  double testMean = 0.0, targetMean = 0.0, declaredMean = 0.0;
  // Per region the scene defines (SceneRegion): NRMSE against the target over the scored
  // pixels inside it (normalised by the region's own mean), and how many; pixels 0: not seen.
  struct RegionScore {
    std::string name;
    double nrmse = 0.0;
    size_t pixels = 0;
  };
  std::vector<RegionScore> regions;
  // Against the engine alone (the 'none' row of the same scene, preset and target, when the
  // sweep has one): its NRMSE, the share of it this row removes, 1 - NRMSE / NRMSE(none)
  // (negative: added), and with a direct+indirect target the share of the reference's indirect
  // light (target - direct reference) this row adds to the engine's image.
  bool recoveredPresent = false;
  double aloneNrmse = 0.0, errorRemoved = 0.0, indirectDelivered = 0.0;
  bool indirectPresent = false;
  std::string declared;  // "obscurance linear r=0.5 spp=256" ...
  double declaredStdError = 0.0;
  double declaredNrmse = 0.0, declaredSsim = 1.0;
  // When the declared quantity is not the target: metrics.h QuantityGap (the target error a
  // perfect estimator of the declared quantity would have, and its share of this row's).
  bool gapPresent = false;
  double gapNrmse = 0.0, gapShare = 0.0;
  size_t pixels = 0;              // compared (unmasked) pixels
  double referenceSeconds = 0.0;  // wall time the reference took (when it was computed)
  // With --ao-split (AO effects): the effect's error e = S - F (S the effect's AO, F = AO_full)
  // over the compared pixels, split as e = E + O + H: O and H the occluded fractions whose
  // occluders are off-screen and hidden (F + O + H = AO_visible), E = S - AO_visible the
  // estimator's own part. Shares of the mean squared error: mean(e X) / mean(e^2) for X = O, H,
  // E (they sum to 1; a negative share means that part cancels some of the others).
  struct AoSplit {
    bool present = false;
    double limitNrmse = 0.0;      // RMS(O + H) / mean(F): NRMSE(AO_visible vs AO_full)
    double offscreenNrmse = 0.0;  // RMS(O) / mean(F)
    double hiddenNrmse = 0.0;     // RMS(H) / mean(F)
    double estimatorNrmse = 0.0;  // RMS(E) / mean(F): the effect against AO_visible
    double visibleFraction = 0.0, offscreenFraction = 0.0, hiddenFraction = 0.0;  // means
    double shareOffscreen = 0.0, shareHidden = 0.0, shareEstimator = 0.0;
  } split;
};

struct RunInfo {
  std::string device, commandLine, date;
  double seconds = 0.0;
  // The machine's 1-minute load average when the run started and ended (/proc/loadavg; < 0:
  // unknown): timings on a loaded shared machine spread, and the report says how loaded it was.
  double loadStart = -1.0, loadEnd = -1.0;
};
// The 1-minute load average, or -1 where the system does not say.
double loadAverage();

// results.csv, results.json, report.md and plots/<scene>_<effect>.svg under `dir`.
void writeResults(const std::string& dir, const std::vector<Row>& rows, const RunInfo& info);
// Fills errorRemoved and indirectDelivered of every row that has an engine-alone row ('none',
// no parameters) of the same scene, preset, size and target.
void fillRecovered(std::vector<Row>& rows);

// Indices of the rows on the Pareto front of (plotted time with its interval, nrmse against
// the target), ordered by time: stats.h's paretoFront, so time differences inside the
// intervals do not keep a less accurate row on the front.
std::vector<size_t> paretoFront(const std::vector<const Row*>& rows);
double plotTime(const Row& row);        // effect ms when the effect has passes, else total ms
Interval plotInterval(const Row& row);  // the same choice, with its interval

}  // namespace gi::bench
