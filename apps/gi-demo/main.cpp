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
    "  --min-frame-ms N       each frame lasts at least N ms (a slow device's rate, to try the\n"
    "                         controls at it)\n"
    "  --frame-budget-ms MS   dynamic resolution: scale the render so a frame takes at most MS\n"
    "                         (0: off, the default; the panel's \"frame budget\" changes it)\n"
    "  --print-widgets        print where the Pause button is and when the clock pauses/plays\n"
    "                         of that name (default: the source tree's file)\n"
    "  --validation           enable Vulkan validation layers (also GI_VALIDATION=1)\n"
    "  --device NAME          pick the Vulkan device by name or index (also GI_DEVICE)\n"
    "keys: WASD walk, Q/E down/up, Shift run, Ctrl creep, right-drag look, P pause, N step,\n"
    "      R accuracy check, F2 screenshot, Tab panel, F1 help, Esc quit\n";

demo::AppOptions parseArgs(int argc, char** argv) {
  demo::AppOptions o;
  o.context = gi::vk::ContextOptions::fromEnvironment();
  gi::cli::CommonFlags common;
  common.width = 1280;
  common.height = 720;
  common.minSize = 16;
  common.validation = o.context.validation;
  for (gi::cli::Args a("gi-demo", argc, argv, kUsage); a.next();) {
    if (gi::cli::parseCommonFlag(a, common)) continue;
    if (a.is("--time"))
      o.time = a.number(-1e9, 1e9);
    else if (a.is("--paused"))
      o.paused = true;
    else if (a.is("--floor"))
      o.floor = float(a.number(-1e6, 1e6));
    else if (a.is("--script"))
      o.script = a.value();
    else if (a.is("--frames"))
      o.frames = int(a.integer(1, 1000000000));
    else if (a.is("--out-dir"))
      o.outDir = a.value();
    else if (a.is("--shader-dir"))
      o.shaderDir = a.value();
    else if (a.is("--min-frame-ms"))
      o.minFrameMs = int(a.integer(0, 60000));
    else if (a.is("--frame-budget-ms"))
      o.frameBudgetMs = a.number(0, 10000);
    else if (a.is("--print-widgets"))
      o.printWidgets = true;
    else
      a.unknown();
  }
  if (common.scene.empty()) gi::cli::usageError("gi-demo", "", "--scene is required");
  o.scene = common.scene;
  o.controller = {common.request, common.width, common.height};
  o.context.validation = common.validation;
  if (!common.device.empty()) o.context.device = common.device;
  return o;
}

}  // namespace

int main(int argc, char** argv) {
  return gi::cli::runMain("gi-demo", [&] {
    demo::App app(parseArgs(argc, argv));
    return app.run();
  });
}
