// gi-render: command-line renderer. Renders a scene (JSON scene, model file or the built-in
// default) and writes the image, or shows it in a window (--window); --timings prints the
// median GPU time of each pass.
#include <sys/resource.h>

#include <algorithm>
#include <chrono>
#include <climits>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "cli.h"
#include "gi/effect_config.h"
#include "gi/engine_settings.h"
#include "gi/errors.h"
#include "gi/image_io.h"
#include "gi/renderer.h"
#include "gi/scene_io.h"
#include "gi/vk/context.h"
#include "gi/vk/swapchain.h"
#include "median.h"
#include "preview.h"
#include "window.h"

namespace {

const char* kUsage =
    "usage: gi-render --scene FILE|default --out IMAGE.png|IMAGE.pfm [options]\n"
    "       gi-render --scene FILE|default --window [--out IMAGE] [options]\n"
    "  --window               show the frames in a window (until closed, or --frames N)\n"
    "  --width W --height H   image (and window) size (default 640x480)\n"
    "  --frames N             frames to render; timings are medians over them\n"
    "                         (default 1; with --window: until the window is closed)\n"
    "  --time T               animation clock in seconds (default 0)\n"
    "  --time-step S          advance the clock by S seconds per frame (default 0)\n"
    "  --timings              print the median GPU time of each pass and peak memory\n"
    "  --isolate-passes       submit and wait after each pass (exact per-pass timings on\n"
    "                         drivers that overlap passes, e.g. lavapipe)\n"
    "  --view NAME            write a raw resource instead of the final image: output, lit,\n"
    "                         depth, normal, albedo, material, emission, motion, floor, or an\n"
    "                         effect's name for its debug view (e.g. ssao)\n"
    "  --effects A,B          effects to run, replacing the scene's list ('none': no effect)\n"
    "  --preset NAME|FILE     quality preset (assets/presets): settings for the effects\n"
    "  --set EFFECT.KEY=V     override one setting (after preset and scene; repeatable);\n"
    "                         engine.KEY=V sets the engine's own (see --list-effects)\n"
    "  --list-effects         list the effect plugins found, with their settings, and the\n"
    "                         engine's settings, and exit\n"
    "  --print-graph          print the compiled frame graph (executed and culled passes)\n"
    "  --graph-dot FILE       write the frame graph as Graphviz dot\n"
    "  --exposure E           exposure before tonemapping (= --set engine.exposure=E)\n"
    "  --surface-points N     keep N area-uniform surface points (view them: --view points;\n"
    "                         = --set engine.surface_points=N)\n"
    "  --validation           enable Vulkan validation layers (also GI_VALIDATION=1)\n"
    "  --device NAME          pick the Vulkan device by name or index (also GI_DEVICE)\n";

struct Options {
  gi::cli::CommonFlags common;  // --scene, --width, --height, --preset, --effects, --set, ...
  std::string out, graphDot;
  bool listEffects = false, printGraph = false;
  int frames = 0;  // 0: not given (one frame, or until the window closes)
  double time = 0.0, timeStep = 0.0;
  bool timings = false, window = false, isolatePasses = false;
};

Options parseArgs(int argc, char** argv) {
  Options o;
  o.common.validation = gi::vk::ContextOptions::fromEnvironment().validation;
  for (gi::cli::Args a("gi-render", argc, argv, kUsage); a.next();) {
    if (gi::cli::parseCommonFlag(a, o.common)) continue;
    if (a.is("--out"))
      o.out = a.value();
    else if (a.is("--frames"))
      o.frames = int(a.integer(1, 100000));
    else if (a.is("--time"))
      o.time = a.number(-1e9, 1e9);
    else if (a.is("--time-step"))
      o.timeStep = a.number(-1e6, 1e6);
    else if (a.is("--exposure") || a.is("--surface-points")) {
      // Shorthands for --set engine.*: same place in the order, same validation.
      const bool exposure = a.is("--exposure");
      const std::string text = gi::cli::formatNumber(
          exposure ? a.number(0, 1e6) : double(a.integer(0, int64_t(1) << 24)));
      o.common.request.overrides.sets.push_back(
          std::string("engine.") + (exposure ? "exposure=" : "surface_points=") + text);
    } else if (a.is("--timings"))
      o.timings = true;
    else if (a.is("--isolate-passes"))
      o.isolatePasses = true;
    else if (a.is("--window"))
      o.window = true;
    else if (a.is("--list-effects"))
      o.listEffects = true;
    else if (a.is("--print-graph"))
      o.printGraph = true;
    else if (a.is("--graph-dot"))
      o.graphDot = a.value();
    else
      a.unknown();
  }
  if (o.listEffects) return o;
  if (o.common.scene.empty()) gi::cli::usageError("gi-render", "", "--scene is required");
  if (o.out.empty() && !o.window)
    gi::cli::usageError("gi-render", "", "--out is required (or --window)");
  return o;
}

void writeImage(const std::string& path, const std::string& view, gi::Renderer& renderer) {
  const bool output = view == gi::resources::kOutput;
  if (std::filesystem::path(path).extension() == ".pfm")
    gi::writePfm(path, output ? renderer.readTarget(gi::resources::kLit)
                              : gi::app::definedChannels(renderer.readTarget(view), view));
  else if (output)
    gi::writePng(path, renderer.readOutput());
  else
    gi::writePng(path, gi::app::previewOf(renderer.readTarget(view), view));
}

int listEffects() {
  gi::EffectRegistry registry;
  registry.scanDefaultLocations();
  std::printf("%s", registry.describe().c_str());
  std::printf("%s - the engine's own settings (presets, scenes and --set, as an effect's)\n%s",
              gi::kEngineSettingsOwner,
              gi::describeSettings(gi::kEngineSettingsOwner, gi::engineSettingDescs()).c_str());
  return 0;
}

int run(const Options& o) {
  if (o.listEffects) return listEffects();
  const std::string ext = std::filesystem::path(o.out).extension().string();
  if (!o.out.empty() && ext != ".png" && ext != ".pfm")
    throw gi::Error(gi::ErrorKind::Usage, o.out, "output must end in .png or .pfm");
  // Outputs are checked before any work: a long render never ends in "cannot write".
  if (!o.out.empty()) gi::cli::checkOutputWritable(o.out);
  if (!o.graphDot.empty()) gi::cli::checkOutputWritable(o.graphDot);
  // Load and validate everything (scene, effects, preset, settings) before any Vulkan work,
  // so bad input fails fast.
  gi::Scene scene = gi::loadScene(o.common.scene);
  for (const std::string& w : scene.warnings)
    std::fprintf(stderr, "gi-render: warning: %s\n", w.c_str());
  gi::EffectRegistry registry;
  const auto scanStart = std::chrono::steady_clock::now();
  registry.scanDefaultLocations();
  const double pluginLoadMs =
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - scanStart)
          .count();
  gi::RenderSettings base;
  base.width = o.common.width;
  base.height = o.common.height;
  base.floorPass = o.timings;
  base.isolatePasses = o.isolatePasses;
  gi::RenderSettings settings = gi::configureRender(scene, registry, o.common.request, base);
  const std::string& view = settings.view;
  // A .pfm of the output view holds the HDR lit image (writeImage).
  if (view == gi::resources::kOutput) settings.keepForReadback = {gi::resources::kLit};

  gi::vk::ContextOptions ctxOptions = gi::vk::ContextOptions::fromEnvironment();
  ctxOptions.validation = o.common.validation;
  if (!o.common.device.empty()) ctxOptions.device = o.common.device;
  std::optional<AppWindow> window;  // outlives the context and the swapchain's surface
  if (o.window) {
    window.emplace(o.common.width, o.common.height, "gi-render: " + o.common.scene);
    ctxOptions.instanceExtensions = AppWindow::instanceExtensions();
    ctxOptions.swapchain = true;
  }
  gi::vk::Context ctx(ctxOptions);

  gi::Renderer renderer(ctx, scene, settings, &registry);
  for (const std::string& w : renderer.warnings())
    std::fprintf(stderr, "gi-render: warning: %s\n", w.c_str());
  if (o.printGraph) std::printf("%s", renderer.graphDescription().c_str());
  if (!o.graphDot.empty()) gi::cli::writeFileAtomic(o.graphDot, renderer.graphDot());
  std::optional<gi::vk::Swapchain> swapchain;
  if (window) swapchain.emplace(ctx, window->handle());

  std::map<std::string, std::vector<double>> samples, cpuSamples;
  const int frames = o.frames > 0 ? o.frames : window ? INT_MAX : 1;
  int rendered = 0;
  for (; rendered < frames && !(window && window->closed()); ++rendered) {
    renderer.setTime(o.time + rendered * o.timeStep);
    renderer.renderFrame();
    for (const auto& t : renderer.lastTimings()) {
      samples[t.name].push_back(t.ms);
      if (t.cpuMs >= 0.0) cpuSamples[t.name].push_back(t.cpuMs);
    }
    if (swapchain) swapchain->present(renderer.outputImage(), renderer.outputExtent());
  }
  if (rendered == 0) std::printf("window closed before the first frame\n");
  if (rendered > 0 && !o.out.empty()) writeImage(o.out, view, renderer);

  if (o.timings && rendered > 0) {
    std::printf("scene %s, %ux%u, %zu triangles, %d frame(s), device %s\n", o.common.scene.c_str(),
                o.common.width, o.common.height, scene.triangleCount(), rendered,
                ctx.deviceName().c_str());
    // With --isolate-passes also each pass's process CPU time (tight on a loaded machine).
    const bool cpu = !cpuSamples.empty();
    std::printf("%-12s %12s%s\n", "pass", "median ms", cpu ? "       cpu ms" : "");
    double total = 0, cpuTotal = 0;
    for (const std::string& name : renderer.passNames()) {
      const double median = gi::cli::median(samples[name]);
      total += median;
      std::printf("%-12s %12.3f", name.c_str(), median);
      if (cpu) {
        const double c = gi::cli::median(cpuSamples[name]);
        cpuTotal += c;
        std::printf(" %12.3f", c);
      }
      std::printf("\n");
    }
    std::printf("%-12s %12.3f", "total", total);
    if (cpu) std::printf(" %12.3f", cpuTotal);
    std::printf("\n");
    std::string culled;
    for (const std::string& c : renderer.culledPassNames()) culled += " " + c;
    std::printf("culled passes:%s\n", culled.empty() ? " none" : culled.c_str());
    if (renderer.lastSkinnedVertexCount() > 0)
      std::printf("skinning: %u vertices deformed in the last frame\n",
                  renderer.lastSkinnedVertexCount());
    const std::vector<std::string> passes = renderer.passNames();
    if (!renderer.surfacePoints().points.empty())
      std::printf("surface points: %zu%s\n", renderer.surfacePoints().points.size(),
                  std::find(passes.begin(), passes.end(), "surface_points") == passes.end()
                      ? " (pass culled: nothing reads them; --view points shows them)"
                      : "");
    const gi::Renderer::DrawCounts draws = renderer.lastFrameDraws();
    std::printf(
        "instance draws (last frame, all views): %llu drawn, %llu culled by the views' "
        "frusta; shadow maps: %u drawn whole, %u from their static cache\n",
        static_cast<unsigned long long>(draws.drawn), static_cast<unsigned long long>(draws.culled),
        draws.shadowMapsDrawn, draws.shadowMapsCached);
    std::printf("frame graph compile %.3f ms (CPU), plugin loading %.3f ms (%zu effect(s))\n",
                renderer.lastCompileMs(), pluginLoadMs, registry.names().size());
    rusage usage{};
    getrusage(RUSAGE_SELF, &usage);
    std::printf("peak memory %.1f MiB\n", usage.ru_maxrss / 1024.0);
  }
  if (ctx.validationErrors() > 0) {
    std::fprintf(stderr, "gi-render: error: %u Vulkan validation error(s)\n",
                 ctx.validationErrors());
    return 3;
  }
  if (rendered > 0 && !o.out.empty()) std::printf("wrote %s\n", o.out.c_str());
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  return gi::cli::runMain("gi-render", [&] { return run(parseArgs(argc, argv)); });
}
