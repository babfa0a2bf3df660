// gi-bench's three modes: the accuracy/time sweep (sweep.cpp), the calibration of a preset
// (calibrate.cpp) and the hard-case robustness sweep (hard_case_sweep.cpp). Each returns the
// process's exit code.
#pragma once

#include "options.h"

namespace gi_bench {

int runSweep(const Options& o);
int runCalibrate(const Options& o);
int runHardCaseSweep(const Options& o);

}  // namespace gi_bench
