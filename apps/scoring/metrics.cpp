#include "metrics.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace gi::bench {

namespace {

void checkSizes(const Plane& a, const Plane& b, const std::vector<unsigned char>& mask) {
  const size_t n = size_t(a.width) * size_t(a.height);
  if (a.width != b.width || a.height != b.height || a.values.size() != n || b.values.size() != n ||
      (!mask.empty() && mask.size() != n))
    throw std::invalid_argument("metrics: images and mask must have the same size");
}

bool kept(const std::vector<unsigned char>& mask, size_t i) {
  return mask.empty() || mask[i];
}

float sanitize(float v) {
  return std::isfinite(v) ? v : 1e6f;
}

// Separable Gaussian blur of `in` (width x height), clamped at the borders.
std::vector<double> blur(const std::vector<double>& in, int w, int h,
                         const std::vector<double>& kernel) {
  const int r = int(kernel.size() / 2);
  std::vector<double> tmp(in.size()), out(in.size());
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      double s = 0.0;
      for (int k = -r; k <= r; ++k) {
        const int xx = x + k;
        if (xx < 0 || xx >= w) continue;  // outside: weight 0 (like a masked pixel)
        s += kernel[size_t(k + r)] * in[size_t(y) * size_t(w) + size_t(xx)];
      }
      tmp[size_t(y) * size_t(w) + size_t(x)] = s;
    }
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      double s = 0.0;
      for (int k = -r; k <= r; ++k) {
        const int yy = y + k;
        if (yy < 0 || yy >= h) continue;
        s += kernel[size_t(k + r)] * tmp[size_t(yy) * size_t(w) + size_t(x)];
      }
      out[size_t(y) * size_t(w) + size_t(x)] = s;
    }
  return out;
}

}  // namespace

double mean(const Plane& image, const std::vector<unsigned char>& mask) {
  double sum = 0.0;
  size_t n = 0;
  for (size_t i = 0; i < image.values.size(); ++i) {
    if (!kept(mask, i)) continue;
    sum += double(sanitize(image.values[i]));
    ++n;
  }
  return n > 0 ? sum / double(n) : 0.0;
}

double nrmse(const Plane& test, const Plane& reference, const std::vector<unsigned char>& mask) {
  checkSizes(test, reference, mask);
  double se = 0.0, refSum = 0.0;
  size_t n = 0;
  for (size_t i = 0; i < test.values.size(); ++i) {
    if (!kept(mask, i)) continue;
    const double d = double(sanitize(test.values[i])) - double(sanitize(reference.values[i]));
    se += d * d;
    refSum += std::abs(double(sanitize(reference.values[i])));
    ++n;
  }
  if (n == 0) return 0.0;
  const double rmse = std::sqrt(se / double(n));
  const double mean = refSum / double(n);
  return rmse / (mean > 1e-8 ? mean : 1.0);
}

double ssim(const Plane& test, const Plane& reference, const std::vector<unsigned char>& mask,
            double dynamicRange) {
  checkSizes(test, reference, mask);
  const int w = test.width, h = test.height;
  const size_t n = test.values.size();
  std::vector<double> kernel(11);
  for (int k = -5; k <= 5; ++k)
    kernel[size_t(k + 5)] = std::exp(-double(k * k) / (2.0 * 1.5 * 1.5));
  std::vector<double> m(n), mx(n), my(n), mxx(n), myy(n), mxy(n);
  size_t count = 0;
  for (size_t i = 0; i < n; ++i) {
    const double keep = kept(mask, i) ? 1.0 : 0.0;
    const double x = sanitize(test.values[i]), y = sanitize(reference.values[i]);
    m[i] = keep;
    mx[i] = keep * x;
    my[i] = keep * y;
    mxx[i] = keep * x * x;
    myy[i] = keep * y * y;
    mxy[i] = keep * x * y;
    count += keep > 0.0;
  }
  if (count == 0) return 1.0;
  m = blur(m, w, h, kernel);
  mx = blur(mx, w, h, kernel);
  my = blur(my, w, h, kernel);
  mxx = blur(mxx, w, h, kernel);
  myy = blur(myy, w, h, kernel);
  mxy = blur(mxy, w, h, kernel);
  const double c1 = (0.01 * dynamicRange) * (0.01 * dynamicRange);
  const double c2 = (0.03 * dynamicRange) * (0.03 * dynamicRange);
  double sum = 0.0;
  for (size_t i = 0; i < n; ++i) {
    if (!kept(mask, i) || !(m[i] > 0.0)) continue;
    const double ux = mx[i] / m[i], uy = my[i] / m[i];
    const double vx = std::max(0.0, mxx[i] / m[i] - ux * ux);
    const double vy = std::max(0.0, myy[i] / m[i] - uy * uy);
    const double cxy = mxy[i] / m[i] - ux * uy;
    sum += ((2.0 * ux * uy + c1) * (2.0 * cxy + c2)) / ((ux * ux + uy * uy + c1) * (vx + vy + c2));
  }
  const double s = sum / double(count);
  return std::isfinite(s) ? s : 0.0;
}

double normaliserMean(const Plane& reference, const std::vector<unsigned char>& mask,
                      size_t* pixels) {
  double sum = 0.0;
  size_t n = 0;
  for (size_t i = 0; i < reference.values.size(); ++i) {
    if (!kept(mask, i)) continue;
    sum += std::abs(double(sanitize(reference.values[i])));
    ++n;
  }
  if (pixels) *pixels = n;
  const double mean = n > 0 ? sum / double(n) : 0.0;
  return mean > 1e-8 ? mean : 1.0;
}

Metrics compare(const Plane& test, const Plane& reference, const std::vector<unsigned char>& mask,
                double dynamicRange, const std::vector<unsigned char>* normaliserMask,
                const Plane* referenceStdError) {
  checkSizes(test, reference, mask);
  if (!mask.empty() && std::none_of(mask.begin(), mask.end(), [](unsigned char m) { return m; }))
    throw std::invalid_argument("metrics: the mask keeps no pixel: there is nothing to score");
  if (test.values.empty())
    throw std::invalid_argument("metrics: empty images: there is nothing to score");
  if (normaliserMask) checkSizes(test, reference, *normaliserMask);
  if (referenceStdError) checkSizes(test, *referenceStdError, mask);
  Metrics r;
  r.ssim = ssim(test, reference, mask, dynamicRange);
  double se = 0.0, var = 0.0;
  for (size_t i = 0; i < test.values.size(); ++i) {
    if (!kept(mask, i)) continue;
    const double d = double(sanitize(test.values[i])) - double(sanitize(reference.values[i]));
    se += d * d;
    if (referenceStdError) var += std::pow(double(sanitize(referenceStdError->values[i])), 2);
    r.testMean += double(sanitize(test.values[i]));
    r.referenceMean += double(sanitize(reference.values[i]));
    ++r.pixels;
  }
  r.testMean /= double(r.pixels);
  r.referenceMean /= double(r.pixels);
  r.rmse = std::sqrt(se / double(r.pixels));
  // The normaliser's pixels: the given ones among the scored; none left: the scored ones.
  std::vector<unsigned char> normalised;
  if (normaliserMask) {
    normalised.resize(test.values.size());
    for (size_t i = 0; i < normalised.size(); ++i)
      normalised[i] = kept(mask, i) && (*normaliserMask)[i];
  }
  r.normaliser = normaliserMean(reference, normalised, &r.normaliserPixels);
  if (normaliserMask && r.normaliserPixels == 0)
    r.normaliser = normaliserMean(reference, mask, &r.normaliserPixels);
  r.nrmse = r.rmse / r.normaliser;
  r.noiseFloor = referenceStdError ? std::sqrt(var / double(r.pixels)) / r.normaliser : 0.0;
  return r;
}

QuantityGap quantityGap(const Plane& test, const Plane& target, const Plane& declared,
                        const std::vector<unsigned char>& mask) {
  double sumT = 0.0, gap2 = 0.0, ee = 0.0, eGap = 0.0;
  size_t n = 0;
  for (size_t i = 0; i < test.values.size(); ++i) {
    if (!kept(mask, i)) continue;
    const double S = sanitize(test.values[i]), T = sanitize(target.values[i]),
                 D = sanitize(declared.values[i]);
    const double e = S - T, gap = D - T;
    sumT += std::abs(T);
    gap2 += gap * gap;
    ee += e * e;
    eGap += e * gap;
    ++n;
  }
  QuantityGap g;
  if (n == 0) return g;
  const double meanT = sumT / double(n) > 1e-8 ? sumT / double(n) : 1.0;  // as nrmse()
  g.gapNrmse = std::sqrt(gap2 / double(n)) / meanT;
  g.gapShare = ee > 0.0 ? eGap / ee : 0.0;
  return g;
}

Plane channel(int width, int height, const std::vector<float>& rgba, int c) {
  Plane p{width, height, std::vector<float>(size_t(width) * size_t(height))};
  if (rgba.size() != p.values.size() * 4)
    throw std::invalid_argument("metrics: RGBA image of the wrong size");
  for (size_t i = 0; i < p.values.size(); ++i) {
    const float* px = &rgba[i * 4];
    p.values[i] = c < 0 ? 0.2126f * px[0] + 0.7152f * px[1] + 0.0722f * px[2] : px[c];
  }
  return p;
}

Plane reinhard(const Plane& p) {
  Plane out = p;
  for (float& v : out.values)
    v = std::isfinite(v) ? std::max(v, 0.0f) / (1.0f + std::max(v, 0.0f)) : 1.0f;
  return out;
}

}  // namespace gi::bench
