// gi-demo's frame loop: input (keys and mouse, or a script) -> camera and clock -> the
// renderer's frame -> the panel -> the window. The keys, the panel and the script all act
// through the Controller and the same few methods here.
#pragma once

#include <array>
#include <chrono>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "accuracy.h"
#include "controller.h"
#include "free_camera.h"
#include "gi/dynamic_resolution.h"
#include "gi/vk/resources.h"
#include "input_queue.h"
#include "module_watcher.h"
#include "panel.h"
#include "presenter.h"
#include "script.h"
#include "shader_watcher.h"
#include "window.h"

namespace demo {

struct AppOptions {
  std::string scene, script, outDir = "out";
  ControllerOptions controller;
  gi::vk::ContextOptions context;
  int frames = 0;  // 0: until closed (or the script ends)
  double time = 0.0;
  bool paused = false;
  std::optional<float> floor;  // default: the lowest point of the scene
  std::string shaderDir;       // hot reload reads a shader file of this name from here if present
  // Each frame lasts at least this long (the rest is slept): a slow device's frame rate, to try
  // the controls at it (the input queue keeps quick taps and clicks).
  int minFrameMs = 0;
  // Dynamic resolution: the render scale keeps the displayed frame within this many ms (0: off;
  // the panel changes it).
  double frameBudgetMs = 0.0;
  // Prints where the panel's Pause button is each frame it moved ("widget pause: x y w h"),
  // and the clock's pause and play: what a test that clicks in the window needs.
  bool printWidgets = false;
};

class App {
 public:
  explicit App(const AppOptions& options);
  ~App();
  // Runs until the window closes, --frames are done or the script ends; the exit code.
  int run();

 private:
  struct ImguiContext;
  void frame();
  bool advanceScript();  // false once the script has ended
  void execute(const ScriptStep& step);
  CameraInput readInput();
  void togglePause();  // the clock (P, the panel's button), said with --print-widgets
  void handleKeys();
  void screenshot(const std::string& path);
  void resizeWindow(int width, int height);
  void printTimings();
  void startAccuracy(const std::string& effect, uint32_t spp);
  void reloadShaders(bool report);
  // `settled`: only modules whose file stopped changing (the window's polling); a script's
  // `reload` takes every changed one at once.
  void reloadPlugins(bool settled);

  AppOptions options_;
  gi::Scene scene_;
  gi::EffectRegistry registry_;
  std::unique_ptr<AppWindow> window_;
  std::unique_ptr<gi::vk::Context> ctx_;
  std::unique_ptr<Controller> controller_;
  std::unique_ptr<ImguiContext> imgui_;
  std::unique_ptr<Presenter> presenter_;
  std::unique_ptr<FreeCamera> camera_;
  AccuracyCheck accuracy_;
  std::unique_ptr<ShaderWatcher> watcher_;
  std::unique_ptr<ModuleWatcher> modules_;
  std::chrono::steady_clock::time_point lastWatch_;
  gi::vk::Image preview_;  // the viewed resource when it is not the output
  FrameStats stats_;
  DemoState state_;
  std::vector<double> timingFrames_, timingGpu_, timingUiCpu_, timingUiGpu_;
  std::vector<ScriptStep> script_;
  size_t scriptNext_ = 0;
  int framesLeft_ = 0, screenshots_ = 0;
  CameraInput held_;
  float lookX_ = 0, lookY_ = 0;
  bool cameraMoved_ = false;
  double lastX_ = 0, lastY_ = 0;
  std::unique_ptr<InputQueue> input_;
  gi::DynamicResolution resolution_{{}};
  std::array<float, 4> pauseButtonPrinted_{};
  std::chrono::steady_clock::time_point last_;
};

}  // namespace demo
