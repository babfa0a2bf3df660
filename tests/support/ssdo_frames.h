// Frames of SSDO's outputs with the camera they were rendered with (world positions from the
// depth, projections), and the flicker metric of tests/test_ssdo_dynamic.cpp.
#pragma once

#include <algorithm>
#include <cmath>
#include <utility>
#include <vector>

#include <glm/glm.hpp>

#include "gi/image_io.h"
#include "gi/renderer.h"
#include "gi/scene.h"

namespace gi::test {

// SSDO's `ambient` as the outgoing radiance the lighting pass adds: SSDO publishes it per unit
// diffuse albedo (alpha 2), and the lighting pass multiplies by albedo x (1 - metallic); this
// does the same with the G-buffer read back (albedo decoded from sRGB). Texels with alpha 1
// (already radiance) are kept.
inline ImageRGBA32F ssdoAmbientRadiance(Renderer& r) {
  ImageRGBA32F ambient = r.readTarget("ambient");
  const ImageRGBA32F albedo = r.readTarget("albedo"), material = r.readTarget("material");
  for (size_t i = 0; i + 3 < ambient.pixels.size(); i += 4) {
    if (!(ambient.pixels[i + 3] > 1.5f)) continue;
    const float metallic = material.pixels[i + 1];
    for (size_t c = 0; c < 3; ++c)
      ambient.pixels[i + c] *= albedo.pixels[i + c] * (1.0f - metallic);
    ambient.pixels[i + 3] = 1.0f;
  }
  return ambient;
}

struct SsdoFrame {
  SsdoFrame(ImageRGBA32F ambientIn, ImageRGBA32F indirectIn, ImageRGBA32F depthIn,
            const CameraView& cameraIn)
      : ambient(std::move(ambientIn)),
        indirect(std::move(indirectIn)),
        depth(std::move(depthIn)),
        camera(cameraIn),
        viewProj(cameraIn.proj * cameraIn.view),
        invViewProj(glm::inverse(viewProj)),
        w(depth.width),
        h(depth.height) {}
  ImageRGBA32F ambient, indirect, depth;
  CameraView camera;
  glm::mat4 viewProj, invViewProj;
  int w = 0, h = 0;

  float depthAt(int x, int y) const { return depth.pixels[(size_t(y) * size_t(w) + x) * 4]; }
  bool sky(int x, int y) const { return !(depthAt(x, y) > 0.0f); }  // reverse-Z: 0 far
  // Red + green + blue of `img` at (x, y).
  float sum(const ImageRGBA32F& img, int x, int y) const {
    const float* p = &img.pixels[(size_t(y) * size_t(w) + x) * 4];
    return p[0] + p[1] + p[2];
  }
  glm::vec3 worldAt(int x, int y) const {
    const glm::vec4 v = invViewProj * glm::vec4((x + 0.5f) / w * 2 - 1, (y + 0.5f) / h * 2 - 1,
                                                depthAt(x, y), 1.0f);
    return glm::vec3(v) / v.w;
  }
  // Pixel coordinates of `p` (pixel (x, y)'s centre at (x, y)) and its depth in .z.
  glm::vec3 projectWithDepth(const glm::vec3& p) const {
    const glm::vec4 q = viewProj * glm::vec4(p, 1.0f);
    return {(q.x / q.w + 1.0f) * 0.5f * float(w) - 0.5f,
            (q.y / q.w + 1.0f) * 0.5f * float(h) - 0.5f, q.z / q.w};
  }
  glm::vec2 project(const glm::vec3& p) const { return glm::vec2(projectWithDepth(p)); }
};

// Mean over consecutive frames of sum |A_k(p) - A_{k-1}(p')| / sum A_k(p), A = ambient (r + g
// + b), p' = p's surface point reprojected into frame k-1 (bilinear, where its four texels show
// the same surface: their bilinear reverse-Z depth, affine in screen space on a plane, is the
// point's within 0.2%, and each is within 5% of it). Not within 4 pixels of the
// border (there SSDO legitimately changes as off-screen occluders enter). `worst`: the largest
// pair; `coverage`: the mean fraction of geometry pixels compared.
struct Flicker {
  double mean = 0.0, worst = 0.0, coverage = 0.0;
};
// Flicker bound for a slow camera path (tests/test_ssdo_dynamic.cpp states the measurements).
inline constexpr double kFlickerBound = 0.015;

inline Flicker flicker(const std::vector<SsdoFrame>& frames) {
  constexpr int kBorder = 4;
  Flicker f;
  int pairs = 0;
  for (size_t k = 1; k < frames.size(); ++k) {
    const SsdoFrame &prev = frames[k - 1], &cur = frames[k];
    double change = 0.0, total = 0.0;
    size_t compared = 0, geometry = 0;
    for (int y = kBorder; y < cur.h - kBorder; ++y)
      for (int x = kBorder; x < cur.w - kBorder; ++x) {
        if (cur.sky(x, y)) continue;
        ++geometry;
        const glm::vec3 q = prev.projectWithDepth(cur.worldAt(x, y));
        if (!std::isfinite(q.x) || !std::isfinite(q.y) || !(q.z > 0.0f)) continue;
        const int x0 = int(std::floor(q.x)), y0 = int(std::floor(q.y));
        if (x0 < kBorder || y0 < kBorder || x0 + 1 >= prev.w - kBorder ||
            y0 + 1 >= prev.h - kBorder)
          continue;
        const float fx = q.x - float(x0), fy = q.y - float(y0);
        bool same = true;
        float value = 0.0f, depth = 0.0f;
        for (int j = 0; j < 4; ++j) {
          const int tx = x0 + (j & 1), ty = y0 + (j >> 1);
          const float d = prev.depthAt(tx, ty);
          const float wgt = ((j & 1) ? fx : 1.0f - fx) * ((j >> 1) ? fy : 1.0f - fy);
          same = same && d > 0.0f && std::abs(d - q.z) <= 0.05f * q.z;
          value += wgt * prev.sum(prev.ambient, tx, ty);
          depth += wgt * d;
        }
        if (!same || std::abs(depth - q.z) > 0.002f * q.z) continue;
        const float now = cur.sum(cur.ambient, x, y);
        change += std::abs(now - value);
        total += now;
        ++compared;
      }
    const double pair = total > 0.0 ? change / total : 0.0;
    f.mean += pair;
    f.worst = std::max(f.worst, pair);
    f.coverage += geometry > 0 ? double(compared) / double(geometry) : 0.0;
    ++pairs;
  }
  if (pairs > 0) {
    f.mean /= pairs;
    f.coverage /= pairs;
  }
  return f;
}

}  // namespace gi::test
