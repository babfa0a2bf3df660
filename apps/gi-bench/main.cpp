// gi-bench: what accuracy costs in time. Sweeps scenes x effects x presets x parameter grids,
// renders each configuration for a few frames (median GPU time per pass from timestamp
// queries), compares the effect's output with the CPU ray-traced reference (gi::reference,
// cached on disk) by NRMSE and SSIM, and writes results.csv/json, report.md and SVG plots.
// --calibrate measures this device and writes a preset whose sample counts are the most
// accurate that fit a frame budget.
#include <unistd.h>

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

#include "bench.h"
#include "cli.h"
#include "gi/effect_config.h"
#include "gi/engine_settings.h"
#include "gi/errors.h"
#include "gi/image_io.h"
#include "gi/input_file.h"
#include "gi/reference/reference.h"
#include "gi/renderer.h"
#include "gi/scene_io.h"
#include "gi/vk/context.h"
#include "hard_cases.h"
#include "metrics.h"
#include "quantity.h"
#include "stats.h"

namespace {

namespace fs = std::filesystem;
namespace ref = gi::reference;
using gi::bench::Interval;
using gi::bench::ReferenceSpec;
using gi::bench::Row;

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
    "                        alone; with presets, each with the presets that configure it)\n"
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
    "  --set E.K=V           --hard-cases: a setting of effect E for its runs (repeatable)\n"
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

struct Options {
  std::string out, cache, device;
  std::vector<std::string> scenes{"default"}, presets{"none"}, grids;
  std::optional<std::vector<std::string>> effects;
  uint32_t width = 320, height = 240, refSpp = 256;
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
  for (int i = 0; i < argc; ++i) o.commandLine += (i ? " " : "") + std::string(argv[i]);
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
    else if (a.is("--cases"))
      o.cases = a.list();
    else if (a.is("--set"))
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
  if (o.cache.empty()) o.cache = defaultCacheDir();
  // Where results go is checked now, not after the sweep and its references.
  if (o.calibrate)
    gi::cli::checkOutputWritable(o.out);
  else
    gi::cli::checkOutputFolder(o.out);
  gi::cli::checkOutputFolder(o.cache);
  return o;
}

// ---- What an effect is compared with -------------------------------------------------------

struct Comparison {
  std::string resource = gi::resources::kLit;  // what the frame is read at
  ReferenceSpec declared, target;              // what it estimates; its physical target
  std::string effect;                          // the effect that decided it ("" for the engine)
};

// The first effect with an AO-like declaration or target decides (its "ao" is compared), else
// the first that estimates indirect light, else direct light. `aoSplit`: the AO target is the
// ao-split reference (its value is AO_full).
Comparison comparisonFor(const std::vector<gi::EffectConfig>& effects,
                         const gi::EffectRegistry& registry, bool aoSplit) {
  Comparison c;
  c.declared.quantity = c.target.quantity = ref::Quantity::Direct;
  bool indirect = false;
  for (const auto& e : effects) {
    if (!registry.has(e.name)) continue;
    gi::GroundTruth truth = registry.info(e.name).estimates;
    const gi::EstimatedQuantity q = registry.create(e.name)->estimatedQuantity(e.settings);
    const ReferenceSpec declared = gi::bench::declaredSpec(q);
    const bool aoDeclared = gi::bench::isAoLike(declared.quantity);
    // An AO effect may output light itself under some settings (obscurance's radiance
    // transfer publishes the ambient light): it declares a light quantity, and is then judged
    // as light. A light effect that declares AO has no "ao" to read: an error.
    if (!aoDeclared && truth == gi::GroundTruth::AmbientOcclusion)
      truth = declared.quantity == ref::Quantity::Direct ? gi::GroundTruth::DirectLight
                                                         : gi::GroundTruth::IndirectLight;
    if (aoDeclared != (truth == gi::GroundTruth::AmbientOcclusion))
      throw gi::Error(gi::ErrorKind::InvalidData, e.name,
                      "the effect's estimatedQuantity (" + gi::bench::label(declared) +
                          ") is AO-like but its ground truth (info().estimates) is light");
    if (aoDeclared) {
      c.resource = gi::resources::kAO;
      c.declared = declared;
      // The ao-split reference's value is AO bit for bit: one reference serves both scores.
      if (aoSplit && declared.quantity == ref::Quantity::AO)
        c.declared.quantity = ref::Quantity::AOSplit;
      c.target = gi::bench::targetSpec(truth, q, aoSplit);
      c.effect = e.name;
      return c;
    }
    if (!indirect && (truth == gi::GroundTruth::IndirectLight ||
                      declared.quantity == ref::Quantity::DirectIndirect)) {
      indirect = true;
      c.declared = declared;
      c.target = gi::bench::targetSpec(gi::GroundTruth::IndirectLight, q, false);
      c.effect = e.name;
    }
  }
  return c;
}

// --target: the lit image against one light quantity, whatever the effects estimate (an AO
// effect is then judged by the lighting it modulates). An AO-like declaration cannot be read
// from the lit image: its declared score becomes the target's.
Comparison litAgainst(Comparison c, ref::Quantity target) {
  c.resource = gi::resources::kLit;
  c.target = ReferenceSpec{};
  c.target.quantity = target;
  if (gi::bench::isAoLike(c.declared.quantity)) c.declared = c.target;
  return c;
}

// Direct+indirect references also name their bounces (--ref-bounces) and "dark-emitters"
// (--no-emitter-light: emissive surfaces light nothing).
std::string referenceLabel(const ReferenceSpec& spec, uint32_t spp, const Options& o) {
  const bool light = spec.quantity == ref::Quantity::DirectIndirect;
  return gi::bench::label(spec) + " spp=" + std::to_string(spp) +
         (light && o.refBounces > 1 ? " bounces=" + std::to_string(o.refBounces) : "") +
         (light && !o.emitterLight ? " dark-emitters" : "");
}

// ---- Reference cache -------------------------------------------------------------------------

uint64_t fnv1a(const std::string& s, uint64_t h = 1469598103934665603ULL) {
  for (unsigned char c : s) h = (h ^ c) * 1099511628211ULL;
  return h;
}

struct Reference {
  gi::ImageRGBA32F value, depth;
  gi::ImageRGBA32F split;  // ao-split only: AO_visible, f_off, f_hid (reference.h)
  uint32_t spp = 0;
  double meanStdError = 0.0, seconds = 0.0;
  bool cached = false;
};

struct ReferenceKey {
  size_t scene = 0;
  ReferenceSpec spec;  // quantity and every parameter it uses
  bool operator<(const ReferenceKey& o) const {
    return scene != o.scene ? scene < o.scene : spec < o.spec;
  }
};

struct LoadedScene {
  std::string name;  // as given
  gi::Scene scene;
  std::string contents;  // file bytes ("default" for the built-in scene)
};

std::string cacheStem(const Options& o, const LoadedScene& s, const ReferenceKey& k) {
  std::ostringstream key;
  key << "gi-bench-reference-v3|" << s.contents.size() << '|';
  const gi::CameraView cam = gi::activeCamera(s.scene, float(o.width) / float(o.height));
  const float* v = &cam.view[0][0];
  const float* p = &cam.proj[0][0];
  char buf[32];
  for (int i = 0; i < 16; ++i) {
    std::snprintf(buf, sizeof buf, "%a,%a,", double(v[i]), double(p[i]));
    key << buf;
  }
  key << '|' << o.width << 'x' << o.height << '|' << gi::bench::keyText(k.spec) << '|' << o.refSpp
      << '|' << o.refSeed << '|' << s.scene.triangleCount()
      << (o.emitterLight ? "" : "|dark-emitters") << "|bounces" << o.refBounces;
  char hex[17];
  std::snprintf(hex, sizeof hex, "%016llx",
                static_cast<unsigned long long>(fnv1a(s.contents, fnv1a(key.str()))));
  return (fs::path(o.cache) / hex).string();
}

Reference computeReference(const Options& o, const LoadedScene& s, const ReferenceKey& k) {
  const std::string stem = cacheStem(o, s, k);
  Reference r;
  if (fs::exists(stem + ".json")) {
    try {
      std::ifstream in(stem + ".json");
      const nlohmann::json meta = nlohmann::json::parse(in);
      r.value = gi::readPfm(stem + ".value.pfm");
      r.depth = gi::readPfm(stem + ".depth.pfm");
      if (k.spec.quantity == ref::Quantity::AOSplit) r.split = gi::readPfm(stem + ".split.pfm");
      r.spp = meta.at("spp");
      r.meanStdError = meta.at("mean_stderr");
      r.seconds = meta.at("seconds");
      r.cached = true;
      if (r.value.width == int(o.width) && r.value.height == int(o.height) &&
          (k.spec.quantity != ref::Quantity::AOSplit ||
           (r.split.width == r.value.width && r.split.height == r.value.height)))
        return r;
    } catch (const std::exception& e) {
      std::fprintf(stderr, "gi-bench: warning: %s: unreadable cache entry, recomputing (%s)\n",
                   stem.c_str(), e.what());
    }
  }
  ref::Settings rs;
  rs.width = o.width;
  rs.height = o.height;
  gi::bench::apply(k.spec, rs);
  rs.spp = o.refSpp;
  rs.minSpp = std::min(rs.minSpp, o.refSpp);
  rs.seed = o.refSeed;
  rs.emitterLight = o.emitterLight;
  rs.bounces = o.refBounces;
  ref::Result res = ref::render(s.scene, rs);
  r = Reference{res.value, res.depth, res.split, res.spp, res.meanStdError, res.seconds, false};
  fs::create_directories(o.cache);
  // The metadata is written last: its presence marks a complete entry.
  gi::writePfm(stem + ".value.pfm", r.value);
  gi::writePfm(stem + ".depth.pfm", r.depth);
  if (k.spec.quantity == ref::Quantity::AOSplit) gi::writePfm(stem + ".split.pfm", r.split);
  nlohmann::json meta = {{"scene", s.name},
                         {"quantity", gi::bench::label(k.spec)},
                         {"key", gi::bench::keyText(k.spec)},
                         {"width", o.width},
                         {"height", o.height},
                         {"spp", r.spp},
                         {"seed", o.refSeed},
                         {"mean_stderr", r.meanStdError},
                         {"seconds", r.seconds}};
  gi::cli::writeFileAtomic(stem + ".json", meta.dump(2) + "\n");
  return r;
}

// ---- Progress ---------------------------------------------------------------------------------

class ProgressBar {
 public:
  ProgressBar(bool enabled, std::string what, size_t total)
      : enabled_(enabled && total > 0),
        tty_(isatty(STDERR_FILENO) != 0),
        what_(std::move(what)),
        total_(total),
        start_(std::chrono::steady_clock::now()) {}
  void step(const std::string& label) {
    ++done_;
    if (!enabled_) return;
    const double elapsed =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
    const double eta = elapsed / double(done_) * double(total_ - done_);
    const int width = 30, filled = int(double(width) * double(done_) / double(total_));
    if (tty_) {
      std::fprintf(stderr, "\r%s [%s%s] %zu/%zu  %.0fs elapsed, ETA %.0fs  %-40.40s", what_.c_str(),
                   std::string(size_t(filled), '#').c_str(),
                   std::string(size_t(width - filled), '.').c_str(), done_, total_, elapsed, eta,
                   label.c_str());
      if (done_ == total_) std::fputc('\n', stderr);
    } else {
      std::fprintf(stderr, "gi-bench: %s %zu/%zu (%s) %.1fs elapsed, ETA %.0fs\n", what_.c_str(),
                   done_, total_, label.c_str(), elapsed, eta);
    }
    std::fflush(stderr);
  }

 private:
  bool enabled_, tty_;
  std::string what_;
  size_t total_, done_ = 0;
  std::chrono::steady_clock::time_point start_;
};

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

std::vector<std::string> splitPlus(const std::string& item) {
  if (item == "none") return {};
  std::vector<std::string> out;
  std::string part;
  std::istringstream in(item);
  while (std::getline(in, part, '+'))
    if (!part.empty()) out.push_back(part);
  return out;
}

std::string joinList(const std::vector<std::string>& items) {
  std::string s;
  for (const auto& n : items) s += (s.empty() ? "" : ", ") + n;
  return s;
}

std::string knownEffects(const gi::EffectRegistry& registry) {
  const std::string s = joinList(registry.names());
  return s.empty() ? "none found" : s;
}

// ---- Measuring one configuration
// -----------------------------------------------------------------

using gi::bench::median;

// One configuration's timings: per repetition, each pass's median over the frames, and the
// totals summed from them.
struct Timing {
  std::vector<std::string> passNames;  // graph order
  std::map<std::string, std::vector<double>> passes;
  std::map<std::string, std::vector<double>> passMins;  // per repetition: fastest frame
  std::map<std::string, std::vector<double>> passCpu;   // per repetition: median CPU ms
  std::vector<double> total, effect, floor, wall;
  std::vector<double> effectMin;  // per repetition: the effect passes' fastest frames, summed
  std::vector<double> effectCpu;  // per repetition: the effect passes' median CPU ms, summed
};

// The rendered configuration: its timings over the repetitions and, after the last one, the
// compared resource and the depth (dropped once scored).
struct Measurement {
  std::vector<gi::bench::PassTime> passes;
  Interval total, effect, floor, wall;
  std::vector<double> effectReps, floorReps;  // per repetition, in order
  std::vector<double> effectRepsMin;          // per repetition: fastest frames
  std::vector<double> effectRepsCpu;          // per repetition: CPU ms (--isolate-passes)
  size_t batch = 0;  // interleave batch: only configurations of one batch share rounds
  gi::ImageRGBA32F out, depth;
  gi::ImageRGBA32F emission;  // --exclude-emitters only
};

// The effect's AO error against the ao-split reference, decomposed as in Row::AoSplit, over the
// pixels `mask` keeps (the ones NRMSE and SSIM use).
Row::AoSplit splitError(const gi::ImageRGBA32F& out, const Reference& reference,
                        const std::vector<unsigned char>& mask) {
  auto sanitize = [](float v) { return std::isfinite(v) ? double(v) : 1e6; };  // as metrics.h
  double sumF = 0.0, ee = 0.0, eO = 0.0, eH = 0.0, eE = 0.0, OH2 = 0.0, O2 = 0.0, H2 = 0.0,
         E2 = 0.0, sumV = 0.0, sumO = 0.0, sumH = 0.0;
  size_t n = 0;
  for (size_t i = 0; i < mask.size(); ++i) {
    if (!mask[i]) continue;
    const double S = sanitize(out.pixels[i * 4]), F = sanitize(reference.value.pixels[i * 4]);
    const double V = sanitize(reference.split.pixels[i * 4]);
    const double O = sanitize(reference.split.pixels[i * 4 + 1]);
    const double H = sanitize(reference.split.pixels[i * 4 + 2]);
    // e = S - F = E + O + H exactly with E = S - (F + O + H) (= S - AO_visible up to rounding).
    const double e = S - F, E = S - (F + O + H);
    sumF += std::abs(F);
    ee += e * e;
    eO += e * O;
    eH += e * H;
    eE += e * E;
    OH2 += (O + H) * (O + H);
    O2 += O * O;
    H2 += H * H;
    E2 += E * E;
    sumV += 1.0 - V;
    sumO += O;
    sumH += H;
    ++n;
  }
  Row::AoSplit s;
  s.present = true;
  if (n == 0) return s;
  const double count = double(n), meanF = sumF / count > 1e-8 ? sumF / count : 1.0;
  auto nrmse = [&](double sumSquares) { return std::sqrt(sumSquares / count) / meanF; };
  s.limitNrmse = nrmse(OH2);
  s.offscreenNrmse = nrmse(O2);
  s.hiddenNrmse = nrmse(H2);
  s.estimatorNrmse = nrmse(E2);
  s.visibleFraction = sumV / count;
  s.offscreenFraction = sumO / count;
  s.hiddenFraction = sumH / count;
  if (ee > 0.0) {
    s.shareOffscreen = eO / ee;
    s.shareHidden = eH / ee;
    s.shareEstimator = eE / ee;
  }
  return s;
}

// What a configuration renders.
struct RenderJob {
  const gi::Scene* scene = nullptr;
  const gi::RenderSettings* settings = nullptr;  // effects and engine settings
  std::string resource;                          // read back after the last repetition
};

// One repetition: a warm-up frame (the previous repetition ran other configurations), then
// `frames` timed frames; each pass's median over them.
void measureRepetition(gi::Renderer& renderer, int frames, Timing& t) {
  renderer.renderFrame();
  std::map<std::string, std::vector<double>> samples, cpu;
  std::vector<double> wall;
  for (int f = 0; f < frames; ++f) {
    const auto t0 = std::chrono::steady_clock::now();
    renderer.renderFrame();
    wall.push_back(
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count());
    for (const auto& pt : renderer.lastTimings()) {
      samples[pt.name].push_back(pt.ms);
      if (pt.cpuMs >= 0.0) cpu[pt.name].push_back(pt.cpuMs);
    }
  }
  t.passNames = renderer.passNames();
  double total = 0.0, effect = 0.0, floor = 0.0, effectMin = 0.0, effectCpu = 0.0;
  for (const std::string& name : t.passNames) {
    const double ms = median(samples[name]);
    t.passes[name].push_back(ms);
    // On a shared CPU device a frame's pass is often preempted: the fastest frame is the
    // least disturbed one (repetitions.csv keeps it beside the median).
    const double fastest = *std::min_element(samples[name].begin(), samples[name].end());
    t.passMins[name].push_back(fastest);
    const double cpuMs = cpu[name].empty() ? -1.0 : median(cpu[name]);
    t.passCpu[name].push_back(cpuMs);
    if (name != "floor" && !renderer.isEnginePass(name)) {
      effectMin += fastest;
      effectCpu += cpuMs;
    }
    if (name == "floor") {
      floor = ms;
      continue;
    }
    total += ms;
    if (!renderer.isEnginePass(name)) effect += ms;
  }
  t.total.push_back(total);
  t.effect.push_back(effect);
  t.effectMin.push_back(effectMin);
  t.effectCpu.push_back(cpu.empty() ? -1.0 : effectCpu);
  t.floor.push_back(floor);
  t.wall.push_back(median(wall));
}

// Configurations measured together, at most this many renderers alive at once: repetition r of
// every configuration of a batch runs before repetition r + 1 of any.
constexpr size_t kInterleaveBatch = 16;

// `scoreNow(i, m)` is called once job i is measured, while its images are held; they are
// dropped afterwards (a sweep at a large resolution would otherwise hold all of them).
std::vector<Measurement> measureAll(
    gi::vk::Context& ctx, const gi::EffectRegistry& registry, const std::vector<RenderJob>& jobs,
    const Options& o, bool floorPass,
    const std::function<void(size_t, const Measurement&)>& scoreNow) {
  std::vector<Measurement> out(jobs.size());
  for (size_t first = 0; first < jobs.size(); first += kInterleaveBatch) {
    const size_t last = std::min(jobs.size(), first + kInterleaveBatch);
    std::vector<std::unique_ptr<gi::Renderer>> renderers;
    for (size_t i = first; i < last; ++i) {
      gi::RenderSettings settings = *jobs[i].settings;
      settings.width = o.width;
      settings.height = o.height;
      settings.floorPass = floorPass;
      settings.isolatePasses = o.isolatePasses;
      settings.keepForReadback = {jobs[i].resource, gi::resources::kDepth};  // read when scored
      if (o.excludeEmitters) settings.keepForReadback.push_back(gi::resources::kEmission);
      renderers.push_back(std::make_unique<gi::Renderer>(ctx, *jobs[i].scene, settings, &registry));
      renderers.back()->renderFrame();  // first-use costs stay out of every repetition
    }
    std::vector<Timing> timings(last - first);
    for (int r = 0; r < o.reps; ++r)
      for (size_t i = first; i < last; ++i)
        measureRepetition(*renderers[i - first], o.frames, timings[i - first]);
    for (size_t i = first; i < last; ++i) {
      const Timing& t = timings[i - first];
      Measurement& m = out[i];
      for (const std::string& name : t.passNames)
        m.passes.push_back({name, gi::bench::medianInterval(t.passes.at(name)), t.passes.at(name),
                            t.passMins.at(name), t.passCpu.at(name)});
      m.total = gi::bench::medianInterval(t.total);
      m.effect = gi::bench::medianInterval(t.effect);
      m.floor = gi::bench::medianInterval(t.floor);
      m.wall = gi::bench::medianInterval(t.wall);
      m.effectReps = t.effect;
      m.effectRepsMin = t.effectMin;
      m.effectRepsCpu = t.effectCpu;
      m.batch = first / kInterleaveBatch;
      m.floorReps = t.floor;
      m.out = renderers[i - first]->readTarget(jobs[i].resource);
      m.depth = renderers[i - first]->readTarget(gi::resources::kDepth);
      if (o.excludeEmitters)
        m.emission = renderers[i - first]->readTarget(gi::resources::kEmission);
      renderers[i - first].reset();
      scoreNow(i, m);
      m.out = {};
      m.depth = {};
      m.emission = {};
    }
  }
  return out;
}

// The effect's output against one reference, over pixels that are geometry in both.
struct Scores {
  gi::bench::Metrics metrics;
  Row::AoSplit split;
};

// The compared pixels: geometry in the reference and in the frame, and with --exclude-emitters
// none within one pixel (8-neighbourhood) of a pixel whose G-buffer emission is positive.
std::vector<unsigned char> comparedMask(const Measurement& m, const Reference& reference,
                                        const Options& o) {
  const int w = int(o.width), h = int(o.height);
  const size_t n = size_t(w) * size_t(h);
  std::vector<unsigned char> mask(n);
  for (size_t i = 0; i < n; ++i)
    mask[i] = reference.depth.pixels[i * 4 + 2] > 0.5f && m.depth.pixels[i * 4] > 0.0f;
  if (!o.excludeEmitters || m.emission.pixels.size() != n * 4) return mask;
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const float* e = &m.emission.pixels[(size_t(y) * size_t(w) + size_t(x)) * 4];
      if (!(e[0] > 0.0f || e[1] > 0.0f || e[2] > 0.0f)) continue;
      for (int dy = -1; dy <= 1; ++dy)
        for (int dx = -1; dx <= 1; ++dx) {
          const int u = x + dx, v = y + dy;
          if (u >= 0 && v >= 0 && u < w && v < h) mask[size_t(v) * size_t(w) + size_t(u)] = 0;
        }
    }
  return mask;
}

Scores score(const Measurement& m, const ReferenceSpec& spec, const Reference& reference,
             const Options& o) {
  const size_t n = size_t(o.width) * size_t(o.height);
  const std::vector<unsigned char> mask = comparedMask(m, reference, o);
  const int w = int(o.width), h = int(o.height);
  Scores s;
  if (gi::bench::isAoLike(spec.quantity)) {
    s.metrics = gi::bench::compare(gi::bench::channel(w, h, m.out.pixels, 0),
                                   gi::bench::channel(w, h, reference.value.pixels, 0), mask);
    if (spec.quantity == ref::Quantity::AOSplit && reference.split.pixels.size() == n * 4)
      s.split = splitError(m.out, reference, mask);
  } else {
    const gi::bench::Plane test = gi::bench::channel(w, h, m.out.pixels, -1);
    const gi::bench::Plane truth = gi::bench::channel(w, h, reference.value.pixels, -1);
    s.metrics = gi::bench::compare(test, truth, mask);
    s.metrics.ssim =
        gi::bench::ssim(gi::bench::reinhard(test), gi::bench::reinhard(truth), mask, 1.0);
  }
  return s;
}

// The part of the error against the target that the declared quantity's own distance from it
// explains (metrics.h QuantityGap); nullopt when the effect declares its target.
std::optional<gi::bench::QuantityGap> gapOf(const Measurement& m, const Comparison& cmp,
                                            const Reference& target, const Reference& declared,
                                            const Options& o) {
  if (cmp.declared == cmp.target ||
      gi::bench::isAoLike(cmp.declared.quantity) != gi::bench::isAoLike(cmp.target.quantity))
    return std::nullopt;
  const std::vector<unsigned char> mask = comparedMask(m, target, o);  // as score()
  const int w = int(o.width), h = int(o.height),
            c = gi::bench::isAoLike(cmp.target.quantity) ? 0 : -1;
  return gi::bench::quantityGap(gi::bench::channel(w, h, m.out.pixels, c),
                                gi::bench::channel(w, h, target.value.pixels, c),
                                gi::bench::channel(w, h, declared.value.pixels, c), mask);
}

std::string formatDouble(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%g", v);
  return buf;
}

std::string nowString() {
  const std::time_t t = std::time(nullptr);
  char buf[64];
  std::strftime(buf, sizeof buf, "%Y-%m-%d %H:%M:%S UTC", std::gmtime(&t));
  return buf;
}

// ---- Sweep --------------------------------------------------------------------------------------

struct Setup {
  gi::EffectRegistry registry;
  std::vector<LoadedScene> scenes;
  std::vector<std::unique_ptr<gi::Preset>> presets;  // nullptr entries: "none"
  std::vector<std::string> presetNames;              // as given, 'all' expanded
};

void loadInputs(const Options& o, Setup& s) {
  s.registry.scanDefaultLocations();
  for (const std::string& name : o.scenes) {
    LoadedScene ls{name, gi::loadScene(name), "default"};
    if (name != "default") ls.contents = gi::readInputFile(name, "scene file");
    for (const std::string& w : ls.scene.warnings)
      std::fprintf(stderr, "gi-bench: warning: %s\n", w.c_str());
    s.scenes.push_back(std::move(ls));
  }
  for (const std::string& given : o.presets) {
    if (given != "all") s.presetNames.push_back(given);
    if (given == "all") {
      const std::vector<std::string> all = gi::presetNames();
      if (all.empty())
        usageError("--presets",
                   "'all': no preset found (searched: " + joinList(gi::presetLocations()) + ")");
      s.presetNames.insert(s.presetNames.end(), all.begin(), all.end());
    }
  }
  for (const std::string& p : s.presetNames) {
    if (p == "none") {
      s.presets.emplace_back();
      continue;
    }
    auto preset = std::make_unique<gi::Preset>(gi::loadPreset(p));
    gi::validatePreset(*preset, s.registry);
    s.presets.push_back(std::move(preset));
  }
}

std::vector<std::string> effectItems(const Options& o, const gi::EffectRegistry& registry) {
  std::vector<std::string> items;
  if (o.effects) {
    for (const std::string& item : *o.effects)
      if (item == "all") {
        const std::vector<std::string> names = registry.names();
        items.insert(items.end(), names.begin(), names.end());
      } else {
        items.push_back(item);
      }
  } else
    items = {registry.has("ssao") ? "ssao" : "none"};
  if (items.empty()) items = {"none"};
  for (const std::string& item : items) {
    const std::vector<std::string> set = splitPlus(item);
    for (size_t k = 0; k < set.size(); ++k)
      if (std::find(set.begin(), set.begin() + long(k), set[k]) != set.begin() + long(k))
        usageError("--effects", "'" + set[k] + "' appears twice in '" + item + "'");
  }
  for (const std::string& item : items)
    for (const std::string& e : splitPlus(item))
      if (!registry.has(e))
        usageError("--effects", "unknown effect '" + e + "' (known: " + knownEffects(registry) +
                                    "; plugins are loaded from <bin>/plugins and GI_PLUGIN_PATH)");
  return items;
}

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
        const std::vector<std::string> set = splitPlus(item);
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
          c.effectLabel = item;
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

gi::vk::Context makeContext(const Options& o) {
  gi::vk::ContextOptions opts = gi::vk::ContextOptions::fromEnvironment();
  opts.validation = o.validation;
  if (!o.device.empty()) opts.device = o.device;
  return gi::vk::Context(opts);
}

std::map<ReferenceKey, Reference> computeReferences(const Options& o, const Setup& s,
                                                    const std::vector<ReferenceKey>& keys) {
  std::map<ReferenceKey, Reference> refs;
  ProgressBar bar(o.progress, "references", keys.size());
  for (const ReferenceKey& k : keys) {
    if (refs.count(k)) continue;
    refs[k] = computeReference(o, s.scenes[k.scene], k);
    bar.step(s.scenes[k.scene].name + " " + gi::bench::label(k.spec) +
             (refs[k].cached ? " (cached)" : ""));
  }
  return refs;
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

int runSweep(const Options& o) {
  const auto start = std::chrono::steady_clock::now();
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
  const std::map<ReferenceKey, Reference> refs = computeReferences(o, s, keys);
  gi::vk::Context ctx = makeContext(o);
  std::vector<RenderJob> jobs;
  for (const Config& c : configs)
    jobs.push_back({&s.scenes[c.scene].scene, &c.settings, c.comparison.resource});
  ProgressBar bar(o.progress, "configurations", configs.size());
  std::vector<Scores> vsTargets(configs.size()), vsDeclareds(configs.size());
  std::vector<std::optional<gi::bench::QuantityGap>> gaps(configs.size());
  const std::vector<Measurement> measured =
      measureAll(ctx, s.registry, jobs, o, true, [&](size_t i, const Measurement& m) {
        const Config& c = configs[i];
        vsTargets[i] =
            score(m, c.comparison.target, refs.at(ReferenceKey{c.scene, c.comparison.target}), o);
        vsDeclareds[i] = score(m, c.comparison.declared,
                               refs.at(ReferenceKey{c.scene, c.comparison.declared}), o);
        gaps[i] = gapOf(m, c.comparison, refs.at(ReferenceKey{c.scene, c.comparison.target}),
                        refs.at(ReferenceKey{c.scene, c.comparison.declared}), o);
        bar.step(s.scenes[c.scene].name + " " + c.effectLabel + " " + c.params);
      });
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
  gi::bench::RunInfo info{
      ctx.deviceName(), o.commandLine, nowString(),
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count()};
  gi::bench::writeResults(o.out, rows, info);
  std::printf("%zu configuration(s) in %.1f s -> %s/report.md\n", rows.size(), info.seconds,
              o.out.c_str());
  return 0;
}

// ---- Calibration
// ----------------------------------------------------------------------------------

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
            score(m, it.cmp.target, refs.at(ReferenceKey{0, it.cmp.target}), o);
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

// ---- Hard cases ---------------------------------------------------------------------------------

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
  std::error_code ec;
  fs::create_directories(o.out, ec);
  std::string csv =
      "case,effect,textures,undecoded,values,non_finite,sky_fraction,flicker,seconds,problems\n";
  int failed = 0;
  size_t nonFinite = 0;
  const auto runs =
      gi::bench::runHardCases(ctx, registry, hc, [&](const gi::bench::HardCaseRun& r) {
        std::string problems;
        for (const std::string& p : r.problems) problems += (problems.empty() ? "" : "; ") + p;
        std::printf(
            "%-20s %-12s %2d textures (%d packed) %8zu values, %zu NaN/Inf, flicker %.3g, "
            "%.1f s%s%s\n",
            r.scene.c_str(), r.effect.c_str(), r.textures, r.undecoded, r.values, r.nonFinite,
            r.flicker, r.seconds, problems.empty() ? "" : "  FAIL: ", problems.c_str());
        std::fflush(stdout);
        std::string quoted = problems;
        std::replace(quoted.begin(), quoted.end(), '"', '\'');
        csv += r.scene + "," + r.effect + "," + std::to_string(r.textures) + "," +
               std::to_string(r.undecoded) + "," + std::to_string(r.values) + "," +
               std::to_string(r.nonFinite) + "," + formatDouble(r.skyFraction) + "," +
               formatDouble(r.flicker) + "," + formatDouble(r.seconds) + ",\"" + quoted + "\"\n";
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

}  // namespace

int main(int argc, char** argv) {
  return gi::cli::runMain("gi-bench", [&] {
    const Options o = parseArgs(argc, argv);
    if (o.hardCases) return runHardCaseSweep(o);
    return o.calibrate ? runCalibrate(o) : runSweep(o);
  });
}
