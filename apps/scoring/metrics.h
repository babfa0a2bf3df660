// Image error metrics of gi-bench: NRMSE and SSIM between a test image and a reference, both
// single-channel, over the pixels a mask keeps (sky pixels are masked out by the caller).
//
//  - NRMSE = sqrt(mean over kept pixels of (x - r)^2) / mean over kept pixels of |r|. Dividing
//    by the reference's mean (not its range) keeps the value meaningful for HDR lighting, where
//    a few bright pixels would dominate the range. A reference whose mean is (nearly) 0 is
//    divided by 1 instead, so constant black images give a finite value.
//  - SSIM (Wang et al. 2004): 11x11 Gaussian window (sigma 1.5), C1 = (0.01 L)^2, C2 =
//    (0.03 L)^2 with L the dynamic range (1 for AO and for tonemapped lighting). Window
//    statistics are weighted by the mask, so masked pixels contribute nothing; the result is
//    the mean SSIM over the kept pixels.
//  - No kept pixel at all: nrmse() and ssim() give 0 and 1 (never NaN); compare(), what the
//    apps score with, refuses it (std::invalid_argument): an empty comparison is no result.
//  - compare() may divide by the mean over fewer pixels than it scores (`normaliserMask`, e.g.
//    without the emitters, whose few bright pixels would dominate the mean) and report the
//    reference's own noise on the same scale (`referenceStdError`: RMS of the per-pixel
//    standard error / normaliser; a perfect renderer scores about this NRMSE).
#pragma once

#include <cstddef>
#include <vector>

namespace gi::bench {

struct Plane {
  int width = 0, height = 0;
  std::vector<float> values;  // width * height, row 0 at the top
};

struct Metrics {
  double nrmse = 0.0;
  double rmse = 0.0;
  double ssim = 1.0;
  size_t pixels = 0;            // kept (scored) pixels
  double normaliser = 1.0;      // the mean |reference| NRMSE divides by
  size_t normaliserPixels = 0;  // the pixels of that mean
  double noiseFloor = 0.0;      // RMS(reference standard error) / normaliser; 0: not given
  double testMean = 0.0, referenceMean = 0.0;  // over the scored pixels (compare())
};

// `mask`: empty (keep everything) or width * height entries, nonzero = keep. Non-finite test
// values count as the largest possible error (their pixels are compared as 0 vs the reference
// plus 1e6), so a broken effect shows up instead of producing NaN.
double nrmse(const Plane& test, const Plane& reference, const std::vector<unsigned char>& mask);
// Mean over the pixels `mask` keeps (empty: all); 0 when it keeps none.
double mean(const Plane& image, const std::vector<unsigned char>& mask);
double ssim(const Plane& test, const Plane& reference, const std::vector<unsigned char>& mask,
            double dynamicRange = 1.0);
Metrics compare(const Plane& test, const Plane& reference, const std::vector<unsigned char>& mask,
                double dynamicRange = 1.0,
                const std::vector<unsigned char>* normaliserMask = nullptr,
                const Plane* referenceStdError = nullptr);

// How much of an effect's error against its physical target T comes from the quantity it
// declares, D, differing from T: e = S - T = (S - D) + (D - T). gapNrmse = RMS(D - T) / mean|T|
// (the error of a perfect estimator of D); gapShare = mean(e (D - T)) / mean(e^2), the share of
// the mean squared error the gap explains (1 - gapShare is the estimator's, S - D; a share may
// be negative or above 1 when the parts cancel). No kept pixel or e = 0 everywhere: shares 0.
struct QuantityGap {
  double gapNrmse = 0.0, gapShare = 0.0;
};
QuantityGap quantityGap(const Plane& test, const Plane& target, const Plane& declared,
                        const std::vector<unsigned char>& mask);

// Channel c (0..3) of an RGBA float image; Rec. 709 luminance when c < 0.
Plane channel(int width, int height, const std::vector<float>& rgba, int c);
// x / (1 + x) per pixel: maps HDR radiance into [0, 1) for SSIM with L = 1.
Plane reinhard(const Plane& p);

}  // namespace gi::bench
