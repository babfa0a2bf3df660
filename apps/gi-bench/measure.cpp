#include "measure.h"

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

#include "gi/errors.h"
#include "stats.h"

namespace gi_bench {

namespace {

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

}  // namespace

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
      for (const std::string& w : renderers.back()->warnings())
        std::fprintf(stderr, "gi-bench: warning: %s\n", w.c_str());
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

// The pixels whose reference mean normalises the error: the scored ones but emitters (G-buffer
// emission > 0), whose few bright pixels would otherwise set the scale (the room's lamp: 0.6% of
// the pixels, 35% of the mean).
std::vector<unsigned char> normaliserMask(const Measurement& m, std::vector<unsigned char> mask) {
  if (m.emission.pixels.size() != mask.size() * 4) return mask;
  for (size_t i = 0; i < mask.size(); ++i) {
    const float* e = &m.emission.pixels[i * 4];
    if (e[0] > 0.0f || e[1] > 0.0f || e[2] > 0.0f) mask[i] = 0;
  }
  return mask;
}

Scores score(const Measurement& m, const ReferenceSpec& spec, const Reference& reference,
             const Options& o, const std::string& scene) {
  const size_t n = size_t(o.width) * size_t(o.height);
  const std::vector<unsigned char> mask = comparedMask(m, reference, o);
  if (std::none_of(mask.begin(), mask.end(), [](unsigned char k) { return k; }))
    throw gi::Error(gi::ErrorKind::InvalidData, scene,
                    "no pixel is geometry in both the frame and the reference (an empty scene, or "
                    "a camera that sees nothing): there is nothing to score");
  const int w = int(o.width), h = int(o.height);
  const bool stdError = reference.stdError.pixels.size() == n * 4;
  Scores s;
  if (gi::bench::isAoLike(spec.quantity)) {
    const gi::bench::Plane noise = gi::bench::channel(w, h, reference.stdError.pixels, 0);
    s.metrics = gi::bench::compare(gi::bench::channel(w, h, m.out.pixels, 0),
                                   gi::bench::channel(w, h, reference.value.pixels, 0), mask, 1.0,
                                   nullptr, stdError ? &noise : nullptr);
    if (spec.quantity == ref::Quantity::AOSplit && reference.split.pixels.size() == n * 4)
      s.split = splitError(m.out, reference, mask);
  } else {
    const gi::bench::Plane test = gi::bench::channel(w, h, m.out.pixels, -1);
    const gi::bench::Plane truth = gi::bench::channel(w, h, reference.value.pixels, -1);
    // The luminance weights of the channels' standard errors: exact when the channels' errors
    // are fully correlated (one path lights all three), an upper bound otherwise.
    const gi::bench::Plane noise = gi::bench::channel(w, h, reference.stdError.pixels, -1);
    const std::vector<unsigned char> normalised = normaliserMask(m, mask);
    s.metrics =
        gi::bench::compare(test, truth, mask, 1.0, &normalised, stdError ? &noise : nullptr);
    s.metrics.ssim =
        gi::bench::ssim(gi::bench::reinhard(test), gi::bench::reinhard(truth), mask, 1.0);
  }
  return s;
}

std::vector<Row::RegionScore> regionScores(const Measurement& m, const ReferenceSpec& spec,
                                           const Reference& reference, const Options& o,
                                           const gi::Scene& scene) {
  std::vector<Row::RegionScore> out;
  if (scene.regions.empty()) return out;
  const int w = int(o.width), h = int(o.height);
  const size_t n = size_t(w) * size_t(h);
  // World positions of the reference's primary hits: the pixel centre's view ray, scaled to
  // the view-space z the reference stored (depth image, g), through the same camera.
  const gi::CameraView cam = gi::activeCamera(scene, float(w) / float(h));
  const glm::mat4 invProj = glm::inverse(cam.proj), invView = glm::inverse(cam.view);
  const bool orthographic = cam.proj[3][3] != 0.0f;
  std::vector<glm::vec3> world(n);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const size_t i = size_t(y) * size_t(w) + size_t(x);
      const float viewZ = reference.depth.pixels[i * 4 + 1];
      const glm::vec2 ndc((x + 0.5f) / float(w) * 2.0f - 1.0f, (y + 0.5f) / float(h) * 2.0f - 1.0f);
      glm::vec4 nearPoint = invProj * glm::vec4(ndc, 1.0f, 1.0f);
      glm::vec3 v = glm::vec3(nearPoint) / nearPoint.w;
      v = orthographic ? glm::vec3(v.x, v.y, viewZ) : v * (viewZ / v.z);
      world[i] = glm::vec3(invView * glm::vec4(v, 1.0f));
    }
  const std::vector<unsigned char> mask = comparedMask(m, reference, o);
  const bool aoLike = gi::bench::isAoLike(spec.quantity);
  const gi::bench::Plane test = gi::bench::channel(w, h, m.out.pixels, aoLike ? 0 : -1);
  const gi::bench::Plane truth = gi::bench::channel(w, h, reference.value.pixels, aoLike ? 0 : -1);
  for (const gi::SceneRegion& region : scene.regions) {
    std::vector<unsigned char> inside(n);
    for (size_t i = 0; i < n; ++i) inside[i] = mask[i] && region.contains(world[i]);
    Row::RegionScore r{region.name, 0.0, 0};
    if (std::any_of(inside.begin(), inside.end(), [](unsigned char k) { return k; })) {
      const std::vector<unsigned char> normalised = aoLike ? inside : normaliserMask(m, inside);
      const gi::bench::Metrics metrics = gi::bench::compare(test, truth, inside, 1.0, &normalised);
      r.nrmse = metrics.nrmse;
      r.pixels = metrics.pixels;
    }
    out.push_back(r);
  }
  return out;
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

}  // namespace gi_bench
