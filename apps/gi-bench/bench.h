// gi-bench's shared types: one measured configuration (a row of the results) and the writers
// of the results folder (results.csv, results.json, report.md, plots/*.svg).
#pragma once

#include <string>
#include <utility>
#include <vector>

namespace gi::bench {

struct Row {
  std::string scene, effect, preset;  // effect "none": engine only
  std::string params;                 // grid settings, "ssao.samples=16 ssao.radius=0.5"
  std::string series;                 // preset + grid settings other than the first grid key
  std::string gridKey;                // first grid key ("" without --grid)
  double gridValue = 0.0;             // its value in this configuration
  unsigned width = 0, height = 0;
  int frames = 0;
  std::vector<std::pair<std::string, double>> passes;  // median GPU ms per pass, graph order
  double totalMs = 0.0;   // sum of the pass medians, floor pass excluded
  double effectMs = 0.0;  // passes that are not the engine's (gbuffer, lighting, ...)
  double floorMs = 0.0;   // the engine's floor pass (a fixed full-screen cost baseline)
  double wallMs = 0.0;    // median CPU wall time of renderFrame() (submit + wait)
  std::string compared;   // "ao" or "lit"
  std::string reference;  // "ao r=0.5 spp=256" ...
  unsigned referenceSpp = 0;
  double referenceStdError = 0.0;  // mean per-pixel standard error of the reference
  double nrmse = 0.0, ssim = 1.0;
  size_t pixels = 0;  // compared (unmasked) pixels
};

struct RunInfo {
  std::string device, commandLine, date;
  double seconds = 0.0;
};

// Writes `text` to `path` through a temporary file and a rename.
void writeFileAtomic(const std::string& path, const std::string& text);
// results.csv, results.json, report.md and plots/<scene>_<effect>.svg under `dir`.
void writeResults(const std::string& dir, const std::vector<Row>& rows, const RunInfo& info);
// Indices of the rows on the Pareto front of (time, nrmse): no other row is both faster and
// more accurate. `time` picks the time of a row.
std::vector<size_t> paretoFront(const std::vector<const Row*>& rows);
double plotTime(const Row& row);  // effect ms when the effect has passes, else total ms

}  // namespace gi::bench
