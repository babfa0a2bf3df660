// Analytic scenes of quads for the screen-space AO tests (test_ssao, test_horizon_ao, ...): a
// quad mesh, a scene of transformed quads with a camera, the 90-degree corner (floor + wall),
// and helpers on rendered images (AoFrame: an AO image read back with its depth and camera).
#pragma once

#include <algorithm>
#include <cmath>
#include <fstream>
#include <string>
#include <utility>
#include <vector>

#include <glm/gtc/matrix_transform.hpp>

#include "gi/image_io.h"
#include "gi/scene.h"
#include "gi/scene_io.h"

namespace gi::test {

inline Mesh quad(float half) {
  Mesh m;
  m.name = "quad";
  for (auto [x, y] : {std::pair{-1.f, -1.f}, {1.f, -1.f}, {1.f, 1.f}, {-1.f, 1.f}})
    m.vertices.push_back({glm::vec3(x * half, y * half, 0), glm::vec3(0, 0, 1), glm::vec2(0)});
  m.indices = {0, 1, 2, 0, 2, 3};
  m.boundsMin = glm::vec3(-half, -half, 0);
  m.boundsMax = glm::vec3(half, half, 0);
  m.triangleAreas = {2 * half * half, 2 * half * half};
  return m;
}

// Quads: world transform (the quad faces local +z) and half size.
using Quads = std::vector<std::pair<glm::mat4, float>>;

// Scene of quads (material 0, the default material) and a camera looking from `eye` at
// `target`. `scale` multiplies every length (scale-invariance test).
inline Scene quadScene(const Quads& quads, glm::vec3 eye, glm::vec3 target, float scale = 1.0f,
                       float znear = 0.05f, float zfar = 100.0f, float yfov = glm::radians(60.0f)) {
  Scene s;
  s.materials.push_back(Material{});
  const glm::mat4 S = glm::scale(glm::mat4(1.0f), glm::vec3(scale));
  for (const auto& [transform, half] : quads) {
    s.meshes.push_back(quad(half));
    int n = s.addNode("quad", S * transform);
    s.nodes[n].meshes = {int(s.meshes.size()) - 1};
  }
  Camera cam;
  cam.yfov = yfov;
  cam.znear = znear * scale;
  cam.zfar = zfar * scale;
  s.cameras.push_back(cam);
  int c = s.addNode("camera",
                    glm::inverse(glm::lookAt(eye * scale, target * scale, glm::vec3(0, 1, 0))));
  s.nodes[c].camera = 0;
  s.activeCameraNode = c;
  s.updateWorldTransforms();
  return s;
}

// The floor y = 0 facing +y (a quad of half size `half`).
inline glm::mat4 floorTransform() {
  return glm::rotate(glm::mat4(1.0f), glm::radians(-90.0f), glm::vec3(1, 0, 0));
}

// A floor (y = 0, facing +y) and a wall (x = 0, facing +x): a 90-degree concave corner.
inline Quads cornerQuads() {
  const glm::mat4 wall = glm::rotate(glm::mat4(1.0f), glm::radians(90.0f), glm::vec3(0, 1, 0));
  return {{floorTransform(), 20.0f}, {wall, 20.0f}};
}
inline Scene cornerScene(float scale = 1.0f, float yfov = glm::radians(60.0f)) {
  return quadScene(cornerQuads(), glm::vec3(2.5f, 1.6f, 0.0f), glm::vec3(0.0f), scale, 0.05f,
                   100.0f, yfov);
}

// The corner seen in the hard cases screen-space effects must survive: the eye 1e-3 above the
// floor (grazing), near 1e-4 / far 1e5, and looking up into the sky with those planes.
struct HardCornerView {
  glm::vec3 eye, target;
  float znear, zfar;
  Scene scene() const { return quadScene(cornerQuads(), eye, target, 1.0f, znear, zfar); }
};
inline std::vector<HardCornerView> hardCornerViews() {
  return {{{6, 1e-3f, 0.5f}, {0, 0, 0.5f}, 0.05f, 100.0f},
          {{2.5f, 1.6f, 0}, {0, 0, 0}, 1e-4f, 1e5f},
          {{2.5f, 0.3f, 0}, {0, 3, 0}, 1e-4f, 1e5f}};
}

// The outline case: a tessellated sphere of radius 0.4 (48 x 24), scaled by `scale` (JSON: "1",
// or "[0.1, 2, 0.1]" for a thin vertical "cylinder"), 4 units (8 radii of 0.5) in front of a
// wall, the camera at z = 3: convex objects, AO 1 everywhere on them. Written as a scene file
// to `path` (primitives are a scene file's) and loaded.
inline Scene outlineScene(const std::string& scale, const std::string& path) {
  {
    std::ofstream f(path);
    f << R"({
      "models": [
        { "primitive": "plane", "size": 40, "rotation": [90, 0, 0], "translation": [0, 0, -4] },
        { "primitive": "sphere", "radius": 0.4, "segments": 48, "rings": 24, "scale": )"
      << scale << R"( } ],
      "camera": { "position": [0, 0, 3], "target": [0, 0, 0], "yfov_deg": 45 } })";
  }
  return loadSceneJson(path);
}

// The depth-discontinuity case: a wall at z = 0 and, 3 units in front of it, an open book (two
// 0.4-wide quads meeting at 90 degrees, opening toward a camera at z = 6): dark inside, up to
// its outline, while nothing darkens the wall 3 units behind.
inline Quads openBookQuads() {
  const glm::mat4 at = glm::translate(glm::mat4(1.0f), glm::vec3(0, 0, 3));
  const glm::mat4 left = at *
                         glm::rotate(glm::mat4(1.0f), glm::radians(-45.0f), glm::vec3(0, 1, 0)) *
                         glm::translate(glm::mat4(1.0f), glm::vec3(0.2f, 0, 0));
  const glm::mat4 right = at *
                          glm::rotate(glm::mat4(1.0f), glm::radians(45.0f), glm::vec3(0, 1, 0)) *
                          glm::translate(glm::mat4(1.0f), glm::vec3(-0.2f, 0, 0));
  return {{glm::mat4(1.0f), 10.0f}, {left, 0.2f}, {right, 0.2f}};
}
inline const glm::vec3 kOpenBookEye(0, 0, 6);

// The pixels of an open-book image within 3 px of a pixel of the other kind (wall vs book),
// away from the border: each wall pixel with its value, and the book pixels' count and darkest
// value. `r` has w, h, at(x, y) and worldAt(x, y).
struct BookOutline {
  std::vector<std::pair<glm::ivec2, float>> wall;
  int pages = 0;
  float darkestPage = 1.0f;
};
BookOutline bookOutline(const auto& r) {
  auto onWall = [&](int x, int y) { return std::abs(r.worldAt(x, y).z) < 1e-3f; };
  auto nearOther = [&](int x, int y, bool wall) {
    for (int j = -3; j <= 3; ++j)
      for (int i = -3; i <= 3; ++i)
        if (onWall(x + i, y + j) != wall) return true;
    return false;
  };
  BookOutline o;
  for (int y = 3; y < r.h - 3; ++y)
    for (int x = 3; x < r.w - 3; ++x) {
      const bool wall = onWall(x, y);
      if (!nearOther(x, y, wall)) continue;
      if (wall) {
        o.wall.push_back({{x, y}, r.at(x, y)});
      } else {
        ++o.pages;
        o.darkestPage = std::min(o.darkestPage, r.at(x, y));
      }
    }
  return o;
}

inline bool finite(const ImageRGBA32F& img) {
  for (float v : img.pixels)
    if (!std::isfinite(v)) return false;
  return true;
}

// A frame of an AO effect read back: "ao" (the value in red), "depth" and the camera, w x h
// pixels, with the look-ups of the helpers here (bookOutline, cornerLinePixels, patternEnergy).
struct AoFrame {
  ImageRGBA32F ao, depth;
  CameraView camera;
  int w = 0, h = 0;
  float at(int x, int y) const { return ao.pixels[(size_t(y) * w + x) * 4]; }
  float depthAt(int x, int y) const { return depth.pixels[(size_t(y) * w + x) * 4]; }
  bool sky(int x, int y) const { return depthAt(x, y) <= 0.0f; }  // reverse-Z: 0 is far
  glm::vec3 viewAt(int x, int y) const {  // view-space position of the pixel's centre
    glm::vec4 v = glm::inverse(camera.proj) *
                  glm::vec4((x + 0.5f) / w * 2 - 1, (y + 0.5f) / h * 2 - 1, depthAt(x, y), 1.0f);
    return glm::vec3(v) / v.w;
  }
  glm::vec3 worldAt(int x, int y) const {
    return glm::vec3(glm::inverse(camera.view) * glm::vec4(viewAt(x, y), 1.0f));
  }
};

// Floor pixels of the corner scene in the 4 rows nearest to the line x = d (every 4x4 phase
// of the interleave pattern is present), away from the image border. `r` has w, h and
// worldAt(x, y).
std::vector<glm::ivec2> cornerLinePixels(const auto& r, float d) {
  int bestRow = -1;
  float bestErr = 1e9f;
  for (int y = 8; y < r.h - 8; ++y) {
    glm::vec3 p = r.worldAt(r.w / 2, y);
    if (std::abs(p.y) < 1e-3f && std::abs(p.x - d) < bestErr)
      bestErr = std::abs(p.x - d), bestRow = y;
  }
  std::vector<glm::ivec2> pixels;
  for (int y = bestRow - 1; y <= bestRow + 2; ++y)
    for (int x = r.w / 2 - 16; x < r.w / 2 + 16; ++x)
      if (std::abs(r.worldAt(x, y).y) < 1e-3f) pixels.push_back({x, y});
  return pixels;
}

// Energy of the 4x4 interleave pattern on the corner's floor between x = minX and maxX,
// insensitive to the AO's smooth variation: the corner scene's camera has no roll and looks
// along -x, so image rows are lines of constant distance to the wall. Along x: residual from a
// straight-line fit per row; along y: second differences of the row means (a linear trend
// cancels).
inline double patternEnergy(const AoFrame& r, float minX, float maxX) {
  double ex = 0.0, ey = 0.0;
  int nx = 0, ny = 0;
  std::vector<double> rowMeans;
  const int x0 = r.w / 2 - 32, x1 = r.w / 2 + 32;
  for (int y = 0; y < r.h; ++y) {
    const glm::vec3 c = r.worldAt(r.w / 2, y);
    if (std::abs(c.y) > 1e-3f || c.x < minX || c.x > maxX) continue;
    double sx = 0, sy = 0, sxx = 0, sxy = 0;
    const int n = x1 - x0;
    for (int x = x0; x < x1; ++x)
      sx += x, sy += r.at(x, y), sxx += double(x) * x, sxy += double(x) * r.at(x, y);
    const double slope = (n * sxy - sx * sy) / (n * sxx - sx * sx), icept = (sy - slope * sx) / n;
    for (int x = x0; x < x1; ++x, ++nx) ex += std::pow(r.at(x, y) - (icept + slope * x), 2);
    rowMeans.push_back(sy / n);
  }
  for (size_t i = 1; i + 1 < rowMeans.size(); ++i, ++ny)
    ey += std::pow(rowMeans[i] - 0.5 * (rowMeans[i - 1] + rowMeans[i + 1]), 2);
  return (nx ? ex / nx : 0.0) + (ny ? ey / ny : 0.0);
}

}  // namespace gi::test
