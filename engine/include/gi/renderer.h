// The built-in frame: G-buffer -> direct lighting -> tonemap, plus the floor pass used as the
// cost baseline. Renders headless into offscreen targets that can be read back.
#pragma once

#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "gi/image_io.h"
#include "gi/scene.h"
#include "gi/vk/context.h"

namespace gi {

struct RenderSettings {
  uint32_t width = 640, height = 480;
  float exposure = 1.0f;
  bool floorPass = false;  // also run the floor pass (for timing baselines)
};

// Offscreen targets that can be read back (tests, debug views).
enum class Target { Depth, Normal, Albedo, Material, Emission, Motion, Lit, Output, Floor };

struct PassTiming {
  std::string name;
  double ms = 0.0;
};

class Renderer {
 public:
  Renderer(vk::Context& ctx, const Scene& scene, const RenderSettings& settings);
  ~Renderer();
  Renderer(const Renderer&) = delete;
  Renderer& operator=(const Renderer&) = delete;

  // Records, submits and waits for one frame; per-pass GPU times end up in lastTimings().
  void renderFrame();
  const std::vector<PassTiming>& lastTimings() const;
  std::vector<std::string> passNames() const;  // passes the last frame executed, in order

  ImageRGBA8 readOutput();                 // tonemapped 8-bit image
  ImageRGBA32F readTarget(Target target);  // any target as float RGBA (depth in r)
  const CameraView& camera() const;
  // The tonemapped RGBA8 image; after renderFrame() it is in VK_IMAGE_LAYOUT_GENERAL and all
  // writes are complete (a presenter copies it into a swapchain image).
  VkImage outputImage() const;
  VkExtent2D outputExtent() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace gi
