#include "gi/environment.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <limits>

#include <stb_image.h>

#include "gi/errors.h"
#include "gi/input_file.h"

namespace gi {

namespace {

float luminance(const glm::vec3& c) {
  return 0.2126f * c.r + 0.7152f * c.g + 0.0722f * c.b;
}

glm::vec3 texel(const Environment& env, int x, int y) {
  x = ((x % env.mapWidth) + env.mapWidth) % env.mapWidth;
  y = std::clamp(y, 0, env.mapHeight - 1);
  const float* p = &env.mapRGB[(size_t(y) * env.mapWidth + x) * 3];
  return {p[0], p[1], p[2]};
}

// Solid angle of one texel of row y (exact: the row's band of the sphere split in W). The
// product form of cos(t0) - cos(t1) keeps pole rows of tall maps > 0 where the difference of
// two cosines near 1 would round to 0 (and the pdf to inf).
float texelSolidAngle(int y, int width, int height) {
  const float t0 = kPi * float(y) / float(height), t1 = kPi * float(y + 1) / float(height);
  return 2.0f * kPi / float(width) *
         (2.0f * std::sin(0.5f * (t0 + t1)) * std::sin(0.5f * (t1 - t0)));
}

// First index i with cdf[i + 1] > u (cdf ascending, cdf[0] = 0, cdf.back() = 1).
int searchCdf(const float* cdf, int n, float u) {
  const float* it = std::upper_bound(cdf + 1, cdf + n + 1, u);
  return std::clamp(int(it - cdf) - 1, 0, n - 1);
}

}  // namespace

std::vector<float> tabulateEnvironment(const Environment& env, int w, int h) {
  w = std::max(w, 1);
  h = std::max(h, 1);
  std::vector<float> rgb(size_t(w) * h * 3);
  Environment unit = env;
  unit.intensity = 1.0f;
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const glm::vec3 c = environmentLookup(
          unit, equirectDirection({(x + 0.5f) / float(w), (y + 0.5f) / float(h)}));
      for (int k = 0; k < 3; ++k) rgb[(size_t(y) * w + x) * 3 + k] = c[k];
    }
  return rgb;
}

void loadEnvironmentMap(Environment& env, const std::string& file) {
  std::error_code ec;
  if (!std::filesystem::exists(file, ec))
    throw Error(ErrorKind::MissingResource, file, "environment map '" + file + "' does not exist");
  // Read through the checked reader (regular files only, bounded), then decode from memory.
  const std::string bytes = readInputFile(file, "environment map");
  if (bytes.size() > size_t(std::numeric_limits<int>::max()))
    throw Error(ErrorKind::Unsupported, file, "environment maps larger than 2 GiB are not read");
  int w = 0, h = 0, n = 0;
  float* data = stbi_loadf_from_memory(reinterpret_cast<const stbi_uc*>(bytes.data()),
                                       int(bytes.size()), &w, &h, &n, 3);
  if (!data || w <= 0 || h <= 0) {
    if (data) stbi_image_free(data);
    throw Error(ErrorKind::Parse, file,
                std::string("cannot decode environment map: ") +
                    (stbi_failure_reason() ? stbi_failure_reason() : "unknown error"));
  }
  env.kind = Environment::Kind::Map;
  env.file = file;
  env.mapWidth = w;
  env.mapHeight = h;
  env.mapRGB.assign(data, data + size_t(w) * h * 3);
  stbi_image_free(data);
  for (float& v : env.mapRGB)
    if (!std::isfinite(v) || v < 0.0f) v = 0.0f;  // guard: radiance is finite, non-negative
}

glm::vec2 equirectUV(const glm::vec3& d) {
  const float len = glm::length(d);
  const glm::vec3 n = len > 1e-30f && std::isfinite(len) ? d / len : glm::vec3(0, 1, 0);
  float u = std::atan2(n.z, n.x) / (2.0f * kPi);
  if (u < 0.0f) u += 1.0f;
  const float v = std::acos(std::clamp(n.y, -1.0f, 1.0f)) / kPi;
  return {std::min(u, 0.99999994f), v};
}

glm::vec3 equirectDirection(const glm::vec2& uv) {
  const float phi = uv.x * 2.0f * kPi, theta = uv.y * kPi;
  const float s = std::sin(theta);
  return {s * std::cos(phi), std::cos(theta), s * std::sin(phi)};
}

glm::vec3 environmentLookup(const Environment& env, const glm::vec3& dir) {
  const float intensity = std::max(env.intensity, 0.0f);
  if (env.kind == Environment::Kind::Constant) return env.constantColor * intensity;
  if (env.kind == Environment::Kind::Map) {
    if (env.mapWidth <= 0 || env.mapHeight <= 0 ||
        env.mapRGB.size() != size_t(env.mapWidth) * env.mapHeight * 3)
      return glm::vec3(0.0f);
    const glm::vec2 uv = equirectUV(dir);
    const float fx = uv.x * env.mapWidth - 0.5f, fy = uv.y * env.mapHeight - 0.5f;
    const int x0 = int(std::floor(fx)), y0 = int(std::floor(fy));
    const float ax = fx - float(x0), ay = fy - float(y0);
    const glm::vec3 top = glm::mix(texel(env, x0, y0), texel(env, x0 + 1, y0), ax);
    const glm::vec3 bottom = glm::mix(texel(env, x0, y0 + 1), texel(env, x0 + 1, y0 + 1), ax);
    return glm::mix(top, bottom, ay) * intensity;
  }
  const float y = std::isfinite(dir.y) ? std::clamp(dir.y, -1.0f, 1.0f) : 0.0f;
  const glm::vec3 c = y >= 0.0f ? glm::mix(env.horizonColor, env.zenithColor, std::sqrt(y))
                                : glm::mix(env.horizonColor, env.groundColor, std::sqrt(-y));
  return c * intensity;
}

std::array<float, 9> shBasis(const glm::vec3& n) {
  return {0.282095f,
          0.488603f * n.y,
          0.488603f * n.z,
          0.488603f * n.x,
          1.092548f * n.x * n.y,
          1.092548f * n.y * n.z,
          0.315392f * (3.0f * n.z * n.z - 1.0f),
          1.092548f * n.x * n.z,
          0.546274f * (n.x * n.x - n.y * n.y)};
}

SH9 irradianceSHFromMap(int width, int height, const std::vector<float>& rgb, float intensity) {
  SH9 sh{};
  if (width <= 0 || height <= 0 || rgb.size() != size_t(width) * height * 3) return sh;
  for (int y = 0; y < height; ++y) {
    const float dw = texelSolidAngle(y, width, height);
    for (int x = 0; x < width; ++x) {
      const glm::vec3 d =
          equirectDirection({(x + 0.5f) / float(width), (y + 0.5f) / float(height)});
      const float* p = &rgb[(size_t(y) * width + x) * 3];
      const glm::vec3 L(p[0], p[1], p[2]);
      const std::array<float, 9> b = shBasis(d);
      for (int i = 0; i < 9; ++i) sh[i] += L * (b[i] * dw);
    }
  }
  // Convolution with the clamped cosine: A0 = pi, A1 = 2pi/3, A2 = pi/4.
  const float band[9] = {kPi,     2 * kPi / 3, 2 * kPi / 3, 2 * kPi / 3, kPi / 4,
                         kPi / 4, kPi / 4,     kPi / 4,     kPi / 4};
  for (int i = 0; i < 9; ++i) sh[i] *= band[i] * std::max(intensity, 0.0f);
  return sh;
}

SH9 irradianceSH(const Environment& env) {
  if (env.kind == Environment::Kind::Map)
    return irradianceSHFromMap(env.mapWidth, env.mapHeight, env.mapRGB, env.intensity);
  return irradianceSHFromMap(kTabulatedWidth, kTabulatedHeight,
                             tabulateEnvironment(env, kTabulatedWidth, kTabulatedHeight),
                             env.intensity);
}

glm::vec3 evalIrradiance(const SH9& sh, const glm::vec3& n) {
  const std::array<float, 9> b = shBasis(n);
  glm::vec3 e(0.0f);
  for (int i = 0; i < 9; ++i) e += sh[i] * b[i];
  return glm::max(e, glm::vec3(0.0f));
}

EnvironmentSampler::EnvironmentSampler(const Environment& env)
    : EnvironmentSampler(env.mapWidth, env.mapHeight, env.mapRGB) {}

EnvironmentSampler::EnvironmentSampler(int width, int height, const std::vector<float>& rgb)
    : width_(std::max(width, 1)), height_(std::max(height, 1)) {
  const bool valid = width > 0 && height > 0 && rgb.size() == size_t(width) * height * 3;
  const size_t n = size_t(width_) * height_;
  std::vector<double> weight(n, 0.0);
  double total = 0.0;
  for (int y = 0; y < height_; ++y) {
    // sin(theta) x texel area, exactly: the texel's solid angle.
    const double dw = texelSolidAngle(y, width_, height_);
    for (int x = 0; x < width_; ++x) {
      const size_t i = size_t(y) * width_ + x;
      const float lum = valid ? luminance({rgb[i * 3], rgb[i * 3 + 1], rgb[i * 3 + 2]}) : 0.0f;
      weight[i] = (std::isfinite(lum) ? std::max(lum, 0.0f) : 0.0f) * dw;
      total += weight[i];
    }
  }
  if (!(total > 0.0)) {  // black or invalid map: uniform over the sphere
    total = 0.0;
    for (int y = 0; y < height_; ++y)
      for (int x = 0; x < width_; ++x)
        total += weight[size_t(y) * width_ + x] = texelSolidAngle(y, width_, height_);
  }
  pixelProb_.resize(n);
  marginal_.assign(size_t(height_) + 1, 0.0f);
  conditional_.assign(size_t(height_) * (width_ + 1), 0.0f);
  double rowAcc = 0.0;
  for (int y = 0; y < height_; ++y) {
    double rowSum = 0.0;
    for (int x = 0; x < width_; ++x) rowSum += weight[size_t(y) * width_ + x];
    float* cdf = &conditional_[size_t(y) * (width_ + 1)];
    double acc = 0.0;
    for (int x = 0; x < width_; ++x) {
      const size_t i = size_t(y) * width_ + x;
      pixelProb_[i] = float(weight[i] / total);
      acc += weight[i];
      cdf[x + 1] = rowSum > 0.0 ? float(acc / rowSum) : float(x + 1) / float(width_);
    }
    cdf[width_] = 1.0f;
    rowAcc += rowSum;
    marginal_[y + 1] = float(rowAcc / total);
  }
  marginal_[height_] = 1.0f;
}

EnvironmentSampler::Sample EnvironmentSampler::sample(float u1, float u2) const {
  u1 = std::clamp(u1, 0.0f, 0.99999994f);
  u2 = std::clamp(u2, 0.0f, 0.99999994f);
  // Skip rows/columns of probability 0 (search finds the first with cdf > u).
  const int y = searchCdf(marginal_.data(), height_, u1);
  const float rowLo = marginal_[y], rowHi = marginal_[y + 1];
  const float fy = rowHi > rowLo ? std::clamp((u1 - rowLo) / (rowHi - rowLo), 0.0f, 1.0f) : 0.5f;
  const float* cdf = &conditional_[size_t(y) * (width_ + 1)];
  const int x = searchCdf(cdf, width_, u2);
  const float fx =
      cdf[x + 1] > cdf[x] ? std::clamp((u2 - cdf[x]) / (cdf[x + 1] - cdf[x]), 0.0f, 1.0f) : 0.5f;
  // Uniform in phi and cos(theta) inside the texel: the pdf is constant over it.
  const float c0 = rowCosTheta(y), c1 = rowCosTheta(y + 1);
  const float cosTheta = std::clamp(c0 + (c1 - c0) * fy, -1.0f, 1.0f);
  const float sinTheta = std::sqrt(std::max(0.0f, 1.0f - cosTheta * cosTheta));
  const float phi = 2.0f * kPi * (float(x) + fx) / float(width_);
  Sample s;
  s.direction = {sinTheta * std::cos(phi), cosTheta, sinTheta * std::sin(phi)};
  s.pixel = y * width_ + x;
  s.pdf = texelPdf(x, y);
  return s;
}

float EnvironmentSampler::texelPdf(int x, int y) const {
  x = std::clamp(x, 0, width_ - 1);
  y = std::clamp(y, 0, height_ - 1);
  const float dw = texelSolidAngle(y, width_, height_);
  const float p = pixelProb_[size_t(y) * width_ + x];
  return dw > 0.0f && p > 0.0f ? p / dw : 0.0f;  // guard: finite even if dw underflows
}

float EnvironmentSampler::rowCosTheta(int y) const {
  return std::cos(kPi * float(std::clamp(y, 0, height_)) / float(height_));
}

float EnvironmentSampler::pdf(const glm::vec3& dir) const {
  const glm::vec2 uv = equirectUV(dir);
  const int x = std::clamp(int(uv.x * width_), 0, width_ - 1);
  const int y = std::clamp(int(uv.y * height_), 0, height_ - 1);
  return texelPdf(x, y);
}

}  // namespace gi
