// gi-soak: renders many frames of an animated scene headless and samples host and device
// memory, then cycles through scene loads, plugin reloads and live effect toggles; fails (exit 1)
// when memory grows after warm-up. Prints the memory curve as CSV lines. tools/soak runs it.
//
// Device memory: lavapipe has no VK_EXT_memory_budget, so the engine's own allocator counters
// (live sub-allocations and their bytes, VkDeviceMemory blocks) stand for it; lavapipe's device
// memory is host memory and so is also inside the process's resident set.
#include <malloc.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <fstream>
#include <string>
#include <vector>

#include "cli.h"
#include "gi/effect_config.h"
#include "gi/effect_registry.h"
#include "gi/engine_settings.h"
#include "gi/errors.h"
#include "gi/renderer.h"
#include "gi/scene_io.h"
#include "gi/vk/context.h"
#include "gi/vk/memory.h"

namespace {

const char* kUsage =
    "usage: gi-soak [--scene S] [--frames N] [--cycles C] [--every K] [--width W --height H]\n"
    "  --scene S              animated scene (default assets/scenes/animated.json)\n"
    "  --frames N             frames rendered on one renderer, clock at 60 Hz (default 10000)\n"
    "  --cycles C             cycles of: fresh plugin registry, scene load, renderer, every\n"
    "                         effect toggled on and off live, 2 frames each (default 20)\n"
    "  --every K              memory sample every K frames (default N / 50)\n"
    "  --width W --height H   resolution (default 160x120)\n"
    "  --rss-tolerance-kib T  largest resident-set growth after warm-up (default 4096; not\n"
    "                         judged under AddressSanitizer, whose quarantine keeps memory)\n"
    "  --rss-per-cycle-kib P  more allowed per judged cycle (default 256: the driver's own\n"
    "                         retention per renderer, see docs/robustness.md; 0 for a driver\n"
    "                         that keeps nothing)\n"
    "  --validation           Vulkan validation layers (also GI_VALIDATION=1)\n"
    "  --device NAME          pick the Vulkan device by name or index (also GI_DEVICE)\n"
    "Warm-up: the first tenth of the frames (at least 20) and the first two cycles. After it,\n"
    "the engine's device allocations must not change at all and the resident set must not rise\n"
    "more than the tolerance (plus P per cycle after the warm-up) above its highest warm-up "
    "sample.\n";

// Under AddressSanitizer freed memory stays resident in its quarantine, so the resident set
// grows without a leak: only the engine's device allocations are judged there.
#ifdef __SANITIZE_ADDRESS__
constexpr double kDefaultRssToleranceKiB = 1e12;
#else
constexpr double kDefaultRssToleranceKiB = 4096;
#endif

struct Options {
  int frames = 10000, cycles = 20, every = 0;
  gi::cli::CommonFlags common;  // --scene, --width, --height, --validation, --device
  double rssToleranceKiB = kDefaultRssToleranceKiB;
  // Mesa 22.3's lavapipe keeps ~6 KiB of heap per pipeline it compiles (its compile threads;
  // heaptrack: every byte left at exit after 20 cycles is in libvulkan_lvp.so) plus LLVM's code
  // pages: ~155 KiB of resident set per cycle, a renderer's ~11 pipelines each. Not ours, and
  // not avoidable while each cycle makes a new renderer: allowed per cycle, with a margin.
  double rssPerCycleKiB = 256;
};

Options parseArgs(int argc, char** argv) {
  Options o;
  o.common.scene = std::string(GI_SOURCE_DIR) + "/assets/scenes/animated.json";
  o.common.width = 160;
  o.common.height = 120;
  o.common.validation = gi::vk::ContextOptions::fromEnvironment().validation;
  using namespace gi::cli;
  for (Args a("gi-soak", argc, argv, kUsage); a.next();) {
    if (parseCommonFlag(a, o.common, kSceneFlags | kSizeFlags | kDeviceFlags)) continue;
    if (a.is("--frames"))
      o.frames = int(a.integer(1, 100000000));
    else if (a.is("--cycles"))
      o.cycles = int(a.integer(0, 1000000));
    else if (a.is("--every"))
      o.every = int(a.integer(1, 100000000));
    else if (a.is("--rss-tolerance-kib"))
      o.rssToleranceKiB = a.number(0, 1e9);
    else if (a.is("--rss-per-cycle-kib"))
      o.rssPerCycleKiB = a.number(0, 1e9);
    else
      a.unknown();
  }
  if (o.every == 0) o.every = std::max(1, o.frames / 50);
  return o;
}

struct Sample {
  std::string phase;
  long step = 0;  // frame or cycle
  double rssKiB = 0;
  uint64_t deviceBytes = 0, allocations = 0;
  size_t blocks = 0;
};

// Resident set of this process (KiB), after returning freed heap pages to the system so that
// the allocator's caching does not read as growth.
double residentKiB() {
  malloc_trim(0);
  std::ifstream statm("/proc/self/statm");
  long size = 0, resident = 0;
  statm >> size >> resident;
  return double(resident) * double(sysconf(_SC_PAGESIZE)) / 1024.0;
}

Sample sample(gi::vk::Context& ctx, const std::string& phase, long step) {
  vkDeviceWaitIdle(ctx.device());
  const gi::vk::MemoryAllocator& a = ctx.allocator();
  Sample s{phase, step, residentKiB(), a.bytesInUse(), a.allocationCount(), a.blockCount()};
  std::printf("%s,%ld,%.0f,%llu,%llu,%zu\n", phase.c_str(), step, s.rssKiB,
              (unsigned long long)s.deviceBytes, (unsigned long long)s.allocations, s.blocks);
  std::fflush(stdout);
  return s;
}

// Compares the samples from `warm` on with the sample at `warm`: device counters exactly; and
// the last resident set with the highest of samples 0..warm, within the tolerance plus
// `perStepKiB` for each sample after `warm` (the resident set wanders by +-1.5 MiB from cycle to
// cycle as lavapipe compiles and frees each renderer's pipelines: a single low warm-up sample
// must not read as growth). Returns the problems.
std::vector<std::string> growth(const std::vector<Sample>& samples, size_t warm,
                                double toleranceKiB, double perStepKiB = 0.0) {
  std::vector<std::string> problems;
  if (warm >= samples.size()) return problems;
  const Sample& base = samples[warm];
  double baseRss = 0.0;
  for (size_t i = 0; i <= warm; ++i) baseRss = std::max(baseRss, samples[i].rssKiB);
  double peak = base.rssKiB;
  for (size_t i = warm; i < samples.size(); ++i) {
    const Sample& s = samples[i];
    peak = std::max(peak, s.rssKiB);
    if (s.deviceBytes != base.deviceBytes || s.allocations != base.allocations ||
        s.blocks != base.blocks) {
      problems.push_back(s.phase + " " + std::to_string(s.step) + ": device memory changed from " +
                         std::to_string(base.deviceBytes) + " bytes in " +
                         std::to_string(base.allocations) + " allocations to " +
                         std::to_string(s.deviceBytes) + " in " + std::to_string(s.allocations));
      break;
    }
  }
  const double grown = samples.back().rssKiB - baseRss;
  toleranceKiB += perStepKiB * double(samples.size() - 1 - warm);
  std::printf(
      "# %s: resident set at most %.0f KiB in the warm-up, %.0f KiB at the end (%+.0f KiB, "
      "peak %.0f; allowed %+.0f), device %llu bytes in %llu allocations\n",
      base.phase.c_str(), baseRss, samples.back().rssKiB, grown, peak, toleranceKiB,
      (unsigned long long)samples.back().deviceBytes,
      (unsigned long long)samples.back().allocations);
  if (grown > toleranceKiB)
    problems.push_back(base.phase + ": resident set grew by " + std::to_string(long(grown)) +
                       " KiB after warm-up (tolerance " + std::to_string(long(toleranceKiB)) +
                       " KiB)");
  return problems;
}

gi::RenderSettings settingsFor(const gi::Scene& scene, const gi::EffectRegistry& registry,
                               const Options& o) {
  gi::RenderSettings base;
  base.width = o.common.width;
  base.height = o.common.height;
  return gi::configureRender(scene, registry, o.common.request, base);
}

int run(const Options& o) {
  gi::vk::ContextOptions co = gi::vk::ContextOptions::fromEnvironment();
  co.validation = o.common.validation;
  if (!o.common.device.empty()) co.device = o.common.device;
  gi::vk::Context ctx(co);
  std::printf("# gi-soak on %s: %s, %d frames at %ux%u, %d cycles\n", ctx.deviceName().c_str(),
              o.common.scene.c_str(), o.frames, o.common.width, o.common.height, o.cycles);
  std::printf("phase,step,rss_kib,device_bytes,device_allocations,device_blocks\n");
  std::vector<std::string> problems;
  const auto start = std::chrono::steady_clock::now();

  // 1. One renderer, the animation running: per-frame work must not accumulate anything.
  {
    gi::EffectRegistry registry;
    registry.scanDefaultLocations();
    const gi::Scene scene = gi::loadScene(o.common.scene);
    gi::Renderer renderer(ctx, scene, settingsFor(scene, registry, o), &registry);
    std::vector<Sample> samples;
    size_t warm = 0;
    const int warmFrames = std::max(20, o.frames / 10);
    for (int f = 0; f < o.frames; ++f) {
      renderer.setTime(f / 60.0);
      renderer.renderFrame();
      if ((f + 1) % o.every == 0 || f + 1 == o.frames) {
        if (f + 1 >= warmFrames && !warm) warm = samples.size();
        samples.push_back(sample(ctx, "frames", f + 1));
      }
    }
    const auto p = growth(samples, warm, o.rssToleranceKiB);
    problems.insert(problems.end(), p.begin(), p.end());
  }
  const double framesSeconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();

  // 2. Everything that is created and destroyed: plugin registry (modules loaded again), scene,
  // renderer, live effect toggles.
  std::vector<Sample> cycles;
  for (int c = 0; c < o.cycles; ++c) {
    gi::EffectRegistry registry;
    registry.scanDefaultLocations();
    const gi::Scene scene = gi::loadScene(o.common.scene);
    gi::RenderSettings rs = settingsFor(scene, registry, o);
    gi::Renderer renderer(ctx, scene, rs, &registry);
    renderer.setTime(c * 0.37);
    renderer.renderFrame();
    const std::vector<gi::EffectConfig> original = rs.effects;
    for (const std::string& name : registry.names()) {
      renderer.setEffects({{name, registry.defaultSettings(name)}});  // on
      renderer.renderFrame();
      renderer.setEffects({});  // off
      renderer.renderFrame();
    }
    renderer.setEffects(original);
    renderer.renderFrame();
    cycles.push_back(sample(ctx, "cycles", c + 1));
  }
  if (!cycles.empty()) {
    const auto p =
        growth(cycles, std::min<size_t>(1, cycles.size() - 1), o.rssToleranceKiB, o.rssPerCycleKiB);
    problems.insert(problems.end(), p.begin(), p.end());
  }
  const double total =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  std::printf("# %d frames in %.1f s (%.2f ms per frame), %d cycles in %.1f s\n", o.frames,
              framesSeconds, 1000.0 * framesSeconds / o.frames, o.cycles, total - framesSeconds);
  if (ctx.validationErrors())
    problems.push_back(std::to_string(ctx.validationErrors()) + " validation errors");
  for (const std::string& p : problems) std::fprintf(stderr, "gi-soak: FAIL: %s\n", p.c_str());
  std::printf("# %s\n", problems.empty() ? "no growth" : "GROWTH FOUND");
  return problems.empty() ? 0 : 1;
}

}  // namespace

int main(int argc, char** argv) {
  return gi::cli::runMain("gi-soak", [&] { return run(parseArgs(argc, argv)); });
}
