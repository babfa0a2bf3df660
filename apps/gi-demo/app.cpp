#include "app.h"

#include <GLFW/glfw3.h>
#include <imgui.h>
#include <imgui_impl_glfw.h>
#include <imgui_impl_vulkan.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <sstream>
#include <thread>

#include "gi/errors.h"
#include "gi/image_io.h"
#include "gi/scene_io.h"
#include "median.h"

namespace demo {

namespace {

constexpr double kScriptStep = 1.0 / 30.0;  // seconds per scripted frame: reproducible runs

double ms(std::chrono::steady_clock::duration d) {
  return std::chrono::duration<double, std::milli>(d).count();
}

using gi::cli::median;

}  // namespace

// Dear ImGui's context and GLFW backend (before the Vulkan backend, gone after it).
struct App::ImguiContext {
  explicit ImguiContext(GLFWwindow* window) {
    IMGUI_CHECKVERSION();
    ImGui::CreateContext();
    ImGui::GetIO().IniFilename = nullptr;  // no imgui.ini left in the working directory
    ImGui::StyleColorsDark();
    ImGui_ImplGlfw_InitForVulkan(window, false);  // InputQueue takes the window's input
  }
  ~ImguiContext() {
    ImGui_ImplGlfw_Shutdown();
    ImGui::DestroyContext();
  }
};

App::App(const AppOptions& o) : options_(o) {
  // Everything that can be wrong with the input fails before a window opens.
  scene_ = gi::loadScene(o.scene);
  for (const std::string& w : scene_.warnings)
    std::fprintf(stderr, "gi-demo: warning: %s\n", w.c_str());
  registry_.scanDefaultLocations();
  // The loaded modules registered their shaders: their texts now are the baseline.
  watcher_ = std::make_unique<ShaderWatcher>(o.shaderDir);
  modules_ = std::make_unique<ModuleWatcher>(registry_.modulePaths());
  if (!o.script.empty()) script_ = loadScript(o.script);

  window_ =
      std::make_unique<AppWindow>(o.controller.width, o.controller.height, "gi-demo: " + o.scene);
  gi::vk::ContextOptions ctxOptions = o.context;
  ctxOptions.instanceExtensions = AppWindow::instanceExtensions();
  ctxOptions.swapchain = true;
  ctx_ = std::make_unique<gi::vk::Context>(ctxOptions);
  // The renderer draws at the window's framebuffer size (HiDPI may differ from the request).
  ControllerOptions co = o.controller;
  int w = 0, h = 0;
  glfwGetFramebufferSize(window_->handle(), &w, &h);
  if (w > 0 && h > 0) co.width = uint32_t(w), co.height = uint32_t(h);
  controller_ = std::make_unique<Controller>(*ctx_, scene_, registry_, co);
  imgui_ = std::make_unique<ImguiContext>(window_->handle());
  input_ = std::make_unique<InputQueue>(window_->handle());
  presenter_ = std::make_unique<Presenter>(*ctx_, window_->handle());

  glm::vec3 lo, hi;
  scene_.worldBounds(lo, hi);
  camera_ = std::make_unique<FreeCamera>(controller_->renderer().camera(), o.floor.value_or(lo.y));
  state_.time = o.time;
  state_.paused = o.paused;
  state_.frameBudgetMs = float(o.frameBudgetMs);
  lastX_ = input_->cursorX(), lastY_ = input_->cursorY();
  last_ = lastWatch_ = std::chrono::steady_clock::now();
}

App::~App() {
  gi::vk::clearShaderOverrides();
  input_.reset();
  presenter_.reset();  // the Vulkan backend before ImGui's context
  imgui_.reset();
  preview_.reset();
  controller_.reset();
}

int App::run() {
  int rendered = 0;
  while (!window_->closed()) {
    if (!script_.empty()) {
      if (!advanceScript()) break;
    } else if (options_.frames > 0 && rendered >= options_.frames) {
      break;
    }
    frame();
    ++rendered;
  }
  ctx_->savePipelineCache();
  if (ctx_->validationErrors() > 0) {
    std::fprintf(stderr, "gi-demo: error: %u Vulkan validation error(s)\n",
                 ctx_->validationErrors());
    return 3;
  }
  return 0;
}

CameraInput App::readInput() {
  CameraInput in;
  const ImGuiIO& io = ImGui::GetIO();
  const double x = input_->cursorX(), y = input_->cursorY();
  if (!io.WantCaptureMouse && input_->buttonDown(GLFW_MOUSE_BUTTON_RIGHT)) {
    in.lookX = float(x - lastX_);
    in.lookY = float(y - lastY_);
  }
  lastX_ = x, lastY_ = y;
  if (io.WantCaptureKeyboard) return in;
  auto down = [&](int key) { return input_->keyDown(key) ? 1.0f : 0.0f; };
  in.forward = down(GLFW_KEY_W) - down(GLFW_KEY_S);
  in.right = down(GLFW_KEY_D) - down(GLFW_KEY_A);
  in.up = down(GLFW_KEY_E) - down(GLFW_KEY_Q);
  in.fast = down(GLFW_KEY_LEFT_SHIFT) + down(GLFW_KEY_RIGHT_SHIFT) > 0;
  in.slow = down(GLFW_KEY_LEFT_CONTROL) + down(GLFW_KEY_RIGHT_CONTROL) > 0;
  return in;
}

// One-shot keys (ImGui 1.86 indexes keys by the GLFW key code).
void App::handleKeys() {
  if (ImGui::GetIO().WantCaptureKeyboard) return;
  if (ImGui::IsKeyPressed(GLFW_KEY_P, false)) togglePause();
  if (ImGui::IsKeyPressed(GLFW_KEY_N)) state_.stepOnce = true;
  if (ImGui::IsKeyPressed(GLFW_KEY_F2, false)) state_.screenshot = true;
  if (ImGui::IsKeyPressed(GLFW_KEY_R, false))
    for (const std::string& e : controller_->effects())
      if (controller_->enabled(e)) {
        state_.accuracyRequest = e;
        break;
      }
  if (ImGui::IsKeyPressed(GLFW_KEY_F1, false)) state_.help = !state_.help;
  if (ImGui::IsKeyPressed(GLFW_KEY_TAB, false)) state_.panel = !state_.panel;
  if (ImGui::IsKeyPressed(GLFW_KEY_ESCAPE, false))
    glfwSetWindowShouldClose(window_->handle(), GLFW_TRUE);
}

void App::togglePause() {
  state_.paused = !state_.paused;
  if (options_.printWidgets) {
    std::printf("clock %s at t = %.3f s\n", state_.paused ? "paused" : "playing", state_.time);
    std::fflush(stdout);
  }
}

void App::frame() {
  const auto start = std::chrono::steady_clock::now();
  // Real time: the clock and the camera advance by the wall time since the last frame, however
  // slow the frames are (a stall of over a second, e.g. a shader rebuilt, counts as one second).
  const double wallDt = std::min(std::chrono::duration<double>(start - last_).count(), 1.0);
  last_ = start;
  const double dt = script_.empty() ? wallDt : kScriptStep;
  // This frame's input: the queued events up to the second change of any key or button.
  if (script_.empty()) input_->apply(ImGui::GetIO());
  // Hot reload: the window checks the shaders and the plugin modules twice a second (a script
  // only on `reload`).
  if (script_.empty() && start - lastWatch_ > std::chrono::milliseconds(500)) {
    lastWatch_ = start;
    reloadPlugins(true);
    reloadShaders(false);
  }
  gi::Renderer& renderer = controller_->renderer();

  // The renderer follows the window's size, times the dynamic resolution's scale (the
  // swapchain's blit stretches the image to the window).
  if (resolution_.options().budgetMs != double(state_.frameBudgetMs)) {
    gi::DynamicResolution::Options o = resolution_.options();
    o.budgetMs = state_.frameBudgetMs;
    resolution_.setOptions(o);
  }
  state_.renderScale = resolution_.scale();
  int w = 0, h = 0;
  glfwGetFramebufferSize(window_->handle(), &w, &h);
  const VkExtent2D size = renderer.outputExtent();
  const uint32_t rw = std::max(16u, uint32_t(std::lround(w * state_.renderScale)));
  const uint32_t rh = std::max(16u, uint32_t(std::lround(h * state_.renderScale)));
  if (w > 0 && h > 0 && (rw != size.width || rh != size.height)) controller_->resize(rw, rh);

  CameraInput input = script_.empty() ? readInput() : held_;
  input.lookX += lookX_;
  input.lookY += lookY_;
  lookX_ = lookY_ = 0;
  // The scene's own camera until the user moves: an untouched view equals gi-render's.
  if (camera_->update(input, float(dt)) || cameraMoved_) {
    renderer.setCameraOverride(camera_->view());
    cameraMoved_ = false;
  }
  if (!state_.paused || state_.stepOnce) state_.time += dt;
  state_.stepOnce = false;
  renderer.setTime(state_.time);
  try {
    renderer.renderFrame();
  } catch (const gi::EffectError& e) {
    // A plugin that fails while the frame renders is turned off (the panel says why) and the
    // frame is drawn without it; the demo goes on.
    if (!controller_->turnOffFailed(e)) throw;
    std::fprintf(stderr, "gi-demo: %s\n", controller_->lastError().c_str());
    renderer.renderFrame();
  }
  stats_.passes = renderer.lastTimings();
  stats_.deviceBytes = ctx_->allocator().bytesInUse();

  const auto uiStart = std::chrono::steady_clock::now();
  ImGui_ImplVulkan_NewFrame();
  ImGui_ImplGlfw_NewFrame();
  if (script_.empty()) input_->writeTo(ImGui::GetIO());  // over the backend's device state
  ImGui::NewFrame();
  if (script_.empty()) handleKeys();
  drawPanel(*controller_, stats_, state_, *camera_, accuracy_);
  drawHelp(state_);
  if (state_.togglePause) togglePause();
  state_.togglePause = false;
  if (options_.printWidgets && state_.panel && state_.pauseButton != pauseButtonPrinted_) {
    const auto& b = pauseButtonPrinted_ = state_.pauseButton;
    std::printf("widget pause: %.0f %.0f %.0f %.0f\n", b[0], b[1], b[2], b[3]);
    std::fflush(stdout);
  }
  ImGui::Render();
  stats_.uiCpuMs = ms(std::chrono::steady_clock::now() - uiStart);

  // An accuracy check compares with the frame just rendered (same clock and camera).
  if (!state_.accuracyRequest.empty()) {
    startAccuracy(state_.accuracyRequest, uint32_t(state_.accuracySpp));
    state_.accuracyRequest.clear();
  }
  accuracy_.poll();
  if (state_.screenshot) {
    std::ostringstream name;
    name << options_.outDir << "/gi-demo-" << ++screenshots_ << ".png";
    screenshot(name.str());
    state_.screenshot = false;
  }
  // The panel may have changed the view or the effects: show what the renderer holds now.
  // A resource that cannot be previewed sends the view back to the output, with the reason.
  std::optional<gi::ImageRGBA8> image;
  if (state_.showError && accuracy_.result()) {
    image = accuracy_.result()->error;
  } else if (controller_->view() != gi::resources::kOutput) {
    try {
      image = controller_->image();
    } catch (const std::exception& e) {
      state_.message = "cannot show '" + controller_->view() + "': " + e.what();
      if (!script_.empty()) std::fprintf(stderr, "gi-demo: %s\n", state_.message.c_str());
      controller_->setView(gi::resources::kOutput);
    }
  }
  if (!image) {
    if (preview_) {  // back from another view: its image goes (memory back to where it was)
      vkDeviceWaitIdle(ctx_->device());
      preview_.reset();
    }
    presenter_->present(renderer.outputImage(), renderer.outputExtent(), VK_IMAGE_LAYOUT_GENERAL,
                        ImGui::GetDrawData());
  } else {
    if (!preview_ || preview_.desc().width != uint32_t(image->width) ||
        preview_.desc().height != uint32_t(image->height)) {
      gi::vk::ImageDesc d;
      d.width = uint32_t(image->width);
      d.height = uint32_t(image->height);
      d.usage = VK_IMAGE_USAGE_SAMPLED_BIT | VK_IMAGE_USAGE_TRANSFER_DST_BIT |
                VK_IMAGE_USAGE_TRANSFER_SRC_BIT;
      vkDeviceWaitIdle(ctx_->device());  // the previous preview may still be read
      preview_ = gi::vk::Image(*ctx_, d);
    }
    vkDeviceWaitIdle(ctx_->device());
    gi::vk::uploadImage(*ctx_, preview_, image->pixels.data(), image->pixels.size());
    presenter_->present(preview_.handle(), {uint32_t(image->width), uint32_t(image->height)},
                        VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL, ImGui::GetDrawData());
  }
  stats_.uiGpuMs = presenter_->uiGpuMs();
  stats_.uiCpuMs += presenter_->uiRecordMs();

  const double frameMs = ms(std::chrono::steady_clock::now() - start);
  stats_.frameMs.push_back(float(frameMs));
  if (stats_.frameMs.size() > 300) stats_.frameMs.pop_front();
  double gpu = 0.0;
  for (const auto& p : stats_.passes) gpu += p.ms;
  timingFrames_.push_back(frameMs);
  timingGpu_.push_back(gpu);
  timingUiCpu_.push_back(stats_.uiCpuMs);
  timingUiGpu_.push_back(std::max(stats_.uiGpuMs, 0.0));
  if (options_.minFrameMs > 0)
    std::this_thread::sleep_until(start + std::chrono::milliseconds(options_.minFrameMs));
  // The displayed frame's time picks the next frames' render scale.
  resolution_.update(ms(std::chrono::steady_clock::now() - start));
}

void App::screenshot(const std::string& path) {
  const std::filesystem::path p(path);
  if (p.has_parent_path()) std::filesystem::create_directories(p.parent_path());
  gi::writePng(path, controller_->image());
  state_.message = "wrote " + path;
  std::printf("wrote %s\n", path.c_str());
  std::fflush(stdout);
}

void App::resizeWindow(int width, int height) {
  glfwSetWindowSize(window_->handle(), width, height);
  // The window system answers asynchronously: wait (bounded) for the new framebuffer size.
  for (int i = 0; i < 200; ++i) {
    glfwWaitEventsTimeout(0.01);
    int w = 0, h = 0;
    glfwGetFramebufferSize(window_->handle(), &w, &h);
    if (w == width && h == height) return;
  }
  throw gi::Error(
      gi::ErrorKind::Unsupported, options_.script,
      "the window did not take the size " + std::to_string(width) + "x" + std::to_string(height));
}

void App::startAccuracy(const std::string& effect, uint32_t spp) {
  try {
    // The frame holds one image per resource: with two writers of the same output, the
    // comparison would not be of this effect's.
    for (const std::string& other : controller_->effects()) {
      if (other == effect || !controller_->enabled(other)) continue;
      for (const std::string& w : registry_.info(other).writes)
        for (const std::string& mine : registry_.info(effect).writes)
          if (w == mine) {
            std::string why = other;
            why += " also writes '" + w + "': switch it off to check ";
            why += effect;
            throw gi::Error(gi::ErrorKind::Usage, "", why);
          }
    }
    accuracy_.start(*ctx_, controller_->renderer(), scene_, state_.time, registry_, effect,
                    controller_->settings(effect), spp);
    state_.message = "accuracy check of " + effect + " started";
  } catch (const std::exception& e) {
    state_.message = std::string("accuracy: ") + e.what();
  }
}

void App::reloadShaders(bool report) {
  const ShaderWatcher::Result r = watcher_->poll();
  std::string line;
  if (!r.error.empty()) {
    // The last good pipelines keep running; the panel shows the compiler's message.
    state_.message = "shader reload failed (the previous shaders keep running):\n" + r.error;
    line = "reload: error: " + r.error;
  } else if (r.rebuilt.empty()) {
    line = "reload: no change";
  } else if (controller_->reloadEffects()) {
    state_.message = "reloaded " + std::to_string(r.rebuilt.size()) + " shader(s)";
    line = "reload: " + std::to_string(r.rebuilt.size()) + " shader(s) rebuilt";
  } else {
    // Compiled but refused by the pipeline: back to the built-in shaders.
    const std::string why = controller_->lastError();
    gi::vk::clearShaderOverrides();
    controller_->reloadEffects();
    state_.message = "shader reload failed, back to the built-in shaders:\n" + why;
    line = "reload: error: " + why;
  }
  if (!report && r.error.empty() && r.rebuilt.empty()) return;
  std::replace(line.begin(), line.end(), '\n', ' ');  // one line
  std::printf("%s\n", line.c_str());
  std::fflush(stdout);
}

void App::reloadPlugins(bool settled) {
  for (const std::string& module : modules_->poll(settled)) {
    modules_->accept(module);
    const std::string file = std::filesystem::path(module).filename().string();
    std::string line;
    const gi::EffectRegistry before = registry_;  // the previous module's effects, to fall back
    try {
      const std::vector<std::string> effects = registry_.reloadModule(module);
      std::vector<std::string> kept;
      if (controller_->adoptReloadedModule(effects, &kept)) {
        std::string names, keys;
        for (const std::string& e : effects) names += (names.empty() ? "" : ", ") + e;
        for (const std::string& k : kept) keys += (keys.empty() ? "" : ", ") + k;
        state_.message = "reloaded plugin " + file + " (" + names + ")";
        line = "plugin reload: " + file + ": " + names +
               "; settings kept: " + (keys.empty() ? "none" : keys);
      } else {
        const std::string why = controller_->lastError();
        registry_ = before;
        controller_->reloadEffects();
        state_.message = "plugin reload of " + file + " failed, the previous module runs:\n" + why;
        line = "plugin reload: error: " + why;
      }
    } catch (const std::exception& e) {
      // The registry is unchanged: the previous module keeps running.
      state_.message =
          std::string("plugin reload failed (the previous module keeps running):\n") + e.what();
      line = std::string("plugin reload: error: ") + e.what();
    }
    std::replace(line.begin(), line.end(), '\n', ' ');  // one line
    std::printf("%s\n", line.c_str());
    std::fflush(stdout);
  }
}

void App::printTimings() {
  std::printf(
      "timings: %zu frames at %ux%u, frame %.2f ms (wall, median), GPU passes %.3f ms, UI GPU "
      "%.3f ms, UI CPU %.3f ms; last frame's shadow maps: %u drawn whole, %u from their cache\n",
      timingFrames_.size(), controller_->renderer().outputExtent().width,
      controller_->renderer().outputExtent().height, median(timingFrames_), median(timingGpu_),
      median(timingUiGpu_), median(timingUiCpu_),
      controller_->renderer().lastFrameDraws().shadowMapsDrawn,
      controller_->renderer().lastFrameDraws().shadowMapsCached);
  timingFrames_.clear();
  timingGpu_.clear();
  timingUiCpu_.clear();
  timingUiGpu_.clear();
}

bool App::advanceScript() {
  while (framesLeft_ == 0) {
    if (scriptNext_ == script_.size()) return false;
    execute(script_[scriptNext_++]);
  }
  --framesLeft_;
  return true;
}

void App::execute(const ScriptStep& s) {
  const std::string& path = options_.script;
  auto number = [&](size_t i) { return scriptNumber(s, i, path); };
  auto must = [&](bool ok) {
    if (!ok)
      throw gi::Error(gi::ErrorKind::Usage, path,
                      "line " + std::to_string(s.line) + ": " + controller_->lastError());
  };
  gi::Renderer& renderer = controller_->renderer();
  if (s.verb == "frames") {
    held_ = {};
    framesLeft_ = int(number(0));
  } else if (s.verb == "key") {
    held_ = {};
    std::stringstream keys(s.args[0]);
    for (std::string k; std::getline(keys, k, '+');) {
      if (k == "w")
        held_.forward += 1;
      else if (k == "s")
        held_.forward -= 1;
      else if (k == "d")
        held_.right += 1;
      else if (k == "a")
        held_.right -= 1;
      else if (k == "e")
        held_.up += 1;
      else if (k == "q")
        held_.up -= 1;
      else if (k == "shift")
        held_.fast = true;
      else if (k == "ctrl")
        held_.slow = true;
      else
        throw gi::Error(gi::ErrorKind::Parse, path,
                        "line " + std::to_string(s.line) + ": unknown key '" + k + "'");
    }
    framesLeft_ = int(number(1));
  } else if (s.verb == "look") {
    lookX_ += float(number(0));
    lookY_ += float(number(1));
  } else if (s.verb == "camera") {
    camera_->place({number(0), number(1), number(2)}, float(number(3)), float(number(4)));
    cameraMoved_ = true;
  } else if (s.verb == "effect") {
    must(controller_->setEnabled(s.args[0], s.args[1] == "on"));
  } else if (s.verb == "set") {
    must(controller_->setFromString(s.args[0]));
  } else if (s.verb == "preset") {
    must(controller_->setPreset(s.args[0] == "none" ? "" : s.args[0]));
  } else if (s.verb == "view") {
    must(controller_->setView(s.args[0]));
  } else if (s.verb == "resize") {
    resizeWindow(int(number(0)), int(number(1)));
  } else if (s.verb == "pause") {
    state_.paused = s.args[0] == "on";
  } else if (s.verb == "step") {
    state_.stepOnce = true;
  } else if (s.verb == "time") {
    state_.time = number(0);
  } else if (s.verb == "accuracy") {
    startAccuracy(s.args[0], uint32_t(number(1)));
    accuracy_.wait();
    const auto& r = accuracy_.result();
    if (!accuracy_.error().empty() || !r || r->effect != s.args[0])
      throw gi::Error(gi::ErrorKind::Usage, path,
                      "line " + std::to_string(s.line) + ": " +
                          (accuracy_.error().empty() ? state_.message : accuracy_.error()));
    std::printf("accuracy: %s nrmse %.6f pixels %zu spp %u seconds %.2f quantity %s\n",
                r->effect.c_str(), r->nrmse, r->pixels, r->spp, r->seconds, r->quantity.c_str());
    if (r->recovered)
      std::printf("accuracy: %s engine alone nrmse %.6f error removed %.6f%s\n", r->effect.c_str(),
                  r->aloneNrmse, r->errorRemoved,
                  r->indirect
                      ? (" indirect delivered " + std::to_string(r->indirectDelivered)).c_str()
                      : "");
  } else if (s.verb == "reload") {
    reloadPlugins(false);
    reloadShaders(true);
  } else if (s.verb == "copy") {
    // As a build or an editor replaces a file: a new file renamed over the old one, so that
    // code or text still mapped from the old file is never changed under a reader.
    const std::string partial = s.args[1] + ".partial";
    std::filesystem::copy_file(s.args[0], partial,
                               std::filesystem::copy_options::overwrite_existing);
    std::filesystem::rename(partial, s.args[1]);
  } else if (s.verb == "screenshot") {
    screenshot(s.args[0]);
  } else if (s.args[0] == "passes") {
    std::string executed, culled;
    for (const std::string& p : renderer.passNames()) executed += " " + p;
    for (const std::string& p : renderer.culledPassNames()) culled += " " + p;
    std::printf("passes:%s\nculled:%s\n", executed.c_str(), culled.c_str());
  } else if (s.args[0] == "views") {
    std::string views;
    for (const std::string& v : renderer.viewNames()) views += " " + v;
    std::printf("views:%s\n", views.c_str());
  } else if (s.args[0] == "timings") {
    printTimings();
  } else if (s.args[0] == "memory") {
    std::printf("device memory: %llu bytes in %zu blocks\n",
                static_cast<unsigned long long>(ctx_->allocator().bytesInUse()),
                ctx_->allocator().blockCount());
  } else {  // print camera
    const glm::vec3 p = camera_->position();
    std::printf("camera: %.4f %.4f %.4f %.3f %.3f\n", p.x, p.y, p.z, camera_->yawDeg(),
                camera_->pitchDeg());
  }
  std::fflush(stdout);
}

}  // namespace demo
