#include "accuracy.h"

#include <algorithm>
#include <cmath>

#include "gi/errors.h"
#include "gi/reference/reference.h"
#include "metrics.h"
#include "quantity.h"

namespace demo {

namespace ref = gi::reference;

struct AccuracyCheck::Pending {
  gi::Scene scene;  // posed copy with the renderer's camera
  ref::Settings settings;
  gi::ImageRGBA32F test, depth;
  gi::ImageRGBA32F alone;  // light quantities: the same frame with no effect
  bool aoLike = false;
  bool indirect = false;  // the quantity is direct + indirect: the direct reference too
  std::string effect, label;
  ref::Result reference, direct;
};

AccuracyCheck::~AccuracyCheck() {
  if (thread_.joinable()) thread_.join();
}

float AccuracyCheck::progress() const {
  return std::clamp(float(sppReached_) / float(std::max(sppAsked_, 1u)), 0.0f, 1.0f);
}

void AccuracyCheck::start(gi::vk::Context& ctx, gi::Renderer& renderer, const gi::Scene& scene,
                          double time, const gi::EffectRegistry& registry,
                          const std::string& effect, const gi::SettingValues& settings,
                          uint32_t spp) {
  wait();
  auto p = std::make_shared<Pending>();
  const gi::bench::ReferenceSpec spec =
      gi::bench::declaredSpec(registry.create(effect)->estimatedQuantity(settings));
  p->aoLike = gi::bench::isAoLike(spec.quantity);
  p->effect = effect;
  p->label = gi::bench::label(spec);
  // The frame as it is now: the effect's image and the depth that says where geometry is.
  p->test = renderer.readTarget(p->aoLike ? gi::resources::kAO : gi::resources::kLit);
  p->depth = renderer.readTarget(gi::resources::kDepth);
  const VkExtent2D size = renderer.outputExtent();
  if (p->test.width != int(size.width) || p->test.height != int(size.height))
    throw gi::Error(gi::ErrorKind::Unsupported, "",
                    "accuracy: " + effect + "'s image is not at the output's size");

  if (!p->aoLike) {
    // The engine alone on the same frame: its settings, no effect, the same clock and camera.
    gi::RenderSettings alone = renderer.settings();
    alone.effects.clear();
    alone.width = size.width;
    alone.height = size.height;
    alone.view = gi::resources::kLit;
    gi::Renderer engine(ctx, scene, alone, &registry);
    engine.setTime(time);
    engine.setCameraOverride(renderer.camera());
    engine.renderFrame();
    p->alone = engine.readTarget(gi::resources::kLit);
    p->indirect = spec.quantity == ref::Quantity::DirectIndirect;
  }

  // The scene posed at the clock, seen by the renderer's camera (a camera node of its own).
  p->scene = scene;
  p->scene.animate(time);
  const gi::CameraView& cam = renderer.camera();
  gi::Camera c;
  c.name = "gi-demo view";
  c.yfov = cam.yfov;
  c.znear = cam.znear;
  c.zfar = cam.zfar;
  p->scene.cameras.push_back(c);
  const int node = p->scene.addNode("gi-demo view", glm::inverse(cam.view));
  p->scene.nodes[node].camera = int(p->scene.cameras.size()) - 1;
  p->scene.activeCameraNode = node;
  p->scene.updateWorldTransforms();

  p->settings.width = size.width;
  p->settings.height = size.height;
  p->settings.spp = std::max(spp, 1u);
  p->settings.minSpp = std::min(16u, p->settings.spp);
  // Leave a core to the window.
  p->settings.threads = std::max(1u, std::thread::hardware_concurrency() - 1);
  gi::bench::apply(spec, p->settings);
  p->settings.progress = [this](const ref::Progress& pr) { sppReached_ = pr.spp; };

  sppAsked_ = p->settings.spp;
  sppReached_ = 0;
  done_ = false;
  error_.clear();
  threadError_.clear();
  pending_ = p;
  thread_ = std::thread([this, p] {
    try {
      p->reference = ref::render(p->scene, p->settings);
      if (p->indirect) {
        ref::Settings direct = p->settings;
        direct.quantity = ref::Quantity::Direct;
        p->direct = ref::render(p->scene, direct);
      }
    } catch (const std::exception& e) {
      std::lock_guard<std::mutex> lock(mutex_);
      threadError_ = e.what();
    }
    done_ = true;
  });
}

void AccuracyCheck::poll() {
  if (thread_.joinable() && done_) finish();
}

void AccuracyCheck::wait() {
  if (thread_.joinable()) finish();
}

void AccuracyCheck::finish() {
  thread_.join();
  std::shared_ptr<Pending> p = std::move(pending_);
  {
    std::lock_guard<std::mutex> lock(mutex_);
    error_ = threadError_;
  }
  if (!error_.empty() || !p) return;
  const int w = p->test.width, h = p->test.height;
  const size_t n = size_t(w) * size_t(h);
  const ref::Result& r = p->reference;
  std::vector<unsigned char> mask(n);
  for (size_t i = 0; i < n; ++i)
    mask[i] = r.depth.pixels[i * 4 + 2] > 0.5f && p->depth.pixels[i * 4] > 0.0f;
  if (std::find(mask.begin(), mask.end(), 1) == mask.end()) {
    // As gi-bench: an empty comparison is not a perfect score.
    error_ =
        "no pixel is geometry in both the frame and the reference (the camera sees only "
        "sky): there is nothing to score";
    return;
  }
  const int c = p->aoLike ? 0 : -1;  // AO-like: the scalar; lighting: luminance
  const gi::bench::Plane test = gi::bench::channel(w, h, p->test.pixels, c);
  const gi::bench::Plane truth = gi::bench::channel(w, h, r.value.pixels, c);
  AccuracyResult out;
  out.effect = p->effect;
  out.quantity = p->label;
  out.nrmse = gi::bench::nrmse(test, truth, mask);
  if (p->alone.pixels.size() == p->test.pixels.size()) {
    const gi::bench::Plane alone = gi::bench::channel(w, h, p->alone.pixels, c);
    out.recovered = true;
    out.aloneNrmse = gi::bench::nrmse(alone, truth, mask);
    out.errorRemoved = out.aloneNrmse > 0.0 ? 1.0 - out.nrmse / out.aloneNrmse : 0.0;
    if (p->direct.value.pixels.size() == r.value.pixels.size()) {
      const gi::bench::Plane direct = gi::bench::channel(w, h, p->direct.value.pixels, c);
      const double missing = gi::bench::mean(truth, mask) - gi::bench::mean(direct, mask);
      if (missing > 1e-9) {
        out.indirect = true;
        out.indirectDelivered =
            (gi::bench::mean(test, mask) - gi::bench::mean(alone, mask)) / missing;
      }
    }
  }
  out.pixels = size_t(std::count(mask.begin(), mask.end(), 1));
  out.spp = r.spp;
  out.seconds = r.seconds;
  double mean = 0.0;
  for (size_t i = 0; i < n; ++i)
    if (mask[i]) mean += std::abs(truth.values[i]);
  mean = out.pixels > 0 && mean > 0.0 ? mean / double(out.pixels) : 1.0;
  out.error = {w, h, std::vector<uint8_t>(n * 4, 255)};
  for (size_t i = 0; i < n; ++i) {
    uint8_t* px = &out.error.pixels[i * 4];
    if (!mask[i]) {
      px[0] = 20, px[1] = 30, px[2] = 90;
      continue;
    }
    const double e = std::abs(double(test.values[i]) - truth.values[i]) / mean * 2.0;
    const uint8_t v =
        uint8_t(std::lround(std::clamp(std::isfinite(e) ? e : 1.0, 0.0, 1.0) * 255.0));
    px[0] = px[1] = px[2] = v;
  }
  result_ = std::move(out);
}

}  // namespace demo
