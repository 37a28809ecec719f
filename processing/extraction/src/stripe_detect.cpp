#include "bsls/extraction/stripe_detect.h"

#include <algorithm>
#include <cmath>
#include <opencv2/imgproc.hpp>
#include <vector>

#include "hysteresis.h"
#include "input_checks.h"

namespace bsls::extraction {
namespace {

using internal::RequireGrey8;
using internal::RequireValid;

// 2 * t * phi(t) at t = 1: the scale-normalised curvature of a unit bar at its
// best scale; dividing by it makes the ridge strength read in grey levels.
constexpr float kBarResponse = 2.0f * 0.24197072f;

cv::Mat Blur(const cv::Mat& values, double sigma) {
  cv::Mat out;
  const int half = std::max(1, static_cast<int>(std::ceil(3.0 * sigma)));
  cv::GaussianBlur(values, out, cv::Size(2 * half + 1, 2 * half + 1), sigma, sigma,
                   cv::BORDER_REPLICATE);
  return out;
}

std::vector<double> Scales(const StripeDetectParams& p) {
  std::vector<double> scales;
  if (p.scale_count == 1) return {p.min_scale};
  const double ratio = std::pow(p.max_scale / p.min_scale, 1.0 / (p.scale_count - 1));
  for (int i = 0; i < p.scale_count; ++i) scales.push_back(p.min_scale * std::pow(ratio, i));
  return scales;
}

// Updates strength = max(strength, sigma^2 * max(0, -lambda_min(Hessian(L))) / kBarResponse).
// The Hessian is taken by central differences of the smoothed image L.
void AccumulateRidge(const cv::Mat& L, double sigma, cv::Mat* strength) {
  const float scale = static_cast<float>(sigma * sigma) / kBarResponse;
  const int rows = L.rows, cols = L.cols;
  for (int y = 0; y < rows; ++y) {
    const float* up = L.ptr<float>(std::max(y - 1, 0));
    const float* mid = L.ptr<float>(y);
    const float* down = L.ptr<float>(std::min(y + 1, rows - 1));
    float* out = strength->ptr<float>(y);
    auto at = [&](int x, int xl, int xr) {
      const float lxx = mid[xr] - 2.0f * mid[x] + mid[xl];
      const float lyy = down[x] - 2.0f * mid[x] + up[x];
      const float lxy = 0.25f * (down[xr] - down[xl] - up[xr] + up[xl]);
      const float half_trace = 0.5f * (lxx + lyy);
      const float half_diff = 0.5f * (lxx - lyy);
      const float lambda_min = half_trace - std::sqrt(half_diff * half_diff + lxy * lxy);
      out[x] = std::max(out[x], -lambda_min * scale);
    };
    if (cols == 1) {
      at(0, 0, 0);
      continue;
    }
    at(0, 0, 1);
    for (int x = 1; x + 1 < cols; ++x) at(x, x - 1, x + 1);  // interior: no clamping
    at(cols - 1, cols - 2, cols - 1);
  }
}

// Multi-scale ridge strength.
cv::Mat ComputeRidgeStrength(const cv::Mat& grey, const StripeDetectParams& p) {
  cv::Mat f;
  grey.convertTo(f, CV_32F);
  cv::Mat strength = cv::Mat::zeros(grey.size(), CV_32F);
  for (double sigma : Scales(p)) AccumulateRidge(Blur(f, sigma), sigma, &strength);
  return strength;
}

// Immerkaer's noise estimate made robust: the median absolute response to
// [1 -2 1; -2 4 -2; 1 -2 1] (which cancels smooth shading), scaled to the
// standard deviation of white noise, over pixels whose neighbourhood is not
// clipped at 0 or 255 (every other row and column: plenty for a median).
// Stripes inflate it a little.
double EstimateNoiseSigma(const cv::Mat& grey) {
  const cv::Mat kernel = (cv::Mat_<float>(3, 3) << 1, -2, 1, -2, 4, -2, 1, -2, 1);
  cv::Mat response;
  cv::filter2D(grey, response, CV_32F, kernel, cv::Point(-1, -1), 0.0, cv::BORDER_REPLICATE);
  cv::Mat lo, hi;
  cv::erode(grey, lo, cv::Mat());
  cv::dilate(grey, hi, cv::Mat());
  std::vector<float> values;
  values.reserve(grey.total() / 4 + 1);
  for (int y = 1; y + 1 < grey.rows; y += 2) {
    const float* rr = response.ptr<float>(y);
    const unsigned char* lr = lo.ptr<unsigned char>(y);
    const unsigned char* hr = hi.ptr<unsigned char>(y);
    for (int x = 1; x + 1 < grey.cols; x += 2)
      if (lr[x] > 0 && hr[x] < 255) values.push_back(std::abs(rr[x]));
  }
  if (values.empty()) return 0.0;
  const auto mid = values.begin() + static_cast<std::ptrdiff_t>(values.size() / 2);
  std::nth_element(values.begin(), mid, values.end());
  return 1.4826 * *mid / 6.0;  // the kernel's norm is 6
}

// The four directions of the shape test: x, y and the two diagonals.
enum class Direction { kX, kY, kDiagonalDown, kDiagonalUp };

// A line structuring element of `length` pixels along `d`, anchored at `anchor`
// (index along the line; -1 = centre).
cv::Mat LineElement(Direction d, int length, int anchor, cv::Point* anchor_point) {
  const int a = anchor < 0 ? length / 2 : anchor;
  switch (d) {
    case Direction::kX:
      *anchor_point = cv::Point(a, 0);
      return cv::Mat::ones(1, length, CV_8U);
    case Direction::kY:
      *anchor_point = cv::Point(0, a);
      return cv::Mat::ones(length, 1, CV_8U);
    case Direction::kDiagonalDown:
      *anchor_point = cv::Point(a, a);
      return cv::Mat::eye(length, length, CV_8U);
    case Direction::kDiagonalUp: {
      cv::Mat e;
      cv::flip(cv::Mat::eye(length, length, CV_8U), e, 1);  // (i, length - 1 - i)
      *anchor_point = cv::Point(length - 1 - a, a);
      return e;
    }
  }
  return {};
}

// Thesis-independent shape test of DetectByHessian along one direction: 255
// where, along d, the pixel rises at least `fraction` of the way from the
// ground (the higher of the darkest values within r steps before and after
// it, so that a stripe must have dark ground on both sides and an edge does
// not) to the peak (the brightest value within peak_r steps), and the peak
// stands at least min_contrast above the ground.
cv::Mat ShapeTest(const cv::Mat& f, Direction d, int r, int peak_r, float fraction,
                  float min_contrast) {
  cv::Point anchor;
  cv::Mat before, after, peak;
  cv::erode(f, before, LineElement(d, r + 1, r, &anchor), anchor, 1, cv::BORDER_REPLICATE);
  cv::erode(f, after, LineElement(d, r + 1, 0, &anchor), anchor, 1, cv::BORDER_REPLICATE);
  cv::dilate(f, peak, LineElement(d, 2 * peak_r + 1, -1, &anchor), anchor, 1, cv::BORDER_REPLICATE);
  cv::Mat out(f.size(), CV_8UC1);
  for (int y = 0; y < f.rows; ++y) {
    const float* fr = f.ptr<float>(y);
    const float* br = before.ptr<float>(y);
    const float* ar = after.ptr<float>(y);
    const float* pr = peak.ptr<float>(y);
    unsigned char* o = out.ptr<unsigned char>(y);
    for (int x = 0; x < f.cols; ++x) {
      const float ground = std::max(br[x], ar[x]);
      const float rise = pr[x] - ground;
      o[x] = rise >= min_contrast && fr[x] >= ground + fraction * rise ? 255 : 0;
    }
  }
  return out;
}

cv::Mat DetectByHessian(const cv::Mat& grey, const StripeDetectParams& p) {
  // Seeds: strong ridges, absolutely and relative to the strongest ridge
  // within the window (so that dim eyebrow stripes seed as well).
  const cv::Mat strength = ComputeRidgeStrength(grey, p);
  cv::Mat level;
  cv::dilate(
      strength, level,
      cv::getStructuringElement(cv::MORPH_RECT, cv::Size(p.contrast_window, p.contrast_window)),
      cv::Point(-1, -1), 1, cv::BORDER_REPLICATE);
  level = cv::max(level, p.min_ridge_contrast);
  cv::Mat relative, seeds_relative, seeds_absolute;
  cv::divide(strength, level, relative);
  cv::compare(relative, p.high_threshold, seeds_relative, cv::CMP_GE);
  cv::compare(strength, 2.0 * p.min_ridge_contrast, seeds_absolute, cv::CMP_GE);

  // Width and shape: a stripe pixel passes the shape test across its stripe;
  // trying x, y and both diagonals needs no direction estimate and lets
  // T-junction centres pass along a diagonal.
  cv::Mat f;
  grey.convertTo(f, CV_32F);
  if (p.level_sigma > 0.0) f = Blur(f, p.level_sigma);
  const int half_window = p.contrast_window / 2;
  const int peak_reach = static_cast<int>(std::ceil(p.max_scale + 1.0));
  const double noise = p.noise_sigma > 0.0 ? p.noise_sigma : EstimateNoiseSigma(grey);
  const float min_rise = static_cast<float>(std::max(p.min_ridge_contrast, p.noise_factor * noise));
  const float fraction = static_cast<float>(p.level_fraction);
  cv::Mat shaped = cv::Mat::zeros(grey.size(), CV_8UC1);
  for (Direction d :
       {Direction::kX, Direction::kY, Direction::kDiagonalDown, Direction::kDiagonalUp}) {
    // Diagonal steps are sqrt(2) long: fewer of them for the same reach.
    const bool diagonal = d == Direction::kDiagonalDown || d == Direction::kDiagonalUp;
    const double step = diagonal ? std::sqrt(2.0) : 1.0;
    const int r = static_cast<int>(std::lround(half_window / step));
    const int pr = static_cast<int>(std::ceil(peak_reach / step));
    shaped |= ShapeTest(f, d, r, pr, fraction, min_rise);
  }
  // Stripes grow from the seeds through the shaped pixels.
  return internal::KeepComponentsTouching(shaped, shaped & seeds_relative & seeds_absolute);
}

cv::Mat DetectByAdaptiveThreshold(const cv::Mat& grey, const StripeDetectParams& p) {
  cv::Mat f;
  grey.convertTo(f, CV_32F);
  f = Blur(f, p.adaptive_sigma);
  const cv::Size window(p.adaptive_window, p.adaptive_window);
  cv::Mat mean, mean_sq;
  cv::boxFilter(f, mean, CV_32F, window, cv::Point(-1, -1), true, cv::BORDER_REPLICATE);
  cv::boxFilter(f.mul(f), mean_sq, CV_32F, window, cv::Point(-1, -1), true, cv::BORDER_REPLICATE);
  cv::Mat mask(grey.size(), CV_8UC1);
  const float k = static_cast<float>(p.adaptive_k);
  const float min_std = static_cast<float>(p.adaptive_min_std);
  for (int y = 0; y < f.rows; ++y) {
    const float* fr = f.ptr<float>(y);
    const float* mr = mean.ptr<float>(y);
    const float* sr = mean_sq.ptr<float>(y);
    unsigned char* out = mask.ptr<unsigned char>(y);
    for (int x = 0; x < f.cols; ++x) {
      const float sd = std::sqrt(std::max(0.0f, sr[x] - mr[x] * mr[x]));
      out[x] = (sd >= min_std && fr[x] > mr[x] + k * sd) ? 255 : 0;
    }
  }
  return mask;
}

}  // namespace

bool StripeDetectParams::IsValid(std::string* error) const {
  auto fail = [error](const char* why) {
    if (error) *error = why;
    return false;
  };
  if (!(min_scale > 0.0 && min_scale <= 20.0)) return fail("min_scale must lie in (0, 20] px");
  if (!(max_scale >= min_scale && max_scale <= 20.0))
    return fail("max_scale must lie in [min_scale, 20] px");
  if (scale_count < 1 || scale_count > 16) return fail("scale_count must lie in 1..16");
  if (contrast_window < 3 || contrast_window % 2 == 0)
    return fail("contrast_window must be odd and >= 3");
  if (!(min_ridge_contrast > 0.0)) return fail("min_ridge_contrast must be > 0 grey levels");
  if (!(noise_sigma >= 0.0)) return fail("noise_sigma must be >= 0 (0 = estimate)");
  if (!(noise_factor >= 0.0)) return fail("noise_factor must be >= 0");
  if (!(level_sigma >= 0.0 && level_sigma <= 20.0))
    return fail("level_sigma must lie in [0, 20] px");
  if (!(level_fraction >= 0.0 && level_fraction < 1.0))
    return fail("level_fraction must lie in [0, 1)");
  if (!(high_threshold > 0.0 && high_threshold <= 1.0))
    return fail("high_threshold must lie in (0, 1]");
  if (!(adaptive_sigma > 0.0 && adaptive_sigma <= 20.0))
    return fail("adaptive_sigma must lie in (0, 20] px");
  if (adaptive_window < 3 || adaptive_window % 2 == 0)
    return fail("adaptive_window must be odd and >= 3");
  if (!(adaptive_min_std >= 0.0)) return fail("adaptive_min_std must be >= 0");
  if (!std::isfinite(adaptive_k)) return fail("adaptive_k must be finite");
  return true;
}

cv::Mat RidgeStrength(const cv::Mat& grey, const StripeDetectParams& params) {
  RequireGrey8(grey, "RidgeStrength");
  RequireValid(params, "RidgeStrength");
  return ComputeRidgeStrength(grey, params);
}

cv::Mat DetectStripes(const cv::Mat& grey, const StripeDetectParams& params) {
  RequireGrey8(grey, "DetectStripes");
  RequireValid(params, "DetectStripes");
  if (params.method == StripeDetector::kAdaptiveThreshold)
    return DetectByAdaptiveThreshold(grey, params);
  return DetectByHessian(grey, params);
}

}  // namespace bsls::extraction
