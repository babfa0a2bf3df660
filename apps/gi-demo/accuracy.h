// Accuracy on demand: the current frame rendered by the CPU reference renderer
// (gi/reference/reference.h) on a background thread, for the quantity an effect declares it
// estimates with its current settings (Effect::estimatedQuantity, as gi-bench), compared with
// the effect's image of that same frame: NRMSE over the pixels that are geometry in both, and
// an error image.
#pragma once

#include <atomic>
#include <mutex>
#include <optional>
#include <string>
#include <thread>

#include "gi/effect_registry.h"
#include "gi/image_io.h"
#include "gi/renderer.h"
#include "gi/scene.h"

namespace demo {

struct AccuracyResult {
  std::string effect, quantity;  // quantity: gi-bench's label, e.g. "ao r=0.5"
  double nrmse = 0.0;
  size_t pixels = 0;  // geometry in both images
  uint32_t spp = 0;
  double seconds = 0.0;
  // |effect - reference| / mean reference, x2, as grey in [0, 1]; blue where not compared.
  gi::ImageRGBA8 error;
  // Light quantities: what the effect recovers of what the engine alone misses (as gi-bench):
  // the engine alone's NRMSE on the same frame and the share of it removed, 1 - NRMSE /
  // that; against direct + indirect also the share of the reference's indirect light
  // (direct+indirect - direct reference) the effect adds to the engine alone's image.
  bool recovered = false, indirect = false;
  double aloneNrmse = 0.0, errorRemoved = 0.0, indirectDelivered = 0.0;
};

class AccuracyCheck {
 public:
  AccuracyCheck() = default;
  ~AccuracyCheck();
  AccuracyCheck(const AccuracyCheck&) = delete;
  AccuracyCheck& operator=(const AccuracyCheck&) = delete;

  // Keeps the renderer's current image of the effect's quantity (call after renderFrame) and
  // starts the reference of `scene` posed at `time`, seen by the renderer's camera, at the
  // renderer's size, with at most `spp` samples per pixel. For a light quantity it also
  // renders the same frame with no effect (a renderer of its own on `ctx`) and, against
  // direct + indirect, the direct reference too. Throws gi::Error when the effect is unknown
  // or its quantity's image is not in the frame; a check already running is abandoned
  // (waited for).
  void start(gi::vk::Context& ctx, gi::Renderer& renderer, const gi::Scene& scene, double time,
             const gi::EffectRegistry& registry, const std::string& effect,
             const gi::SettingValues& settings, uint32_t spp);
  bool running() const { return thread_.joinable() && !done_; }
  float progress() const;  // samples per pixel reached / asked, in [0, 1]
  // Collects a finished check (joins the thread); the last result stays until the next start.
  void poll();
  void wait();
  const std::optional<AccuracyResult>& result() const { return result_; }
  const std::string& error() const { return error_; }  // why the last check failed

 private:
  void finish();

  std::thread thread_;
  std::atomic<bool> done_{false};
  std::atomic<uint32_t> sppReached_{0};
  uint32_t sppAsked_ = 1;
  std::optional<AccuracyResult> result_;
  std::string error_;
  // Handed from the thread to finish().
  std::mutex mutex_;
  std::string threadError_;
  struct Pending;
  std::shared_ptr<Pending> pending_;
};

}  // namespace demo
