#include "options.h"

#include <cstdlib>

#include "cli.h"
#include "gi/errors.h"
#include "gi/image_io.h"
#include "gi/vk/context.h"

namespace gi_bench {

namespace {

const char* kUsage =
    "usage: gi-bench --out DIR [--scenes A,B] [--effects E1,E2+E3,none] [--presets P1,none]\n"
    "                [--grid EFFECT.KEY=V1,V2,...]... [options]\n"
    "       gi-bench --quick --out DIR                  (CI smoke sweep, a few seconds)\n"
    "       gi-bench --hard-cases --out DIR [--effects A,B] [--cases C,D] [--frames K]\n"
    "                [--set EFFECT.KEY=V]...\n"
    "                (every effect x hard scenes: no NaN/Inf in any texture, ranges, flicker)\n"
    "       gi-bench --calibrate --budget-ms B --width W --height H [--scene S]\n"
    "                [--effects E] --out PRESET.json\n"
    "  --scenes A,B          scenes (JSON, model files or 'default'; default: default)\n"
    "  --effects A,B+C,none  effect sets to sweep, one per comma; '+' runs effects together,\n"
    "                        'none' is the engine alone, 'all' every registered effect (each\n"
    "                        alone; with presets, each with the presets that configure it),\n"
    "                        'recommended' each preset's recommended_effects together\n"
    "                        (default: ssao when found, else none)\n"
    "  --presets P,none,all  quality presets (names or files; 'none': effect defaults; 'all':\n"
    "                        every preset found, e.g. assets/presets/)\n"
    "  --grid E.K=V1,V2      sweep one setting; several --grid flags form a cartesian product\n"
    "  --frames K            frames per repetition, after one warm-up frame (default 5)\n"
    "  --reps R              repetitions per configuration (default 5), interleaved round-\n"
    "                        robin across configurations; times are medians over the\n"
    "                        repetitions with a 95% order-statistics interval (R >= 6 reaches\n"
    "                        95%; R = 5 gives [min, max], 93.75%)\n"
    "  --width W --height H  resolution (default 320x240)\n"
    "  --ref-spp N           reference samples per pixel (default 256)\n"
    "  --ref-spp-max N       a sweep renders a reference again with more samples until its\n"
    "                        noise floor (RMS standard error / normaliser) is at most a\n"
    "                        quarter of the smallest NRMSE it scores, up to N samples\n"
    "                        (default 8 x --ref-spp; --quick: --ref-spp, no refinement);\n"
    "                        the report marks references that stopped at N\n"
    "  --ref-seed N          reference seed (default 1)\n"
    "  --target Q            score every configuration's lit image against light quantity Q\n"
    "                        (direct or direct+indirect) instead of each effect's own target:\n"
    "                        AO effects are then scored by the lighting they modulate, so\n"
    "                        AO and GI effects share one axis (declared score: the effect's\n"
    "                        own light quantity, or Q for AO-like ones)\n"
    "  --exclude-emitters    leave pixels within 1 pixel of an emissive surface (G-buffer\n"
    "                        emission > 0) out of the scores: their radiance is the emitter's\n"
    "                        own, the same for every method, and where rasteriser and ray\n"
    "                        tracer put an emitter's edge in different pixels that edge\n"
    "                        (radiance many times its surroundings') can dominate the NRMSE\n"
    "  --no-emitter-light    direct+indirect references: emissive surfaces are seen but light\n"
    "                        nothing (as for effects whose light comes from the lights only,\n"
    "                        e.g. ISM's VPLs; the Cornell box's lamp is an emissive quad)\n"
    "  --ref-bounces N       direct+indirect references: diffuse bounces, 1..8 (default 1;\n"
    "                        e.g. for ism.bounces=N)\n"
    "  --ao-split            AO effects: split the reference's occlusion into what the depth\n"
    "                        buffer holds, off-screen and hidden occluders (gi-reference\n"
    "                        --quantity ao-split) and report where the effect cannot converge\n"
    "  --cache DIR           reference cache (default: build/bench-cache in a build tree,\n"
    "                        else ~/.cache/gi/bench-cache)\n"
    "  --isolate-passes      submit each pass alone and wait (a CPU driver otherwise lets a\n"
    "                        pass's work spill into the next pass's timestamps) and also\n"
    "                        record each pass's process CPU time (repetitions.csv: robust\n"
    "                        to other jobs on a shared CPU, unlike wall-clock timestamps)\n"
    "  --budget-ms B         --calibrate: frame budget (GPU ms, all passes)\n"
    "  --headroom F          --calibrate: keep the measured time under (1 - F) * budget (0.1);\n"
    "                        the upper end of the time interval must fit, and cost is assumed\n"
    "                        not to fall when a sample count rises unless measured clearly\n"
    "                        lower\n"
    "  --metric M            --calibrate: accuracy to maximise, ssim (default) or nrmse. SSIM\n"
    "                        sees noise and interleave patterns that a biased estimator's\n"
    "                        NRMSE hides (SSAO's NRMSE is ~flat from 1 to 64 samples)\n"
    "  --cases A,B           --hard-cases: only these cases (default: all)\n"
    "  --set E.K=V           --hard-cases: a setting of effect E for its runs, or of the\n"
    "                        engine (engine.K=V) for every run (repeatable)\n"
    "  --environment-map F   --hard-cases: every case under this equirect HDR map\n"
    "  --no-progress         no progress lines on stderr\n"
    "  --validation          Vulkan validation layers (also GI_VALIDATION=1)\n"
    "  --device NAME         Vulkan device by name or index (also GI_DEVICE)\n"
    "Ground truth, two scores per configuration: against the quantity the effect declares it\n"
    "estimates with its current settings (Effect::estimatedQuantity: AO, obscurance with a\n"
    "membership, the Alchemy integral, direct or direct+indirect light) and against its\n"
    "physical target (EffectInfo::estimates: reference AO of its radius for AO-like effects,\n"
    "direct+indirect for indirect light, else direct). AO-like quantities are read from the\n"
    "'ao' resource, light from the lit image. Sky pixels (reference sky mask or G-buffer\n"
    "depth 0) are excluded.\n";

}  // namespace

[[noreturn]] void usageError(const std::string& where, const std::string& message) {
  gi::cli::usageError("gi-bench", where, message);
}

// The reference cache: build/bench-cache in a build tree (<bin>/../CMakeCache.txt), else the
// user's cache folder ($XDG_CACHE_HOME or ~/.cache, gi/bench-cache): an installed prefix may
// not be writable.
std::string defaultCacheDir() {
  std::error_code ec;
  const fs::path exe = fs::read_symlink("/proc/self/exe", ec);
  if (!ec && fs::exists(exe.parent_path().parent_path() / "CMakeCache.txt", ec))
    return (exe.parent_path().parent_path() / "bench-cache").string();
  if (const char* xdg = std::getenv("XDG_CACHE_HOME"); xdg && *xdg)
    return (fs::path(xdg) / "gi" / "bench-cache").string();
  if (const char* home = std::getenv("HOME"); home && *home)
    return (fs::path(home) / ".cache" / "gi" / "bench-cache").string();
  return "bench-cache";
}

Options parseArgs(int argc, char** argv) {
  Options o;
  o.validation = gi::vk::ContextOptions::fromEnvironment().validation;
  for (int i = 0; i < argc; ++i) {  // appended: GCC 12 warns falsely (-Wrestrict) on " " + s
    if (i) o.commandLine += ' ';
    o.commandLine += argv[i];
  }
  gi::cli::CommonFlags device;  // --device, --validation: parsed as every app parses them
  device.validation = o.validation;
  for (gi::cli::Args a("gi-bench", argc, argv, kUsage); a.next();) {
    if (gi::cli::parseCommonFlag(a, device, gi::cli::kDeviceFlags)) continue;
    if (a.is("--out"))
      o.out = a.value();
    else if (a.is("--scenes") || a.is("--scene"))
      o.scenes = a.list();
    else if (a.is("--effects"))
      o.effects = a.list();  // a set twice is refused, as gi-render refuses an effect twice
    else if (a.is("--presets") || a.is("--preset"))
      o.presets = a.list();
    else if (a.is("--grid"))
      o.grids.push_back(a.value());
    else if (a.is("--frames")) {
      o.frames = int(a.integer(1, 10000));
      o.framesGiven = true;
    } else if (a.is("--reps"))
      o.reps = int(a.integer(1, 1000));
    else if (a.is("--width")) {
      o.width = uint32_t(a.integer(1, 16384));
      o.sizeGiven = true;
    } else if (a.is("--height")) {
      o.height = uint32_t(a.integer(1, 16384));
      o.sizeGiven = true;
    } else if (a.is("--ref-spp")) {
      o.refSpp = uint32_t(a.integer(1, 1 << 20));
      o.sppGiven = true;
    } else if (a.is("--ref-spp-max")) {
      o.refSppMax = uint32_t(a.integer(1, 1 << 20));
    } else if (a.is("--ref-seed"))
      o.refSeed = uint64_t(a.integer(0, 1000000000000000));
    else if (a.is("--cache"))
      o.cache = a.value();
    else if (a.is("--budget-ms"))
      o.budgetMs = a.numberAbove(0, 1e7);
    else if (a.is("--headroom"))
      o.headroom = a.number(0, 0.9);
    else if (a.is("--quick"))
      o.quick = true;
    else if (a.is("--hard-cases"))
      o.hardCases = true;
    else if (a.is("--cases")) {
      o.cases = a.list();
      if (o.cases.empty()) a.fail("no case given (leave the option out for every case)");
    } else if (a.is("--set"))
      o.sets.push_back(a.value());
    else if (a.is("--environment-map"))
      o.environmentMap = a.value();
    else if (a.is("--target")) {
      const std::string q = a.value();
      if (q != "direct" && q != "direct+indirect")
        a.fail("expects direct or direct+indirect, got '" + q + "'");
      o.target = ref::parseQuantity(q);
    } else if (a.is("--exclude-emitters"))
      o.excludeEmitters = true;
    else if (a.is("--no-emitter-light"))
      o.emitterLight = false;
    else if (a.is("--ref-bounces"))
      o.refBounces = uint32_t(a.integer(1, ref::kMaxBounces));
    else if (a.is("--ao-split"))
      o.aoSplit = true;
    else if (a.is("--isolate-passes"))
      o.isolatePasses = true;
    else if (a.is("--calibrate"))
      o.calibrate = true;
    else if (a.is("--metric")) {
      o.metric = a.value();
      o.metricGiven = true;
      if (o.metric != "ssim" && o.metric != "nrmse")
        a.fail("expects ssim or nrmse, got '" + o.metric + "'");
    } else if (a.is("--no-progress"))
      o.progress = false;
    else
      a.unknown();
  }
  o.validation = device.validation;
  o.device = device.device;
  if (o.out.empty()) usageError("", "--out is required");
  if (o.scenes.empty()) usageError("--scenes", "no scene given");
  if (o.presets.empty()) usageError("--presets", "no preset given");
  if (!o.calibrate && o.metricGiven) usageError("--metric", "only applies to --calibrate");
  if (o.calibrate) {
    if (!(o.budgetMs > 0)) usageError("--calibrate", "needs --budget-ms");
    if (fs::path(o.out).extension() != ".json")
      usageError(o.out, "--calibrate writes a preset: --out must end in .json");
  }
  if (!o.hardCases && !o.cases.empty()) usageError("--cases", "only applies to --hard-cases");
  if (!o.hardCases && !o.sets.empty())
    usageError("--set", "only applies to --hard-cases (sweeps use --grid)");
  if (!o.hardCases && !o.environmentMap.empty())
    usageError("--environment-map", "only applies to --hard-cases");
  if (o.target && (o.aoSplit || o.calibrate || o.hardCases))
    usageError("--target", "excludes --ao-split, --calibrate and --hard-cases");
  if (o.hardCases) {
    if (o.calibrate || o.quick) usageError("--hard-cases", "excludes --calibrate and --quick");
    if (!o.sizeGiven) o.width = 160, o.height = 120;
    if (!o.framesGiven) o.frames = 64;
  }
  if (o.quick) {
    if (!o.sizeGiven) o.width = 64, o.height = 48;
    if (!o.framesGiven) o.frames = 2;
    if (!o.sppGiven) o.refSpp = 16;
  }
  if (o.refSppMax == 0) o.refSppMax = o.quick ? o.refSpp : 8 * o.refSpp;
  if (o.refSppMax < o.refSpp) usageError("--ref-spp-max", "must be at least --ref-spp");
  if (o.cache.empty()) o.cache = defaultCacheDir();
  // Where results go is checked now, not after the sweep and its references.
  if (o.calibrate) {
    gi::cli::checkOutputWritable(o.out);
  } else {
    gi::cli::checkOutputFolder(o.out);
    // The files the run will replace (report.cpp, hard_case_sweep.cpp), and whatever plots/
    // already holds: none may be a folder, device, FIFO or socket.
    for (const char* file :
         {"results.csv", "repetitions.csv", "results.json", "report.md", "hard_cases.csv"})
      gi::checkReplaceableOutput((fs::path(o.out) / file).string());
    const fs::path plots = fs::path(o.out) / "plots";
    std::error_code ec;
    if (fs::exists(plots, ec) && !fs::is_directory(plots, ec))
      throw gi::Error(gi::ErrorKind::Output, plots.string(), "exists and is not a folder");
    if (fs::is_directory(plots, ec))
      for (const fs::directory_entry& e : fs::directory_iterator(plots, ec))
        gi::checkReplaceableOutput(e.path().string());
  }
  gi::cli::checkOutputFolder(o.cache);
  return o;
}

}  // namespace gi_bench
