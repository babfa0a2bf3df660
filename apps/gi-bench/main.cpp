// gi-bench: what accuracy costs in time. Sweeps scenes x effects x presets x parameter grids,
// renders each configuration for a few frames (median GPU time per pass from timestamp
// queries), compares the effect's output with the CPU ray-traced reference (gi::reference,
// cached on disk) by NRMSE and SSIM, and writes results.csv/json, report.md and SVG plots.
// --calibrate measures this device and writes a preset whose sample counts are the most
// accurate that fit a frame budget.
// The modes live in sweep.cpp, calibrate.cpp and hard_case_sweep.cpp; the command line in
// options.cpp.
#include "cli.h"
#include "modes.h"

int main(int argc, char** argv) {
  return gi::cli::runMain("gi-bench", [&] {
    const gi_bench::Options o = gi_bench::parseArgs(argc, argv);
    if (o.hardCases) return gi_bench::runHardCaseSweep(o);
    return o.calibrate ? gi_bench::runCalibrate(o) : gi_bench::runSweep(o);
  });
}
