#include "panel.h"

#include <imgui.h>

#include <algorithm>
#include <cmath>
#include <numeric>

#include "gi/engine_settings.h"

namespace demo {

namespace {

void tooltip(const gi::SettingDesc& d) {
  if (!ImGui::IsItemHovered()) return;
  std::string text = d.help;
  text += d.changesGraph ? "\n(rebuilds the frame graph)" : "\n(uniform only)";
  ImGui::SetTooltip("%s", text.c_str());
}

// Snaps to the declared step from the minimum, inside the range.
double snap(const gi::SettingDesc& d, double v) {
  if (d.step > 0.0) v = d.minValue + std::round((v - d.minValue) / d.step) * d.step;
  return std::clamp(v, d.minValue, d.maxValue);
}

const ImU32 kPassColors[] = {IM_COL32(230, 25, 75, 255),  IM_COL32(60, 180, 75, 255),
                             IM_COL32(255, 225, 25, 255), IM_COL32(0, 130, 200, 255),
                             IM_COL32(245, 130, 48, 255), IM_COL32(145, 30, 180, 255),
                             IM_COL32(70, 240, 240, 255), IM_COL32(240, 50, 230, 255),
                             IM_COL32(210, 245, 60, 255), IM_COL32(250, 190, 212, 255)};

// Each pass's GPU time as one segment of a bar, the UI's own pass last, with a legend.
void stackedBar(const FrameStats& stats) {
  std::vector<gi::PassTiming> parts = stats.passes;
  if (stats.uiGpuMs >= 0.0) parts.push_back({"imgui (UI)", stats.uiGpuMs});
  double total = 0.0;
  for (const auto& p : parts) total += p.ms;
  ImGui::Text("GPU %.2f ms per frame (%zu passes + UI)", total, stats.passes.size());
  const float width = ImGui::GetContentRegionAvail().x, height = 18.0f;
  const ImVec2 origin = ImGui::GetCursorScreenPos();
  ImDrawList* draw = ImGui::GetWindowDrawList();
  float x = origin.x;
  for (size_t i = 0; i < parts.size() && total > 0.0; ++i) {
    const float w = float(parts[i].ms / total) * width;
    draw->AddRectFilled({x, origin.y}, {x + w, origin.y + height},
                        kPassColors[i % std::size(kPassColors)]);
    x += w;
  }
  ImGui::Dummy({width, height});
  for (size_t i = 0; i < parts.size(); ++i) {
    ImGui::ColorButton(("##c" + std::to_string(i)).c_str(),
                       ImGui::ColorConvertU32ToFloat4(kPassColors[i % std::size(kPassColors)]),
                       ImGuiColorEditFlags_NoTooltip, {10, 10});
    ImGui::SameLine();
    ImGui::Text("%-16s %7.3f ms", parts[i].name.c_str(), parts[i].ms);
  }
}

void timingSection(const FrameStats& stats) {
  if (!ImGui::CollapsingHeader("Timings", ImGuiTreeNodeFlags_DefaultOpen)) return;
  std::vector<float> frames(stats.frameMs.begin(), stats.frameMs.end());
  const float last = frames.empty() ? 0.0f : frames.back();
  const float worst = frames.empty() ? 1.0f : *std::max_element(frames.begin(), frames.end());
  ImGui::Text("frame %.1f ms (%.1f fps), UI CPU %.2f ms, UI GPU %.3f ms", last,
              last > 0 ? 1000.0f / last : 0.0f, stats.uiCpuMs, std::max(stats.uiGpuMs, 0.0));
  ImGui::PlotLines("##frames", frames.data(), int(frames.size()), 0, "frame time (ms)", 0.0f,
                   worst * 1.2f, {ImGui::GetContentRegionAvail().x, 60});
  stackedBar(stats);
  ImGui::Text("device memory in use: %.1f MiB", double(stats.deviceBytes) / (1024.0 * 1024.0));
}

void passSection(gi::Renderer& renderer) {
  if (!ImGui::CollapsingHeader("Frame graph")) return;
  // Which effect's work reaches the image: one that runs no pass is named, not left unseen.
  for (const gi::Renderer::EffectPasses& e : renderer.effectPasses())
    ImGui::Text("%s: %zu of %zu passes run", e.effect.c_str(), e.run, e.total);
  for (const std::string& w : renderer.warnings())
    ImGui::TextColored({1, 0.7f, 0.2f, 1}, "%s", w.c_str());
  ImGui::TextUnformatted("executed:");
  for (const std::string& p : renderer.passNames())
    ImGui::BulletText("%s%s", p.c_str(), renderer.isEnginePass(p) ? "" : "  (effect)");
  ImGui::TextUnformatted("culled:");
  const auto culled = renderer.culledPassNames();
  if (culled.empty()) ImGui::BulletText("none");
  for (const std::string& p : culled) ImGui::TextDisabled("  - %s", p.c_str());
}

void settingsOf(Controller& controller, const std::string& owner) {
  ImGui::PushID(owner.c_str());
  for (const gi::SettingDesc& d : controller.settings(owner).descs())
    settingWidget(controller, owner, d);
  ImGui::PopID();
}

}  // namespace

bool settingWidget(Controller& controller, const std::string& owner, const gi::SettingDesc& d) {
  const gi::SettingValues& values = controller.settings(owner);
  const char* label = d.name.c_str();
  using T = gi::SettingType;
  nlohmann::json changed;
  const ImGuiSliderFlags log = d.logScale ? ImGuiSliderFlags_Logarithmic : 0;
  switch (d.type) {
    case T::Bool: {
      bool v = values.flag(d.name);
      if (ImGui::Checkbox(label, &v)) changed = v;
      break;
    }
    case T::Int: {
      int v = values.integer(d.name);
      const int lo = int(d.minValue), hi = int(d.maxValue);
      bool edited = false;
      // Wide ranges without a log hint (sizes, counts) are typed in with the step.
      if (d.step > 0.0 && !d.logScale && hi - lo > 256)
        edited = ImGui::InputInt(label, &v, int(d.step), int(d.step) * 8);
      else
        edited = ImGui::SliderInt(label, &v, lo, hi, "%d", log | ImGuiSliderFlags_AlwaysClamp);
      if (edited) changed = int(snap(d, v));
      break;
    }
    case T::Float: {
      float v = float(values.number(d.name));
      if (ImGui::SliderFloat(label, &v, float(d.minValue), float(d.maxValue), "%.4g",
                             log | ImGuiSliderFlags_AlwaysClamp))
        changed = snap(d, v);
      break;
    }
    case T::Enum: {
      const int current = values.integer(d.name);
      if (ImGui::BeginCombo(label, d.options.at(current).c_str())) {
        for (size_t i = 0; i < d.options.size(); ++i)
          if (ImGui::Selectable(d.options[i].c_str(), int(i) == current)) changed = d.options[i];
        ImGui::EndCombo();
      }
      break;
    }
    case T::Vec3:
    case T::Color: {
      const auto a = values.vector(d.name);
      float v[3] = {float(a[0]), float(a[1]), float(a[2])};
      bool edited = d.type == T::Color && d.maxValue <= 1.0
                        ? ImGui::ColorEdit3(label, v)
                        : ImGui::SliderFloat3(label, v, float(d.minValue), float(d.maxValue),
                                              "%.3g", ImGuiSliderFlags_AlwaysClamp);
      if (edited) changed = nlohmann::json::array({snap(d, v[0]), snap(d, v[1]), snap(d, v[2])});
      break;
    }
  }
  tooltip(d);
  if (changed.is_null()) return false;
  controller.setSetting(owner, d.name, changed);
  return true;
}

void accuracySection(DemoState& state, const AccuracyCheck& accuracy) {
  if (!ImGui::CollapsingHeader("Accuracy (CPU reference)")) return;
  ImGui::SliderInt("reference spp", &state.accuracySpp, 1, 1024, "%d",
                   ImGuiSliderFlags_Logarithmic | ImGuiSliderFlags_AlwaysClamp);
  ImGui::TextDisabled("an effect's \"accuracy\" button (or R: the first one on) starts a check");
  if (accuracy.running()) ImGui::ProgressBar(accuracy.progress(), {-1, 0}, "reference rendering");
  if (!accuracy.error().empty())
    ImGui::TextColored({1, 0.4f, 0.3f, 1}, "%s", accuracy.error().c_str());
  if (const auto& r = accuracy.result()) {
    ImGui::Text("%s vs %s: NRMSE %.4f", r->effect.c_str(), r->quantity.c_str(), r->nrmse);
    ImGui::Text("%zu pixels, %u spp, %.1f s", r->pixels, r->spp, r->seconds);
    if (r->recovered)
      ImGui::Text("engine alone %.4f: %.0f%% of its error removed", r->aloneNrmse,
                  100.0 * r->errorRemoved);
    if (r->indirect)
      ImGui::Text("%.0f%% of the reference's indirect light delivered",
                  100.0 * r->indirectDelivered);
    ImGui::Checkbox("show the error image", &state.showError);
  }
}

void drawPanel(Controller& controller, const FrameStats& stats, DemoState& state,
               FreeCamera& camera, const AccuracyCheck& accuracy) {
  if (!state.panel) return;
  ImGui::SetNextWindowPos({10, 10}, ImGuiCond_FirstUseEver);
  ImGui::SetNextWindowSize({420, 640}, ImGuiCond_FirstUseEver);
  ImGui::Begin("gi-demo (F1: help, Tab: hide)");
  gi::Renderer& renderer = controller.renderer();

  ImGui::Text("t = %.2f s %s", state.time, state.paused ? "(paused)" : "");
  ImGui::SameLine();
  if (ImGui::Button(state.paused ? "Play" : "Pause")) state.togglePause = true;
  const ImVec2 at = ImGui::GetItemRectMin(), size = ImGui::GetItemRectSize();
  state.pauseButton = {at.x, at.y, size.x, size.y};
  ImGui::SameLine();
  if (ImGui::Button("Step")) state.stepOnce = true;
  ImGui::SameLine();
  if (ImGui::Button("Screenshot")) state.screenshot = true;
  ImGui::SliderFloat("camera speed", &camera.speed, 0.1f, 20.0f, "%.2f m/s",
                     ImGuiSliderFlags_Logarithmic);
  ImGui::SliderFloat("frame budget", &state.frameBudgetMs, 0.0f, 200.0f,
                     state.frameBudgetMs > 0.0f ? "%.0f ms" : "off");
  if (ImGui::IsItemHovered())
    ImGui::SetTooltip("dynamic resolution: the render scale keeps the frame within this time");
  ImGui::SameLine();
  ImGui::Text("render %ux%u (%.0f%%)", renderer.outputExtent().width,
              renderer.outputExtent().height, 100.0 * state.renderScale);
  if (!state.message.empty()) ImGui::TextWrapped("%s", state.message.c_str());
  if (!controller.lastError().empty())
    ImGui::TextColored({1, 0.4f, 0.3f, 1}, "%s", controller.lastError().c_str());

  // Preset and view.
  const std::string presetLabel = controller.preset().empty() ? "none" : controller.preset();
  if (ImGui::BeginCombo("preset", presetLabel.c_str())) {
    if (ImGui::Selectable("none", controller.preset().empty())) controller.setPreset("");
    for (const std::string& p : controller.presets())
      if (ImGui::Selectable(p.c_str(), p == controller.preset())) controller.setPreset(p);
    ImGui::EndCombo();
  }
  if (ImGui::BeginCombo("view", controller.view().c_str())) {
    std::vector<std::string> views = renderer.viewNames();
    if (std::find(views.begin(), views.end(), gi::resources::kOutput) == views.end())
      views.insert(views.begin(), gi::resources::kOutput);
    for (const std::string& v : views)
      if (ImGui::Selectable(v.c_str(), v == controller.view())) controller.setView(v);
    ImGui::EndCombo();
  }

  timingSection(stats);
  passSection(renderer);

  if (ImGui::CollapsingHeader("Effects", ImGuiTreeNodeFlags_DefaultOpen)) {
    for (const std::string& name : controller.effects()) {
      const gi::EffectInfo& info = controller.registry().info(name);
      ImGui::PushID(name.c_str());
      bool on = controller.enabled(name);
      if (ImGui::Checkbox("##on", &on)) controller.setEnabled(name, on);
      if (ImGui::IsItemHovered()) ImGui::SetTooltip("%s", info.description.c_str());
      ImGui::SameLine();
      if (ImGui::TreeNode(name.c_str())) {
        ImGui::TextWrapped("%s", info.description.c_str());
        if (!info.debugView.empty() && ImGui::SmallButton("show its view"))
          controller.setView(info.debugView);
        if (on) {
          ImGui::SameLine();
          if (ImGui::SmallButton("accuracy")) state.accuracyRequest = name;
        }
        settingsOf(controller, name);
        ImGui::TreePop();
      }
      ImGui::PopID();
    }
  }
  if (ImGui::CollapsingHeader("Engine")) settingsOf(controller, gi::kEngineSettingsOwner);
  accuracySection(state, accuracy);
  ImGui::End();
}

void drawHelp(DemoState& state) {
  if (!state.help) return;
  ImGui::SetNextWindowPos({440, 10}, ImGuiCond_FirstUseEver);
  ImGui::Begin("Keys", &state.help, ImGuiWindowFlags_AlwaysAutoResize);
  const char* keys[][2] = {{"W A S D", "walk"},
                           {"Q / E", "down / up"},
                           {"Shift / Ctrl", "run / creep"},
                           {"right mouse drag", "look around"},
                           {"P", "pause / play the clock"},
                           {"N", "step one frame (paused)"},
                           {"R", "accuracy check of the first effect on"},
                           {"F2", "screenshot (PNG in out/)"},
                           {"Tab", "hide / show the panel"},
                           {"F1", "this help"},
                           {"Esc", "quit"}};
  for (const auto& k : keys) ImGui::Text("%-18s %s", k[0], k[1]);
  ImGui::End();
}

}  // namespace demo
