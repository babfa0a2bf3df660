#include "modes.h"

#include <algorithm>
#include <cstdio>
#include <string>

#include "cli.h"
#include "hard_cases.h"
#include "setup.h"

namespace gi_bench {

int runHardCaseSweep(const Options& o) {
  gi::EffectRegistry registry;
  registry.scanDefaultLocations();
  gi::bench::HardCaseOptions hc;
  hc.width = o.width;
  hc.height = o.height;
  hc.flickerFrames = o.frames;
  hc.cases = o.cases;
  hc.sets = o.sets;
  hc.environmentMap = o.environmentMap;
  if (o.effects)
    for (const std::string& item : *o.effects) hc.effects.push_back(item);
  gi::vk::Context ctx = makeContext(o);
  std::string csv =
      "case,effect,textures,undecoded,values,non_finite,sky_fraction,flicker,seconds,problems,"
      "guards_fired\n";
  int failed = 0;
  size_t nonFinite = 0;
  const auto runs =
      gi::bench::runHardCases(ctx, registry, hc, [&](const gi::bench::HardCaseRun& r) {
        std::string problems;
        for (const std::string& p : r.problems) problems += (problems.empty() ? "" : "; ") + p;
        const std::string guards = gi::bench::guardSummary(r.guards);
        std::printf(
            "%-20s %-12s %2d textures (%d packed) %8zu values, %zu NaN/Inf, flicker %.3g, "
            "%.1f s%s%s%s%s\n",
            r.scene.c_str(), r.effect.c_str(), r.textures, r.undecoded, r.values, r.nonFinite,
            r.flicker, r.seconds, problems.empty() ? "" : "  FAIL: ", problems.c_str(),
            guards.empty() ? "" : "  guards fired: ", guards.c_str());
        std::fflush(stdout);
        std::string quoted = problems;
        std::replace(quoted.begin(), quoted.end(), '"', '\'');
        csv += r.scene + "," + r.effect + "," + std::to_string(r.textures) + "," +
               std::to_string(r.undecoded) + "," + std::to_string(r.values) + "," +
               std::to_string(r.nonFinite) + "," + formatDouble(r.skyFraction) + "," +
               formatDouble(r.flicker) + "," + formatDouble(r.seconds) + ",\"" + quoted + "\",\"" +
               guards + "\"\n";
        failed += !r.problems.empty();
        nonFinite += r.nonFinite;
      });
  gi::cli::writeFileAtomic((fs::path(o.out) / "hard_cases.csv").string(), csv);
  std::printf("%zu runs (%zu cases x %zu effect sets), %d failed, %zu NaN/Inf values -> %s\n",
              runs.size(), hc.cases.empty() ? gi::bench::hardCases().size() : hc.cases.size(),
              runs.size() / std::max<size_t>(1, hc.cases.empty() ? gi::bench::hardCases().size()
                                                                 : hc.cases.size()),
              failed, nonFinite, (fs::path(o.out) / "hard_cases.csv").c_str());
  return failed ? 1 : 0;
}

}  // namespace gi_bench
