// The renderer orchestrates: it owns the engine's state (scene on the GPU, lights, environment,
// output), runs the built-in passes (passes/) and the requested effects on one frame graph in
// dependency order, checks what each declares against what it does, and applies live changes.
#include "gi/renderer.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <ctime>
#include <map>
#include <set>

#include "gi/effect.h"
#include "gi/effect_contract.h"
#include "gi/environment.h"
#include "gi/errors.h"
#include "gi/gbuffer.h"
#include "gi/graph/frame_graph.h"
#include "gi/vk/common.h"
#include "gi/vk/gpu_timer.h"
#include "gi/vk/pipeline.h"
#include "gi/vk/resources.h"
#include "render/frame_submission.h"
#include "render/passes/builtin_passes.h"
#include "render/target_readback.h"
#include "render/view_uniforms.h"

namespace gi {

using namespace gi::vk;
namespace res = gi::resources;

namespace {

void validateSettings(const RenderSettings& s) {
  if (s.width == 0 || s.height == 0 || s.width > 16384 || s.height > 16384)
    throw Error(ErrorKind::Usage, "", "image size must be between 1x1 and 16384x16384");
  if (s.shadowMapSize < 16 || s.shadowMapSize > 8192)
    throw Error(ErrorKind::Usage, "", "shadow map size must be between 16 and 8192");
}

Image makeOutputImage(Context& ctx, uint32_t w, uint32_t h) {
  ImageDesc od;
  od.format = VK_FORMAT_R8G8B8A8_UNORM;
  od.width = w;
  od.height = h;
  od.usage =
      VK_IMAGE_USAGE_STORAGE_BIT | VK_IMAGE_USAGE_SAMPLED_BIT | VK_IMAGE_USAGE_TRANSFER_SRC_BIT;
  return Image(ctx, od);
}

}  // namespace

struct Renderer::Impl : EffectContext {
  struct ActiveEffect {
    std::unique_ptr<Effect> effect;
    EffectInfo info;
    SettingValues settings;
  };

  Context& ctx;
  RenderSettings settings;
  const Scene& source;  // the scene as loaded (scene() is the GPU service)
  const EffectRegistry* registry;
  CameraView cameraView;
  std::optional<CameraView> cameraOverride;  // a free camera instead of the scene's
  std::unique_ptr<SceneGpu> sceneGpu;
  LightSetup lightSetup;
  std::unique_ptr<EnvironmentGpu> environment;
  std::unique_ptr<SurfacePointsPass> surfacePoints;
  uint32_t pointsRequested = 0;
  Image output;
  Sampler linearClamp, nearestClamp;
  Buffer frameBuffer;
  std::optional<LightBuffers> lightBuffers;
  FrameUniforms frameData{};
  glm::mat4 prevViewProj{1.0f};  // the camera of the previous frame (motion vectors)
  FrameClock clock;
  std::vector<std::weak_ptr<ExtraViewUniforms>> views;  // extra views, refreshed per frame
  std::unique_ptr<EngineState> state;

  // Built-in passes, in frame order around the effects.
  std::unique_ptr<Effect> skinningPass, gbufferPass, surfacePointsPass, shadowPass, lightingPass,
      tonemapPass, floorPass;
  std::vector<ActiveEffect> effects;
  std::set<std::string> enginePasses;            // names of the passes the built-ins added
  std::vector<EffectPublications> publications;  // this build's, effect by effect in order
  std::map<std::string, std::vector<std::string>> effectPasses;  // effect -> its passes
  std::vector<std::string> graphWarnings;
  std::map<std::string, double> ranges;  // resource -> publishedRange, this build

  FrameGraph graph;
  bool graphDirty = true, recompiledByLastChange = false;
  ShadowFitBounds shadowFit;
  double compileMs = 0.0;
  DescriptorArena descriptors;
  std::unique_ptr<GpuTimer> timer;  // sized to the compiled graph
  uint32_t timerScopes = 0;
  std::unique_ptr<FrameSubmission> submission;
  std::vector<PassTiming> timings;

  Impl(Context& c, const Scene& s, const RenderSettings& rs, const EffectRegistry* reg)
      : ctx(c),
        settings(rs),
        source(s),
        registry(reg),
        pointsRequested(rs.surfacePoints),
        graph(c, {std::max(rs.width, 1u), std::max(rs.height, 1u)}),
        descriptors(c) {
    validateSettings(settings);
    cameraView = activeCamera(source, aspect());
    prevViewProj = cameraView.proj * cameraView.view;
    sceneGpu = std::make_unique<SceneGpu>(ctx, source);
    environment = std::make_unique<EnvironmentGpu>(ctx, source.environment);
    output = makeOutputImage(ctx, settings.width, settings.height);
    lightBuffers.emplace(ctx);
    linearClamp = Sampler(ctx, VK_FILTER_LINEAR, VK_SAMPLER_ADDRESS_MODE_CLAMP_TO_EDGE);
    nearestClamp = Sampler(ctx, VK_FILTER_NEAREST, VK_SAMPLER_ADDRESS_MODE_CLAMP_TO_EDGE);
    frameBuffer = Buffer(ctx, sizeof(FrameUniforms), VK_BUFFER_USAGE_UNIFORM_BUFFER_BIT, true);
    updateLights();
    updateFrameUniforms();  // frame() is valid from the first prepare() on
    state.reset(new EngineState{ctx, settings, *sceneGpu, lightSetup, *environment, surfacePoints,
                                output, nearestClamp.handle(), linearClamp.handle()});
    state->lightBuffers = &*lightBuffers;
    ctx.requireWorkgroup(256, 1, "skinning / surface points");  // local_size_x 256
    skinningPass = makeSkinningPass(*state);
    gbufferPass = makeGBufferPass(*state);
    surfacePointsPass = makeSurfacePointsPass(*state);
    shadowPass = makeShadowPass(*state);
    lightingPass = makeLightingPass(*state);
    tonemapPass = makeTonemapPass(*state);
    floorPass = makeFloorPass(*state);
    for (Effect* e : builtins()) e->prepare(*this, SettingValues());
    for (const EffectConfig& e : settings.effects) effects.push_back(createEffect(e));
    updateSurfacePoints();
    buildGraph();
    submission = std::make_unique<FrameSubmission>(ctx);
  }

  ~Impl() override {
    vkDeviceWaitIdle(ctx.device());
    graph.reset();
    graph.releasePersistent();
    effects.clear();
  }

  float aspect() const { return float(settings.width) / float(settings.height); }
  // The free camera when one is set, else the scene's (posed when animated).
  CameraView currentCamera() const {
    if (!cameraOverride)
      return activeCamera(source.activeCameraNode >= 0 ? sceneGpu->pose() : source, aspect());
    CameraView v = *cameraOverride;
    v.proj = perspectiveReverseZ(v.yfov, aspect(), v.znear, v.zfar);
    return v;
  }
  std::vector<Effect*> builtins() const {
    return {skinningPass.get(), gbufferPass.get(), surfacePointsPass.get(), shadowPass.get(),
            lightingPass.get(), tonemapPass.get(), floorPass.get()};
  }

  // ---- EffectContext ----------------------------------------------------------------------
  vk::Context& vulkan() override { return ctx; }
  VkBuffer frameUniforms() override { return frameBuffer.handle(); }
  const FrameUniforms& frame() override { return frameData; }
  VkSampler nearestSampler() override { return nearestClamp.handle(); }
  VkSampler linearSampler() override { return linearClamp.handle(); }
  VkExtent2D outputExtent() override { return {settings.width, settings.height}; }
  void requestSurfacePoints(uint32_t count) override {
    pointsRequested = std::max(pointsRequested, count);
  }
  GpuScene& scene() override { return *sceneGpu; }
  std::shared_ptr<ViewUniforms> createView() override {
    auto v = std::make_shared<ExtraViewUniforms>(ctx);
    views.push_back(v);
    return v;
  }
  const CameraView& camera() override { return cameraView; }
  const std::vector<LightInfo>& lights() override { return lightSetup.world; }
  double publishedRange(const std::string& resource) override {
    auto it = ranges.find(resource);
    return it == ranges.end() ? 0.0 : it->second;
  }

  // ---- state --------------------------------------------------------------------------------

  // Runs `call` of an effect's code: whatever it throws (of any type) becomes a gi::Error naming
  // the effect, its module and the call, so a plugin cannot take the app down; the callers'
  // undo paths then keep the previous configuration.
  template <class F>
  void guarded(const std::string& effect, const char* call, F&& f) {
    auto fail = [&](const std::string& why) {
      const std::string origin =
          registry && registry->has(effect) ? registry->origin(effect) : "built-in";
      throw EffectError(ErrorKind::InvalidData, origin,
                        "effect '" + effect + "' failed in " + call + ": " + why, effect);
    };
    try {
      f();
    } catch (const Error& e) {
      // The engine's own errors (a frame-graph or declaration check) get the effect's name
      // when they do not say it already.
      const std::string what = e.what();
      const std::string problem =
          e.file().empty() ? what : what.substr(std::min(what.size(), e.file().size() + 2));
      const bool named = what.find("'" + effect + "'") != std::string::npos;
      throw EffectError(e.kind(), e.file(),
                        named ? problem : "effect '" + effect + "', " + call + ": " + problem,
                        effect);
    } catch (const std::exception& e) {
      fail(e.what());
    } catch (...) {
      fail("it threw something that is not a std::exception");
    }
  }
  void prepareEffect(ActiveEffect& a, const SettingValues& values) {
    guarded(a.info.name, "prepare()", [&] { a.effect->prepare(*this, values); });
  }

  ActiveEffect createEffect(const EffectConfig& e) {
    if (!registry)
      throw Error(ErrorKind::Usage, "", "effect '" + e.name + "' requested but no registry given");
    ActiveEffect a{nullptr, registry->info(e.name), e.settings};
    guarded(e.name, "its constructor", [&] { a.effect = registry->create(e.name); });
    prepareEffect(a, a.settings);
    return a;
  }

  // (Re)samples the points when more are asked for than exist (at the scene as loaded).
  void updateSurfacePoints() {
    if (pointsRequested == 0 || (surfacePoints && surfacePoints->count() >= pointsRequested))
      return;
    surfacePoints.reset();
    surfacePoints = std::make_unique<SurfacePointsPass>(
        ctx, source, pointsRequested, settings.surfacePointSeed, sceneGpu->instanceRefs());
  }

  // Plans the lights and shadow views of the current pose and camera and uploads them. When a
  // light starts or stops casting into the scene the layout changes and the graph is rebuilt.
  void updateLights() {
    glm::vec3 lo, hi;
    sceneGpu->bounds(lo, hi);
    shadowFit.update(lo, hi);
    LightSetup next = planLights(source, sceneGpu->pose().nodes, cameraView, shadowFit.min(),
                                 shadowFit.max(), settings.shadowMapSize);
    checkLightLimits(next, ctx.properties().limits);
    if (!next.sameLayout(lightSetup)) graphDirty = true;
    lightBuffers->upload(next);
    lightSetup = std::move(next);
  }

  void setTime(double seconds) {
    clock.seconds = seconds;
    sceneGpu->setTime(seconds);
    // Animated cameras and lights. The motion vectors compare with the camera of the last
    // rendered frame (renderFrame keeps it); before the first frame nothing moved.
    if (source.activeCameraNode >= 0 || cameraOverride) cameraView = currentCamera();
    if (clock.framesRendered == 0) prevViewProj = cameraView.proj * cameraView.view;
    updateLights();
  }

  // ---- the frame graph ----------------------------------------------------------------------

  // Effects of one stage in the order their declared resources imply (gi/effect_contract.h).
  std::vector<ActiveEffect*> orderedEffects(EffectStage stage) {
    std::vector<ActiveEffect*> list;
    std::vector<const EffectInfo*> infos;
    for (ActiveEffect& a : effects)
      if (a.info.stage == stage) {
        list.push_back(&a);
        infos.push_back(&a.info);
      }
    std::vector<ActiveEffect*> out;
    for (size_t i : orderEffects(infos)) out.push_back(list[i]);
    return out;
  }

  static bool isOptionalInput(const std::string& name) {
    return std::any_of(kLightingInputs.begin(), kLightingInputs.end(),
                       [&](const LightingInput& in) { return name == in.resource; });
  }

  // Adds one effect's (or built-in's) passes and checks them against its declaration. A
  // plugin effect owns its passes: one that fails while recording names it (EffectError).
  void addChecked(Effect& e, const EffectInfo& info, const SettingValues& values,
                  bool plugin = true) {
    Blackboard& bb = graph.blackboard();
    bb.startTracking();
    graph.setPassOwner(plugin ? info.name : "");
    const size_t passesBefore = graph.passNames().size();
    guarded(info.name, "addPasses()", [&] { e.addPasses(graph, *this, values); });
    graph.setPassOwner("");
    if (plugin) {
      publications.push_back({info.name, bb.lookedUp(), bb.published()});
      recordRange(info, values, bb.published());
      const std::vector<std::string> all = graph.passNames();
      effectPasses[info.name].assign(all.begin() + std::ptrdiff_t(passesBefore), all.end());
    }
    // An optional lighting input may stay unpublished: its neutral fallback stands in (e.g.
    // SSDO's contact_shadow when off).
    checkEffectResources(info, bb.lookedUp(), bb.published(), isOptionalInput);
  }

  // What lighting.comp ignores when another input is published (kLightingInputs).
  static std::vector<Masking> lightingMasks() {
    std::vector<Masking> masks;
    auto does = [](const std::string& name) {
      for (const LightingInput& in : kLightingInputs)
        if (name == in.resource) return std::string(in.does);
      return std::string();
    };
    for (const LightingInput& in : kLightingInputs)
      if (*in.maskedBy) masks.push_back({in.maskedBy, does(in.maskedBy), in.resource, in.does});
    return masks;
  }

  // Its outputs account for occluders and light within its declared range (publishedRange).
  void recordRange(const EffectInfo& info, const SettingValues& values,
                   const std::set<std::string>& published) {
    double range = 0.0;
    if (!info.range.empty()) {
      const auto& descs = values.descs();
      if (std::none_of(descs.begin(), descs.end(),
                       [&](const SettingDesc& d) { return d.name == info.range; }))
        throw Error(ErrorKind::Usage, "",
                    "effect '" + info.name + "' declares its range by the setting '" + info.range +
                        "', which it does not have");
      range = values.number(info.range);
    }
    for (const std::string& r : published) ranges[r] = range;
  }

  void addBuiltin(Effect& e) {
    const std::vector<std::string> before = graph.passNames();
    addChecked(e, e.info(), SettingValues(), false);
    const std::vector<std::string> after = graph.passNames();
    for (size_t i = before.size(); i < after.size(); ++i) enginePasses.insert(after[i]);
  }

  void buildGraph() {
    const auto start = std::chrono::steady_clock::now();
    graph.reset();
    graph.setOutputExtent({settings.width, settings.height});
    graph.setAliasing(settings.aliasTransients);
    sceneGpu->setVertices({});
    enginePasses.clear();
    publications.clear();
    effectPasses.clear();
    graphWarnings.clear();
    ranges.clear();
    Blackboard& bb = graph.blackboard();
    // The neutral value of each optional lighting input, declared in this one place.
    for (const LightingInput& in : kLightingInputs)
      graph.declareFallback(in.resource, in.format,
                            {{in.neutral[0], in.neutral[1], in.neutral[2], in.neutral[3]}});
    // Engine data every pass may read: lights, shadow views, the environment.
    bb.put(res::kLights, graph.importBuffer(res::kLights, lightBuffers->lights().handle(),
                                            lightBuffers->lights().size()));
    bb.put(res::kShadowViews,
           graph.importBuffer(res::kShadowViews, lightBuffers->shadowViews().handle(),
                              lightBuffers->shadowViews().size()));
    const Image& envMap = environment->map();
    TextureDesc envDesc{envMap.desc().format, SizeClass::Absolute, 1.0f, envMap.desc().width,
                        envMap.desc().height};
    bb.put(res::kEnvironmentMap,
           graph.importTexture(res::kEnvironmentMap, envMap.handle(), envMap.view(), envDesc,
                               VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL));
    bb.put(res::kEnvironmentSampling,
           graph.importBuffer(res::kEnvironmentSampling, environment->samplingBuffer(),
                              environment->samplingBytes()));

    addBuiltin(*skinningPass);
    addBuiltin(*gbufferPass);
    addBuiltin(*surfacePointsPass);
    addBuiltin(*shadowPass);
    for (ActiveEffect* a : orderedEffects(EffectStage::BeforeLighting))
      addChecked(*a->effect, a->info, a->settings);
    addBuiltin(*lightingPass);
    for (ActiveEffect* a : orderedEffects(EffectStage::AfterLighting))
      addChecked(*a->effect, a->info, a->settings);
    checkComposition(publications, lightingMasks());  // no effect's work silently lost
    addBuiltin(*tonemapPass);
    addBuiltin(*floorPass);
    if (!bb.has(settings.view)) {
      std::string names;
      for (const std::string& n : bb.names()) names += (names.empty() ? "" : ", ") + n;
      throw Error(ErrorKind::Usage, "",
                  "unknown view '" + settings.view + "' (available: " + names + ")");
    }
    TextureHandle view = bb.texture(settings.view);
    if (!view.valid())
      throw Error(ErrorKind::Usage, "", "view '" + settings.view + "' is a buffer, not an image");
    graph.markOutput(view);
    for (const std::string& name : settings.keepForReadback)
      if (bb.has(name) && bb.texture(name).valid()) graph.markOutput(bb.texture(name));
    if (settings.floorPass) graph.markOutput(bb.texture(res::kFloor));
    graph.compile();
    graphDirty = false;
    warnAboutCulledEffects();
    // One timestamp scope per executed pass (any number of shadow-casting lights).
    const uint32_t scopes = std::max(uint32_t(graph.executedPasses().size()) + 8, 64u);
    if (!timer || timerScopes < scopes) {
      timer = std::make_unique<GpuTimer>(ctx, scopes);
      timerScopes = scopes;
    }
    compileMs =
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  }

  // Each enabled effect, in order, with how many of its passes the graph runs.
  std::vector<Renderer::EffectPasses> passesPerEffect() const {
    const std::vector<std::string> run = graph.executedPasses();
    const std::set<std::string> executed(run.begin(), run.end());
    std::vector<Renderer::EffectPasses> out;
    for (const EffectPublications& e : publications) {
      const std::vector<std::string>& passes = effectPasses.at(e.effect);
      const auto ran = std::count_if(passes.begin(), passes.end(),
                                     [&](const std::string& p) { return executed.count(p) != 0; });
      out.push_back({e.effect, size_t(ran), passes.size()});
    }
    return out;
  }

  // An enabled effect that runs no pass costs nothing but does nothing either: said, naming
  // it, instead of left for the user to find in --print-graph.
  void warnAboutCulledEffects() {
    for (const Renderer::EffectPasses& e : passesPerEffect())
      if (e.total == 0)
        graphWarnings.push_back("effect '" + e.effect +
                                "' adds no pass: nothing to do for this scene and settings");
      else if (e.run == 0)
        graphWarnings.push_back("effect '" + e.effect +
                                "' runs no pass: nothing it writes reaches the view '" +
                                settings.view + "'");
  }

  // Rebuilds now; if the new configuration fails, restores `undo` and rethrows (the renderer
  // keeps working with its previous configuration).
  template <class Undo>
  void rebuildOrUndo(Undo undo) {
    try {
      buildGraph();
    } catch (...) {
      undo();
      dropGraph();
      buildGraph();
      throw;
    }
  }

  // ---- frames ---------------------------------------------------------------------------

  // The main view's uniforms of the coming frame (frameData, uploaded).
  void updateFrameUniforms() {
    frameData =
        mainViewUniforms(settings, source.environment, *environment,
                         uint32_t(lightSetup.lights.size()), cameraView, prevViewProj, clock);
    frameBuffer.write(&frameData, sizeof frameData);
  }

  // Extra views: frame-wide values from the main view, their own camera (after the effects'
  // update() hooks moved them).
  void updateViews() {
    std::erase_if(views, [](const std::weak_ptr<ExtraViewUniforms>& v) { return v.expired(); });
    for (const auto& v : views) v.lock()->refresh(frameData);
  }

  void renderFrame() {
    if (graphDirty) buildGraph();
    sceneGpu->setCulling(settings.cullDraws);
    sceneGpu->beginFrame();
    state->shadowMapsDrawn = state->shadowMapsCached = 0;
    updateFrameUniforms();
    for (ActiveEffect& a : effects)
      guarded(a.info.name, "update()", [&] { a.effect->update(*this, a.settings); });
    updateViews();
    descriptors.reset();
    try {
      timings = submission->run(graph, descriptors, *timer, settings.isolatePasses);
    } catch (const EffectError& e) {
      forgetFailedFrame();
      if (!e.file().empty() || !registry || !registry->has(e.effect())) throw;
      throw EffectError(e.kind(), registry->origin(e.effect()), e.what(),
                        e.effect());  // its module
    } catch (...) {
      forgetFailedFrame();
      throw;
    }
    prevViewProj = cameraView.proj * cameraView.view;
    clock.previousSeconds = clock.seconds;
    ++clock.framesRendered;
  }

  // ---- live changes ---------------------------------------------------------------------

  // Drops the compiled graph (its passes may refer to pipelines about to be replaced); the
  // next frame rebuilds it unless a change rebuilds it first.
  void dropGraph() {
    vkDeviceWaitIdle(ctx.device());
    graph.reset();
    graphDirty = true;
  }
  // A frame whose recording failed was not (or only partly) submitted, but the graph's record
  // of its images' layouts moved on: start again from a new graph and cleared history.
  void forgetFailedFrame() {
    dropGraph();
    graph.releasePersistent();
  }

  void setEffectSettings(const std::string& name, const SettingValues& values) {
    for (size_t i = 0; i < effects.size(); ++i) {
      ActiveEffect& a = effects[i];
      if (a.info.name != name) continue;
      const bool rebuild = a.settings.graphDiffers(values);
      if (rebuild) {
        dropGraph();
        const SettingValues old = a.settings;
        try {
          prepareEffect(a, values);
        } catch (...) {
          prepareEffect(a, old);  // the previous settings worked
          throw;
        }
      }
      a.settings = values;
      if (i < settings.effects.size()) settings.effects[i].settings = values;
      recompiledByLastChange = rebuild;
      if (rebuild) updateSurfacePoints();
      return;
    }
    throw Error(ErrorKind::Usage, "", "effect '" + name + "' is not active in this renderer");
  }

  // Keeps the instances of effects that stay (their settings updated), creates new ones. On
  // any error (unknown effect, a failing prepare or graph) the previous effects stay active
  // with their previous settings.
  void setEffects(const std::vector<EffectConfig>& configs) {
    std::set<std::string> seen;
    for (const EffectConfig& c : configs)
      if (!seen.insert(c.name).second)
        throw Error(ErrorKind::Usage, "", "effect '" + c.name + "' listed twice");
    dropGraph();
    const std::vector<EffectConfig> oldConfigs = settings.effects;
    std::vector<ActiveEffect> previous = std::move(effects);
    effects.clear();
    auto restore = [&] {
      for (ActiveEffect& a : effects)
        for (size_t i = 0; i < oldConfigs.size(); ++i)
          if (oldConfigs[i].name == a.info.name && !previous[i].effect) {
            previous[i] = std::move(a);
            break;
          }
      effects = std::move(previous);
      settings.effects = oldConfigs;
      for (size_t i = 0; i < effects.size(); ++i) {
        effects[i].settings = oldConfigs[i].settings;
        prepareEffect(effects[i], effects[i].settings);
      }
      buildGraph();
    };
    try {
      for (const EffectConfig& c : configs) {
        auto it = std::find_if(previous.begin(), previous.end(), [&](const ActiveEffect& a) {
          return a.effect && a.info.name == c.name;
        });
        if (it == previous.end()) {
          effects.push_back(createEffect(c));
          continue;
        }
        if (it->settings.graphDiffers(c.settings)) prepareEffect(*it, c.settings);
        it->settings = c.settings;
        effects.push_back(std::move(*it));
        it->effect.reset();
      }
      settings.effects = configs;
      updateSurfacePoints();
      recompiledByLastChange = true;
      buildGraph();
    } catch (...) {
      restore();
      throw;
    }
  }

  void setView(const std::string& view) {
    const std::string old = settings.view;
    settings.view = view;
    dropGraph();
    rebuildOrUndo([&] { settings.view = old; });
    recompiledByLastChange = true;
  }

  // Size-dependent state: the output image, the camera's aspect, motion history.
  void resize() {
    output = makeOutputImage(ctx, settings.width, settings.height);
    cameraView = currentCamera();
    prevViewProj = cameraView.proj * cameraView.view;
    for (const auto& v : views)
      if (auto view = v.lock()) view->forgetHistory();
  }

  // Engine settings, size, view and effect list in one call (what a settings UI changes). On an
  // error the renderer keeps its previous configuration.
  void applySettings(const RenderSettings& next) {
    validateSettings(next);
    const RenderSettings old = settings;
    auto differs = [](const std::vector<EffectConfig>& a, const std::vector<EffectConfig>& b) {
      if (a.size() != b.size()) return true;
      for (size_t i = 0; i < a.size(); ++i)
        if (a[i].name != b[i].name || a[i].settings.toJson() != b[i].settings.toJson()) return true;
      return false;
    };
    const bool effectsChange = differs(next.effects, old.effects);
    const bool resized = next.width != old.width || next.height != old.height;
    const bool graphChange = resized || next.shadowMapSize != old.shadowMapSize ||
                             next.surfacePoints != old.surfacePoints ||
                             next.surfacePointSeed != old.surfacePointSeed ||
                             next.view != old.view || next.floorPass != old.floorPass ||
                             next.aliasTransients != old.aliasTransients;
    auto apply = [&](const RenderSettings& s) {
      dropGraph();
      const RenderSettings before = settings;
      settings = s;
      settings.effects = before.effects;  // setEffects() changes these
      if (s.width != before.width || s.height != before.height) resize();
      if (s.surfacePointSeed != before.surfacePointSeed) surfacePoints.reset();
      pointsRequested = std::max(pointsRequested, settings.surfacePoints);
      updateSurfacePoints();
      updateLights();
    };
    try {
      apply(next);
      if (effectsChange)
        setEffects(next.effects);  // rebuilds the graph
      else
        buildGraph();
    } catch (...) {
      apply(old);
      buildGraph();
      throw;
    }
    recompiledByLastChange = graphChange || effectsChange;
  }

  FrameGraph::TextureState stateOf(const std::string& name) {
    TextureHandle h = graph.blackboard().texture(name);
    if (!h.valid())
      throw Error(ErrorKind::Usage, "", "no resource named '" + name + "' in this frame");
    // Never hand out another resource's texels as this one's.
    if (!graph.intactAtEnd(h))
      throw Error(ErrorKind::Usage, "",
                  "'" + name +
                      "' cannot be read back: a later pass reused its memory (frame-graph "
                      "aliasing); list it in RenderSettings::keepForReadback");
    return graph.textureState(h);
  }
};

Renderer::Renderer(Context& ctx, const Scene& scene, const RenderSettings& settings,
                   const EffectRegistry* registry)
    : impl_(std::make_unique<Impl>(ctx, scene, settings, registry)) {}
Renderer::~Renderer() = default;
void Renderer::renderFrame() {
  impl_->renderFrame();
}
void Renderer::setTime(double seconds) {
  impl_->setTime(seconds);
}
uint32_t Renderer::lastSkinnedVertexCount() const {
  return impl_->state->skinnedThisFrame;
}
std::vector<Renderer::DeformedMesh> Renderer::readDeformedMeshes() {
  Impl& m = *impl_;
  std::vector<DeformedMesh> out;
  if (m.sceneGpu->deformed().empty()) return out;
  const vk::Buffer& vb = m.sceneGpu->vertexBuffer();
  vk::Buffer staging(m.ctx, vb.size(), VK_BUFFER_USAGE_TRANSFER_DST_BIT, true);
  m.ctx.submitAndWait([&](VkCommandBuffer c) {
    VkBufferCopy copy{0, 0, vb.size()};
    vkCmdCopyBuffer(c, vb.handle(), staging.handle(), 1, &copy);
  });
  const auto* all = static_cast<const Vertex*>(staging.mapped());
  for (const SceneGpu::Deformed& d : m.sceneGpu->deformed())
    out.push_back({d.node, d.mesh, {all + d.dstFirst, all + d.dstFirst + d.count}});
  return out;
}
const SurfacePointSet& Renderer::surfacePoints() const {
  static const SurfacePointSet kNone;
  return impl_->surfacePoints ? impl_->surfacePoints->set() : kNone;
}
uint64_t Renderer::surfacePointEvaluations() const {
  return impl_->surfacePoints ? impl_->surfacePoints->evaluations() : 0;
}
std::vector<SurfacePointSample> Renderer::readSurfacePoints() {
  if (!impl_->surfacePoints) return {};
  return impl_->surfacePoints->read(impl_->ctx);
}
const std::vector<PassTiming>& Renderer::lastTimings() const {
  return impl_->timings;
}
std::vector<std::string> Renderer::passNames() const {
  return impl_->graph.executedPasses();
}
std::vector<std::string> Renderer::culledPassNames() const {
  return impl_->graph.culledPasses();
}
const std::vector<std::string>& Renderer::warnings() const {
  return impl_->graphWarnings;
}
bool Renderer::isEnginePass(const std::string& pass) const {
  return impl_->enginePasses.count(pass) > 0;
}
std::vector<Renderer::EffectPasses> Renderer::effectPasses() const {
  return impl_->passesPerEffect();
}
std::string Renderer::graphDescription() const {
  std::string effects;
  for (const EffectPasses& e : effectPasses())
    effects += "  " + e.effect + ": " + std::to_string(e.run) + " of " + std::to_string(e.total) +
               " passes run" + (e.run == 0 ? " (reaches nothing: culled)" : "") + "\n";
  return (effects.empty() ? "" : "effects:\n" + effects) + impl_->graph.describe();
}
std::string Renderer::graphDot() const {
  return impl_->graph.toDot();
}
Renderer::DrawCounts Renderer::lastFrameDraws() const {
  const SceneGpu::DrawCounts c = impl_->sceneGpu->drawCounts();
  return {c.drawn, c.culled, impl_->state->shadowMapsDrawn, impl_->state->shadowMapsCached};
}
double Renderer::lastCompileMs() const {
  return impl_->compileMs;
}
void Renderer::setEffectSettings(const std::string& effect, const SettingValues& values) {
  impl_->setEffectSettings(effect, values);
}
void Renderer::setEffects(const std::vector<EffectConfig>& effects) {
  impl_->setEffects(effects);
}
void Renderer::setView(const std::string& view) {
  impl_->setView(view);
}
void Renderer::applySettings(const RenderSettings& settings) {
  impl_->applySettings(settings);
}
const RenderSettings& Renderer::settings() const {
  return impl_->settings;
}
bool Renderer::graphRecompiledByLastChange() const {
  return impl_->recompiledByLastChange;
}
const CameraView& Renderer::camera() const {
  return impl_->cameraView;
}
void Renderer::setCameraOverride(const std::optional<CameraView>& camera) {
  if (camera && !(camera->znear > 0.0f && camera->zfar > camera->znear && camera->yfov > 0.0f &&
                  camera->yfov < 3.14f))
    throw Error(ErrorKind::InvalidData, "",
                "camera override: needs 0 < znear < zfar and a vertical fov in (0, 3.14)");
  impl_->cameraOverride = camera;
  impl_->cameraView = impl_->currentCamera();
  if (impl_->clock.framesRendered == 0)
    impl_->prevViewProj = impl_->cameraView.proj * impl_->cameraView.view;
  impl_->updateLights();
}
ImageRGBA32F Renderer::readTarget(const std::string& name) {
  // An unpacked G-buffer channel nothing read this frame (its pass was culled): unpacked here
  // from the packed texels, as the pass would have.
  for (size_t c = 0; c < gbuffer::kChannels.size(); ++c) {
    const Blackboard& bb = impl_->graph.blackboard();
    if (name != gbuffer::kChannels[c] || !bb.has(name) || impl_->graph.produced(bb.texture(name)))
      continue;
    if (!impl_->graph.intactAtEnd(bb.texture(res::kGBuffer)))
      throw Error(ErrorKind::Usage, "",
                  "'" + name +
                      "' was not unpacked this frame and the packed G-buffer's memory "
                      "was reused (frame-graph aliasing); list '" +
                      name + "' in RenderSettings::keepForReadback");
    const FrameGraph::TextureState packed = impl_->stateOf(res::kGBuffer);
    return gbuffer::unpackChannel(readTexels(impl_->ctx, packed), int(packed.extent.width),
                                  int(packed.extent.height), c);
  }
  const FrameGraph::TextureState t = impl_->stateOf(name);
  return texelsToFloat(readTexels(impl_->ctx, t), t, name);
}
std::vector<uint8_t> Renderer::readTargetBytes(const std::string& name) {
  return readTexels(impl_->ctx, impl_->stateOf(name));
}
std::vector<Renderer::NamedTexture> Renderer::readAllTextures() {
  std::vector<NamedTexture> out;
  for (const auto& [name, state] : impl_->graph.allocatedTextures()) {
    NamedTexture t{name, state.format, false, {}};
    if (canDecode(state.format) && state.layout != VK_IMAGE_LAYOUT_UNDEFINED) {
      t.image = texelsToFloat(readTexels(impl_->ctx, state), state, name);
      t.decoded = true;
    }
    out.push_back(std::move(t));
  }
  return out;
}
std::vector<std::string> Renderer::viewNames() const {
  // Images of float or normalized texels only: a buffer (lights, sampling tables) or packed
  // integer texels (the "gbuffer", whose channels are views of their own) cannot be shown.
  std::vector<std::string> names;
  const Blackboard& bb = impl_->graph.blackboard();
  for (const std::string& n : bb.names())
    if (bb.texture(n).valid() && canDecode(impl_->graph.textureFormat(bb.texture(n))))
      names.push_back(n);
  return names;
}
VkImage Renderer::outputImage() const {
  return impl_->output.handle();
}
VkExtent2D Renderer::outputExtent() const {
  return {impl_->settings.width, impl_->settings.height};
}
ImageRGBA8 Renderer::readOutput() {
  std::vector<uint8_t> raw = readTexels(impl_->ctx, impl_->stateOf(res::kOutput));
  return {int(impl_->settings.width), int(impl_->settings.height), std::move(raw)};
}

}  // namespace gi
