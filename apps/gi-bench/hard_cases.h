// The hard-case sweep (gi-bench --hard-cases, ctest label `hardcases`): every registered effect
// (and the engine alone, "none") x scenes and cameras that break naive formulas — grazing planes,
// contact occluders, albedo 0 and 1, a closed box, thin slabs, depth discontinuities, extreme
// clip planes, a near-orthographic camera, scene scales 1e-3 and 1e4, sky-only views, degenerate
// skinning, zero-area triangles, zero normals. Each run reads back every texture the frame graph
// used (aliasing off, so each transient holds its own last version) and asserts: no NaN/Inf
// anywhere, documented ranges on the published outputs, and no flicker over a static camera.
// A new effect joins by being registered; a new case is one more entry of hardCases().
#pragma once

#include <functional>
#include <string>
#include <vector>

#include "gi/effect_registry.h"
#include "gi/image_io.h"
#include "gi/scene.h"
#include "gi/vk/context.h"
#include "gi/vk/guard_counters.h"

namespace gi::bench {

struct HardCase {
  std::string name;
  std::string what;  // one line: what makes it hard
  std::function<Scene()> build;
};

// The cases, in a fixed order. Each scene has its own camera; lengths are world lengths and a
// scaled scene carries Scene::lengthScale, so effects' radii scale with it.
std::vector<HardCase> hardCases();

struct HardCaseOptions {
  uint32_t width = 160, height = 120;
  int warmupFrames = 2;  // before the texture check and before the flicker frames
  // Static-camera frames compared pairwise on "lit" and "ao" (0: no flicker check).
  int flickerFrames = 64;
  std::vector<std::string> effects;  // empty: every registered effect and "none"
  std::vector<std::string> cases;    // empty: every case
  // Settings for the effects, "effect.key=value" (as gi-render --set): e.g. the ISM's
  // environment VPLs, which its defaults leave off.
  std::vector<std::string> sets;
  // An equirect HDR map (gi::loadEnvironmentMap) that replaces every case's environment (empty:
  // each case's own): the map paths of effects that read it (SSDO's `environment_sampling`
  // map and mis, the ISM's environment VPLs) on every case.
  std::string environmentMap;
};

// Largest change allowed between two frames of a static camera, relative to max(1, |value|):
// nothing here is temporal, so frames must repeat up to the driver's arithmetic.
inline constexpr double kFlickerTolerance = 1e-4;

struct HardCaseRun {
  std::string scene, effect;
  int textures = 0;   // read back and checked
  int undecoded = 0;  // packed integer formats the engine cannot decode (their consumers are
                      // checked)
  size_t values = 0, nonFinite = 0;
  double skyFraction = 0.0;  // pixels where depth is 0 (what the camera sees of the scene)
  double flicker = -1.0;     // largest relative frame-to-frame change (-1: not measured)
  double seconds = 0.0;
  std::vector<std::string> problems;  // empty: the run passed
  // The shaders' guards that changed a value during the warm-up frames, per pipeline (guard
  // counting is on for the sweep: gi/vk/guard_counters.h). Not a failure: where a formula
  // needed its guard, and how often.
  std::vector<vk::GuardCounters::Count> guards;
};

// "ssdo: ssdo.comp distance 120, lighting.comp non-finite 3" (empty: none fired).
std::string guardSummary(const std::vector<vk::GuardCounters::Count>& guards);

// Checks one image of the named resource: counts non-finite values and appends range problems
// ("ao" in [0, 1], radiance "lit"/"ambient"/"indirect" >= 0, "depth" in [0, 1]).
void checkTexture(const std::string& name, const ImageRGBA32F& image, HardCaseRun& run);

// Runs the sweep; `progress` (may be empty) sees each run when it ends. Throws gi::Error for an
// unknown effect or case name.
std::vector<HardCaseRun> runHardCases(vk::Context& ctx, const EffectRegistry& registry,
                                      const HardCaseOptions& options,
                                      const std::function<void(const HardCaseRun&)>& progress = {});

}  // namespace gi::bench
