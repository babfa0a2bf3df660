#include "preview.h"

#include <algorithm>
#include <cmath>
#include <cstdint>

#include "gi/effect.h"

namespace gi::app {

namespace {

bool oneChannel(const std::string& view) {
  return view == resources::kDepth || view == resources::kAO;
}

}  // namespace

ImageRGBA32F definedChannels(ImageRGBA32F image, const std::string& view) {
  if (!oneChannel(view)) return image;
  for (size_t i = 0; i + 3 < image.pixels.size(); i += 4) {
    image.pixels[i + 1] = image.pixels[i + 2] = image.pixels[i];
    image.pixels[i + 3] = 1.0f;
  }
  return image;
}

ImageRGBA8 previewOf(const ImageRGBA32F& img, const std::string& view) {
  const bool signedData = view == resources::kNormal || view == resources::kMotion;
  const bool grey = oneChannel(view);
  ImageRGBA8 out{img.width, img.height, std::vector<uint8_t>(img.pixels.size())};
  for (size_t i = 0; i < img.pixels.size(); ++i) {
    const bool alpha = i % 4 == 3;
    float v = grey ? img.pixels[i - i % 4] : img.pixels[i];
    if (signedData) v = v * 0.5f + 0.5f;
    if (alpha) v = 1.0f;
    if (!std::isfinite(v)) v = 0.0f;
    out.pixels[i] = uint8_t(std::lround(std::clamp(v, 0.0f, 1.0f) * 255.0f));
  }
  return out;
}

}  // namespace gi::app
