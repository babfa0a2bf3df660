// The Dear ImGui panel of gi-demo, generated from the effect registry: each effect's switch
// and its declared settings as widgets (range, step, log scale, help as a tooltip), the
// engine's settings the same way, presets, the view, live GPU timings and the executed and
// culled passes. No effect is named here. Every change goes through the Controller.
#pragma once

#include <array>
#include <deque>
#include <string>
#include <vector>

#include "accuracy.h"
#include "controller.h"
#include "free_camera.h"

namespace demo {

struct FrameStats {
  std::deque<float> frameMs;           // wall time of recent frames (the graph)
  std::vector<gi::PassTiming> passes;  // GPU time of each pass, last frame
  double uiCpuMs = 0.0;                // building the panel + recording its draw lists, last frame
  double uiGpuMs = -1.0;               // the ImGui render pass, last finished frame
  uint64_t deviceBytes = 0;
};

struct DemoState {
  bool paused = false, stepOnce = false, screenshot = false;
  bool help = false, panel = true;
  double time = 0.0;
  std::string message;          // last screenshot path or similar
  std::string accuracyRequest;  // an effect whose accuracy check the user asked for
  int accuracySpp = 64;
  bool showError = false;      // show the last accuracy check's error image
  bool togglePause = false;    // the panel's Pause/Play button was pressed
  float frameBudgetMs = 0.0f;  // dynamic resolution\'s budget (0: off), and its current scale
  double renderScale = 1.0;
  std::array<float, 4> pauseButton{};  // where it is: x, y, width, height (window pixels)
};

void drawPanel(Controller& controller, const FrameStats& stats, DemoState& state,
               FreeCamera& camera, const AccuracyCheck& accuracy);
void drawHelp(DemoState& state);

// One setting as a widget; true when the user changed it (then it is sent to the controller).
bool settingWidget(Controller& controller, const std::string& owner, const gi::SettingDesc& desc);

}  // namespace demo
