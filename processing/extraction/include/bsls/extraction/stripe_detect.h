// The modern stripe detector: a binary mask of bright stripe pixels (not a
// thesis algorithm; it replaces thesis 4.1-4.2 enhancement + edge detection
// in the default chain).
//
// The brick images have bright stripes 1..10 px wide, 12..15 px apart, whose
// contrast varies by a factor of 3 or more (shading, dark eyebrows) on a dark
// ground. Two detectors are offered:
//
//  kHessianRidge (default): Hessian-seeded hysteresis over a shape test.
//   * Ridge strength: at each of scale_count scales sigma (geometric from
//     min_scale to max_scale) the Hessian of the Gaussian-smoothed image is
//     formed; the strength is sigma^2 * max(0, -lambda_min) (lambda_min its
//     most negative eigenvalue) / (2 * 0.242), so that a bright bar of
//     contrast C seen at its best scale scores about C grey levels; the
//     maximum over the scales is taken (RidgeStrength).
//   * Seeds: strength >= 2 * min_ridge_contrast and >= high_threshold times
//     the local ridge level (the strongest ridge within contrast_window,
//     floored at min_ridge_contrast), so that weak eyebrow stripes seed as
//     well as bright ones.
//   * Shape test, on the image smoothed by level_sigma, along x, y and both
//     diagonals (a pixel passes if one direction passes): the ground is the
//     higher of the darkest values within contrast_window / 2 before and after
//     the pixel (a stripe has dark ground on both sides, an edge on one only);
//     the peak is the brightest value within max_scale + 1 px; the peak must
//     rise above the ground by max(min_ridge_contrast, noise_factor * noise
//     sigma) and the pixel must stand level_fraction of the way up. This
//     keeps the mask about as wide as the stripe at half height, rejects
//     edges and flat noise, and T-junction centres pass along a diagonal.
//   * Mask: the 8-connected components of shape-test pixels that hold a seed.
//  kAdaptiveThreshold (for comparison): the image smoothed by adaptive_sigma
//    above local mean + adaptive_k * local std over adaptive_window, where
//    the local std is at least adaptive_min_std.
//
// Measurements behind the default (tests/extraction/stripe_detect_test.cpp,
// StripeDetect.DetectorComparison, brick scenes with a dark patch): both
// detectors cover the bright stripes and bridge nothing, but the adaptive
// threshold loses the junctions of the dark patch and of wide stripes
// (10 px at a 13 px pitch), where the Hessian detector keeps them.
//
// Images: input CV_8UC1 grey; outputs CV_8UC1 0/255 (mask) or CV_32FC1 (strength,
// grey levels). x = column, y = row. Borders replicated.
//
// Errors: empty or non-CV_8UC1 input and invalid parameters throw
// std::invalid_argument("<Function>: <reason>").
//
// Thread-safety: pure functions of their arguments. kHessianRidge runs band
// by band (64 rows) on OpenCV's thread pool (cv::parallel_for_); every band
// reads the rows around it, so the result does not depend on the number of
// threads (cv::setNumThreads(1) makes it serial).
#ifndef BSLS_EXTRACTION_STRIPE_DETECT_H_
#define BSLS_EXTRACTION_STRIPE_DETECT_H_

#include <opencv2/core.hpp>
#include <string>

#include "bsls/common/cancellation.h"

namespace bsls::extraction {

enum class StripeDetector { kHessianRidge, kAdaptiveThreshold };

struct StripeDetectParams {
  StripeDetector method = StripeDetector::kHessianRidge;

  // kHessianRidge. A bar of width w answers best near sigma = w / 2, so
  // scales 1..4 px cover widths 1..10 px.
  double min_scale = 1.0;         // px, > 0
  double max_scale = 4.0;         // px, >= min_scale; also sets the peak reach (max_scale + 1)
  int scale_count = 4;            // >= 1 (1: only min_scale)
  int contrast_window = 27;       // px, odd >= 3; must span a stripe and a gap (> pitch)
  double min_ridge_contrast = 5;  // grey levels, > 0; seeds need twice this
  double high_threshold = 0.30;   // seeds: fraction of the local ridge level, (0, 1]
  double level_fraction = 0.5;    // shape test: how far up from ground to peak, [0, 1)
  double level_sigma = 0.7;       // shape test: Gaussian smoothing of the image, px, >= 0
  double noise_sigma = 0.0;       // grey levels of the image noise; 0 = estimate from the image
  double noise_factor = 2.5;      // shape test: the peak rises this many noise sigmas, >= 0

  // kAdaptiveThreshold.
  double adaptive_sigma = 1.0;    // pre-smoothing, pixels, > 0
  int adaptive_window = 15;       // pixels, odd >= 3
  double adaptive_k = 0.2;        // threshold = mean + k * std
  double adaptive_min_std = 5.0;  // grey levels; flatter neighbourhoods are background

  // True when the values are usable; otherwise says why.
  bool IsValid(std::string* error) const;
};

// Multi-scale Hessian ridge strength (see above), CV_32FC1, grey levels, >= 0.
cv::Mat RidgeStrength(const cv::Mat& grey, const StripeDetectParams& params);

// Binary mask (0/255) of bright stripe pixels by params.method. `cancel` is
// asked by every band of rows (Cancelled when asked to stop).
cv::Mat DetectStripes(const cv::Mat& grey, const StripeDetectParams& params,
                      const Cancellation& cancel = {});

}  // namespace bsls::extraction

#endif  // BSLS_EXTRACTION_STRIPE_DETECT_H_
