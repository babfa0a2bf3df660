// Environment lighting on the CPU: radiance lookup for every Environment kind, equirectangular
// HDR maps (.hdr via stb_image), importance sampling (2D CDF over the map weighted by luminance
// x sin(theta)) and SH9 irradiance (what lighting.comp evaluates for the ambient term).
//
// Equirect mapping (world space, +y up): u = atan2(d.z, d.x) / (2 pi) wrapped to [0, 1),
// v = acos(d.y) / pi; pixel (x, y) covers u in [x, x+1) / W, v in [y, y+1) / H (row 0 is up).
#pragma once

#include <array>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "gi/scene.h"

namespace gi {

constexpr float kPi = 3.14159265358979f;

// Loads an .hdr (Radiance RGBE) file into env (kind Map, mapRGB). Throws gi::Error:
// MissingResource when the file does not exist (naming it), Parse when stb cannot decode it.
void loadEnvironmentMap(Environment& env, const std::string& file);

glm::vec2 equirectUV(const glm::vec3& dir);  // dir need not be normalised
glm::vec3 equirectDirection(const glm::vec2& uv);

// Radiance arriving from world direction `dir` (times the environment's intensity): the
// procedural sky (as common.glsl), the constant colour or the bilinearly filtered map.
glm::vec3 environmentLookup(const Environment& env, const glm::vec3& dir);

// Nine SH coefficients (l <= 2, real basis, order Y00, Y1-1, Y10, Y11, Y2-2, Y2-1, Y20, Y21,
// Y22) of the *irradiance* E(n) = integral L(w) max(0, n.w) dw (the cosine lobe is already
// convolved in), so E(n) = sum c_i Y_i(n).
using SH9 = std::array<glm::vec3, 9>;
std::array<float, 9> shBasis(const glm::vec3& n);
// Sky and Constant environments as an equirect map: radiance at each texel centre, intensity
// NOT applied (like mapRGB). irradianceSH projects this map at kTabulatedWidth x Height.
constexpr int kTabulatedWidth = 128, kTabulatedHeight = 64;
std::vector<float> tabulateEnvironment(const Environment& env, int width, int height);
// Projects the environment (Sky and Constant are tabulated into a 128x64 map first).
SH9 irradianceSH(const Environment& env);
SH9 irradianceSHFromMap(int width, int height, const std::vector<float>& rgb, float intensity);
glm::vec3 evalIrradiance(const SH9& sh, const glm::vec3& n);

// Importance sampling of an equirect map proportional to luminance x sin(theta) (texels
// uniform inside; a black map falls back to uniform over the image).
class EnvironmentSampler {
 public:
  EnvironmentSampler(int width, int height, const std::vector<float>& rgb);
  explicit EnvironmentSampler(const Environment& env);  // env must be kind Map
  struct Sample {
    glm::vec3 direction;
    float pdf;  // per unit solid angle
    int pixel;  // y * width + x
  };
  Sample sample(float u1, float u2) const;  // u1, u2 uniform in [0, 1)
  float pdf(const glm::vec3& dir) const;    // per unit solid angle
  // Per unit solid angle, constant over texel (x, y); what sample() and pdf() return.
  float texelPdf(int x, int y) const;
  // cos(theta) of the top edge of row y (y = height: the bottom edge); sample() interpolates it.
  float rowCosTheta(int y) const;
  // The tables sample() searches, for uploading them to the GPU (gi::EnvironmentGpu).
  const std::vector<float>& marginalCdf() const { return marginal_; }
  const std::vector<float>& conditionalCdf() const { return conditional_; }
  int width() const { return width_; }
  int height() const { return height_; }

 private:
  int width_, height_;
  std::vector<float> marginal_;     // CDF over rows, height+1 entries
  std::vector<float> conditional_;  // CDF per row, height * (width+1)
  std::vector<float> pixelProb_;    // probability of each pixel
};

}  // namespace gi
