// gi-bench's command line: what a run asks for (sweep, calibration or hard cases), parsed and
// checked before any work. The other files of gi-bench work in namespace gi_bench with the
// aliases below.
#pragma once

#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "bench.h"
#include "gi/reference/reference.h"
#include "quantity.h"

namespace gi_bench {

namespace fs = std::filesystem;
namespace ref = gi::reference;
using gi::bench::Interval;
using gi::bench::ReferenceSpec;
using gi::bench::Row;

struct Options {
  std::string out, cache, device;
  std::vector<std::string> scenes{"default"}, presets{"none"}, grids;
  std::optional<std::vector<std::string>> effects;
  uint32_t width = 320, height = 240, refSpp = 256;
  // Sweeps refine a reference (more samples) until its noise floor is at most a quarter of the
  // smallest NRMSE it scores, up to this many samples (0: 8 x refSpp; --quick: refSpp).
  uint32_t refSppMax = 0;
  uint64_t refSeed = 1;
  int frames = 5, reps = 5;
  bool hardCases = false;
  std::vector<std::string> cases;  // --hard-cases: a subset
  std::vector<std::string> sets;   // --hard-cases: effect settings
  std::string environmentMap;      // --hard-cases: replaces every case's environment
  bool quick = false, calibrate = false, progress = true, validation = false, aoSplit = false;
  std::optional<ref::Quantity> target;  // --target: one light quantity for every configuration
  bool excludeEmitters = false;         // --exclude-emitters
  bool emitterLight = true;             // false: --no-emitter-light
  uint32_t refBounces = 1;              // --ref-bounces
  bool isolatePasses = false;
  double budgetMs = 0.0, headroom = 0.1;
  std::string metric = "ssim";  // --calibrate: what "most accurate" means
  bool metricGiven = false;
  bool sizeGiven = false, framesGiven = false, sppGiven = false;
  std::string commandLine;
};

Options parseArgs(int argc, char** argv);
// Throws gi-bench's usage error "<where>: <message> (see gi-bench --help)".
[[noreturn]] void usageError(const std::string& where, const std::string& message);

}  // namespace gi_bench
