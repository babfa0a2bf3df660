// gi-demo: the interactive demo. A GLFW window showing the renderer's frames with a Dear ImGui
// panel generated from the loaded effects (switches, settings, presets, views, live GPU
// timings and the frame graph), a walking camera, pause/step, screenshots; --script drives
// the same controls for tests and measurements.
#include <cstdio>
#include <string>

#include "app.h"
#include "cli.h"
#include "gi/effect_config.h"

namespace {

const char* kUsage =
    "usage: gi-demo --scene FILE|default [options]\n"
    "  --width W --height H   window size (default 1280x720)\n"
    "  --preset NAME|FILE     quality preset (assets/presets); switchable in the panel\n"
    "  --effects A,B          effects switched on at start, replacing the scene's list\n"
    "  --set OWNER.KEY=V      override a setting (repeatable), as gi-render --set\n"
    "  --view NAME            resource shown at start (output, normal, an effect's name, ...)\n"
    "  --time T               clock at start (seconds); --paused starts it stopped\n"
    "  --floor Y              floor height the camera cannot go below (default: scene's lowest)\n"
    "  --script FILE          run the steps of FILE (see apps/gi-demo/script.h), then exit\n"
    "  --frames N             exit after N frames (without --script)\n"
    "  --out-dir DIR          where the screenshot key writes (default out)\n"
    "  --shader-dir DIR       hot reload reads an effect's shader file from DIR when it has one\n"
    "                         of that name (default: the source tree's file)\n"
    "  --validation           enable Vulkan validation layers (also GI_VALIDATION=1)\n"
    "  --device NAME          pick the Vulkan device by name or index (also GI_DEVICE)\n"
    "keys: WASD walk, Q/E down/up, Shift run, Ctrl creep, right-drag look, P pause, N step,\n"
    "      R accuracy check, F2 screenshot, Tab panel, F1 help, Esc quit\n";

[[noreturn]] void usageError(const std::string& message) {
  throw gi::Error(gi::ErrorKind::Usage, "", message + " (see gi-demo --help)");
}

double number(const std::string& flag, const char* text, double lo, double hi) {
  if (const auto v = gi::cli::numberIn(text, lo, hi)) return *v;
  usageError(flag + " " + gi::cli::rangeMessage(text, lo, hi));
}

demo::AppOptions parseArgs(int argc, char** argv) {
  demo::AppOptions o;
  o.context = gi::vk::ContextOptions::fromEnvironment();
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    auto value = [&]() -> const char* {
      if (i + 1 >= argc) usageError(a + " needs a value");
      return argv[++i];
    };
    if (a == "--help" || a == "-h") {
      std::fputs(kUsage, stdout);
      std::exit(0);
    } else if (a == "--scene")
      o.scene = value();
    else if (a == "--width")
      o.controller.width = uint32_t(number(a, value(), 16, 16384));
    else if (a == "--height")
      o.controller.height = uint32_t(number(a, value(), 16, 16384));
    else if (a == "--preset")
      o.controller.preset = value();
    else if (a == "--effects")
      o.controller.overrides.effects = gi::splitEffectList(value());
    else if (a == "--set")
      o.controller.overrides.sets.push_back(value());
    else if (a == "--view")
      o.controller.view = value();
    else if (a == "--time")
      o.time = number(a, value(), -1e9, 1e9);
    else if (a == "--paused")
      o.paused = true;
    else if (a == "--floor")
      o.floor = float(number(a, value(), -1e6, 1e6));
    else if (a == "--script")
      o.script = value();
    else if (a == "--frames")
      o.frames = int(number(a, value(), 1, 1e9));
    else if (a == "--out-dir")
      o.outDir = value();
    else if (a == "--shader-dir")
      o.shaderDir = value();
    else if (a == "--validation")
      o.context.validation = true;
    else if (a == "--device")
      o.context.device = value();
    else
      usageError("unknown argument '" + a + "'");
  }
  if (o.scene.empty()) usageError("--scene is required");
  return o;
}

}  // namespace

int main(int argc, char** argv) {
  return gi::cli::runMain("gi-demo", [&] {
    demo::App app(parseArgs(argc, argv));
    return app.run();
  });
}
