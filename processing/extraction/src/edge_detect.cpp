#include "bsls/extraction/edge_detect.h"

#include <algorithm>
#include <cassert>
#include <cmath>
#include <opencv2/imgproc.hpp>
#include <vector>

#include "hysteresis.h"
#include "input_checks.h"
#include "neighbourhood.h"

namespace bsls::extraction {
namespace {

using internal::RequireGrey8;
using internal::RequireScalarImage;
using internal::RequireValid;

auto Failer(std::string* error) {
  return [error](const char* why) {
    if (error) *error = why;
    return false;
  };
}

cv::Mat ToFloat(const cv::Mat& image) {
  cv::Mat out;
  image.convertTo(out, CV_32F);
  return out;
}

// Histogram of `values` (CV_32FC1) with `bins` bins over [0, max]; negative
// values fall in bin 0.
std::vector<double> HistogramOf(const cv::Mat& values, int bins, double max_value) {
  std::vector<double> hist(static_cast<size_t>(bins), 0.0);
  const double scale = bins / max_value;
  for (int y = 0; y < values.rows; ++y) {
    const float* row = values.ptr<float>(y);
    for (int x = 0; x < values.cols; ++x) {
      const int bin = std::clamp(static_cast<int>(row[x] * scale), 0, bins - 1);
      hist[static_cast<size_t>(bin)] += 1.0;
    }
  }
  return hist;
}

// The value below which (1 - fraction) of the pixels of `values` lie.
double UpperQuantile(const cv::Mat& values, double fraction) {
  std::vector<float> all;
  all.reserve(values.total());
  for (int y = 0; y < values.rows; ++y) {
    const float* row = values.ptr<float>(y);
    all.insert(all.end(), row, row + values.cols);
  }
  const size_t k = std::min(all.size() - 1, static_cast<size_t>((1.0 - fraction) * all.size()));
  std::nth_element(all.begin(), all.begin() + static_cast<std::ptrdiff_t>(k), all.end());
  return all[k];
}

// Thesis 4.2: the automatic threshold of a response image, or the quantile
// fallback; `from_two_peaks` tells which.
double AutomaticThreshold(const cv::Mat& response, int bins, const TwoPeakParams& two_peak,
                          double fallback_fraction, bool* from_two_peaks) {
  const std::optional<double> t = TwoPeakThresholdOfImage(response, bins, two_peak);
  if (from_two_peaks) *from_two_peaks = t.has_value();
  if (t) return *t;
  return UpperQuantile(response, fallback_fraction);
}

cv::Mat Binarise(const cv::Mat& response, double threshold) {
  cv::Mat out;
  cv::compare(response, threshold, out, cv::CMP_GE);  // 0/255
  // A threshold of 0 on a blank response would select everything; keep blank blank.
  if (threshold <= 0.0) cv::compare(response, 0.0, out, cv::CMP_GT);
  return out;
}

cv::Mat BinariseResponse(const cv::Mat& response, const EdgeThresholdParams& params) {
  const double threshold =
      params.automatic ? AutomaticThreshold(response, params.histogram_bins, params.two_peak,
                                            params.fallback_fraction, nullptr)
                       : params.fixed;
  return Binarise(response, threshold);
}

// Thesis 4.2.3: Gaussian smoothing then 3x3 Sobel derivatives (CV_16SC1).
struct CannyDerivatives {
  cv::Mat dx;
  cv::Mat dy;
};

CannyDerivatives ComputeCannyDerivatives(const cv::Mat& grey, double sigma) {
  cv::Mat smoothed = grey;
  if (sigma > 0.0) {
    const int half = static_cast<int>(std::ceil(3.0 * sigma));
    cv::GaussianBlur(grey, smoothed, cv::Size(2 * half + 1, 2 * half + 1), sigma, sigma,
                     cv::BORDER_REPLICATE);
  }
  CannyDerivatives d;
  cv::Sobel(smoothed, d.dx, CV_16S, 1, 0, 3, 1.0, 0.0, cv::BORDER_REPLICATE);
  cv::Sobel(smoothed, d.dy, CV_16S, 0, 1, 3, 1.0, 0.0, cv::BORDER_REPLICATE);
  return d;
}

CannyThresholds ThresholdsFor(const CannyDerivatives& d, const CannyParams& params) {
  CannyThresholds out;
  if (!params.automatic) {
    out.low = params.low;
    out.high = params.high;
    return out;
  }
  cv::Mat gx, gy, magnitude;
  d.dx.convertTo(gx, CV_32F);
  d.dy.convertTo(gy, CV_32F);
  if (params.l2_gradient)
    cv::magnitude(gx, gy, magnitude);
  else
    magnitude = cv::abs(gx) + cv::abs(gy);
  // Thesis 4.2: the upper hysteresis limit is the two-peak valley of the
  // edge-magnitude histogram; the lower one a fixed fraction of it.
  out.high = AutomaticThreshold(magnitude, params.histogram_bins, params.two_peak,
                                params.fallback_fraction, &out.from_two_peaks);
  out.high = std::max(out.high, 1.0);
  out.low = params.low_ratio * out.high;
  return out;
}

}  // namespace

bool TwoPeakParams::IsValid(std::string* error) const {
  auto fail = Failer(error);
  if (smoothing_radius < 0 || smoothing_radius > 64)
    return fail("two-peak smoothing_radius must lie in 0..64 bins");
  if (min_peak_separation < 2) return fail("two-peak min_peak_separation must be >= 2 bins");
  return true;
}

bool EdgeThresholdParams::IsValid(std::string* error) const {
  auto fail = Failer(error);
  if (!automatic && !(fixed > 0.0)) return fail("fixed edge threshold must be > 0");
  if (histogram_bins < 16 || histogram_bins > 65536)
    return fail("histogram_bins must lie in 16..65536");
  if (!(fallback_fraction > 0.0 && fallback_fraction < 1.0))
    return fail("fallback_fraction must lie in (0, 1)");
  return two_peak.IsValid(error);
}

bool LaplacianParams::IsValid(std::string* error) const {
  auto fail = Failer(error);
  if (!(sigma >= 0.0 && sigma <= 50.0)) return fail("LoG sigma must lie in [0, 50] pixels");
  return threshold.IsValid(error);
}

bool CannyParams::IsValid(std::string* error) const {
  auto fail = Failer(error);
  if (!(sigma >= 0.0 && sigma <= 50.0)) return fail("Canny sigma must lie in [0, 50] pixels");
  if (!(low_ratio > 0.0 && low_ratio <= 1.0)) return fail("Canny low_ratio must lie in (0, 1]");
  if (!automatic && !(low > 0.0 && low <= high))
    return fail("Canny fixed thresholds need 0 < low <= high");
  if (histogram_bins < 16 || histogram_bins > 65536)
    return fail("Canny histogram_bins must lie in 16..65536");
  if (!(fallback_fraction > 0.0 && fallback_fraction < 1.0))
    return fail("Canny fallback_fraction must lie in (0, 1)");
  return two_peak.IsValid(error);
}

std::optional<TwoPeakResult> TwoPeakThreshold(std::span<const double> histogram,
                                              const TwoPeakParams& params) {
  RequireValid(params, "TwoPeakThreshold");
  const int n = static_cast<int>(histogram.size());
  for (double count : histogram)
    if (!(count >= 0.0) || !std::isfinite(count))
      throw std::invalid_argument("TwoPeakThreshold: histogram counts must be finite and >= 0");
  if (n < params.min_peak_separation + 1) return std::nullopt;

  // Moving-average smoothing suppresses single-bin noise peaks.
  std::vector<double> s(static_cast<size_t>(n), 0.0);
  for (int i = 0; i < n; ++i) {
    const int a = std::max(0, i - params.smoothing_radius);
    const int b = std::min(n - 1, i + params.smoothing_radius);
    double sum = 0.0;
    for (int j = a; j <= b; ++j) sum += histogram[static_cast<size_t>(j)];
    s[static_cast<size_t>(i)] = sum / (b - a + 1);
  }
  auto at = [&s](int i) { return s[static_cast<size_t>(i)]; };

  // First peak: the highest bin.
  const int p1 = static_cast<int>(std::max_element(s.begin(), s.end()) - s.begin());
  if (!(at(p1) > 0.0)) return std::nullopt;
  // Second peak: far from the first and high, (k - p1)^2 h(k) largest ...
  int p2 = -1;
  double best = 0.0;
  for (int k = 0; k < n; ++k) {
    const int d = k - p1;
    if (std::abs(d) < params.min_peak_separation) continue;
    const double score = static_cast<double>(d) * d * at(k);
    if (score > best) {
      best = score;
      p2 = k;
    }
  }
  if (p2 < 0) return std::nullopt;
  // ... then climbed to the top of its own hill, staying clear of the first.
  for (bool moved = true; moved;) {
    moved = false;
    for (int step : {-1, 1}) {
      const int k = p2 + step;
      if (k < 0 || k >= n || std::abs(k - p1) < params.min_peak_separation) continue;
      if (at(k) > at(p2)) {
        p2 = k;
        moved = true;
      }
    }
  }
  const int lo = std::min(p1, p2);
  const int hi = std::max(p1, p2);
  // Threshold: the lowest bin between the peaks (middle of a flat minimum).
  int first_min = lo + 1;
  for (int k = lo + 1; k < hi; ++k)
    if (at(k) < at(first_min)) first_min = k;
  int last_min = first_min;
  while (last_min + 1 < hi && at(last_min + 1) == at(first_min)) ++last_min;
  const int t = (first_min + last_min) / 2;
  if (!(at(t) < at(lo) && at(t) < at(hi))) return std::nullopt;
  return TwoPeakResult{lo, hi, t};
}

std::optional<double> TwoPeakThresholdOfImage(const cv::Mat& magnitude, int bins,
                                              const TwoPeakParams& params) {
  RequireScalarImage(magnitude, "TwoPeakThresholdOfImage");
  RequireValid(params, "TwoPeakThresholdOfImage");
  if (bins < 16 || bins > 65536)
    throw std::invalid_argument("TwoPeakThresholdOfImage: bins must lie in 16..65536");
  const cv::Mat values = magnitude.depth() == CV_32F ? magnitude : ToFloat(magnitude);
  double max_value = 0.0;
  cv::minMaxLoc(values, nullptr, &max_value);
  if (!(max_value > 0.0)) return std::nullopt;
  const std::vector<double> hist = HistogramOf(values, bins, max_value);
  const std::optional<TwoPeakResult> peaks = TwoPeakThreshold(hist, params);
  if (!peaks) return std::nullopt;
  return (peaks->threshold + 0.5) * max_value / bins;  // centre of the threshold bin
}

cv::Mat HysteresisThreshold(const cv::Mat& magnitude, double low, double high) {
  RequireScalarImage(magnitude, "HysteresisThreshold");
  if (!(low <= high)) throw std::invalid_argument("HysteresisThreshold: needs low <= high");
  cv::Mat weak, strong;
  cv::compare(magnitude, low, weak, cv::CMP_GE);
  cv::compare(magnitude, high, strong, cv::CMP_GE);
  return internal::KeepComponentsTouching(weak, strong);
}

namespace internal {

cv::Mat KeepComponentsTouching(const cv::Mat& weak, const cv::Mat& strong,
                               const Cancellation& cancel, std::string_view stage) {
  assert(weak.size() == strong.size() && weak.type() == CV_8UC1 && strong.type() == CV_8UC1);
  // Flood fill from every strong pixel of `weak` (marked 2 when reached);
  // the pixels reached are the components touching a strong pixel.
  PaddedBinary img(weak);
  const std::ptrdiff_t s = static_cast<std::ptrdiff_t>(img.Stride());
  const std::ptrdiff_t offsets[8] = {-s - 1, -s, -s + 1, -1, 1, s - 1, s, s + 1};
  std::vector<size_t> stack;
  cancel.ThrowIfRequested(stage);
  // The strong pixels in raster order, by index into a buffer laid out like img's.
  const std::vector<size_t> starts = PaddedBinary(strong).SetIndices();
  for (size_t k = 0; k < starts.size(); ++k) {
    if (k % 16384 == 0) cancel.ThrowIfRequested(stage);
    const size_t start = starts[k];
    if (img.data[start] != 1) continue;
    stack.assign(1, start);
    img.data[start] = 2;
    while (!stack.empty()) {
      const size_t i = stack.back();
      stack.pop_back();
      for (std::ptrdiff_t o : offsets) {
        const size_t q = static_cast<size_t>(static_cast<std::ptrdiff_t>(i) + o);
        if (img.data[q] != 1) continue;
        img.data[q] = 2;
        stack.push_back(q);
      }
    }
  }
  return img.ToMatWhere(2);
}

}  // namespace internal

cv::Mat SobelMagnitude(const cv::Mat& grey) {
  RequireGrey8(grey, "SobelMagnitude");
  // Thesis 4.2.1, eq. 4.11-4.12: |Gx| + |Gy|.
  cv::Mat gx, gy;
  cv::Sobel(grey, gx, CV_32F, 1, 0, 3, 1.0, 0.0, cv::BORDER_REPLICATE);
  cv::Sobel(grey, gy, CV_32F, 0, 1, 3, 1.0, 0.0, cv::BORDER_REPLICATE);
  return cv::abs(gx) + cv::abs(gy);
}

cv::Mat SobelEdges(const cv::Mat& grey, const EdgeThresholdParams& params) {
  RequireGrey8(grey, "SobelEdges");
  RequireValid(params, "SobelEdges");
  return BinariseResponse(SobelMagnitude(grey), params);
}

cv::Mat LaplacianKernel(LaplacianMask mask) {
  if (mask == LaplacianMask::kH1FourNeighbour)  // thesis eq. 4.15
    return (cv::Mat_<float>(3, 3) << 0, -1, 0, -1, 4, -1, 0, -1, 0);
  return (cv::Mat_<float>(3, 3) << -1, -1, -1, -1, 8, -1, -1, -1, -1);  // thesis eq. 4.16
}

cv::Mat LaplacianOfGaussian(const cv::Mat& grey, double sigma, LaplacianMask mask) {
  RequireGrey8(grey, "LaplacianOfGaussian");
  if (!(sigma >= 0.0 && sigma <= 50.0))
    throw std::invalid_argument("LaplacianOfGaussian: sigma must lie in [0, 50] pixels");
  // Thesis 4.2.2: Gaussian smoothing, then h1 or h2.
  cv::Mat values = ToFloat(grey);
  if (sigma > 0.0) {
    const int half = static_cast<int>(std::ceil(3.0 * sigma));
    cv::GaussianBlur(values, values, cv::Size(2 * half + 1, 2 * half + 1), sigma, sigma,
                     cv::BORDER_REPLICATE);
  }
  cv::Mat response;
  cv::filter2D(values, response, CV_32F, LaplacianKernel(mask), cv::Point(-1, -1), 0.0,
               cv::BORDER_REPLICATE);
  return response;
}

cv::Mat LaplacianEdges(const cv::Mat& grey, const LaplacianParams& params) {
  RequireGrey8(grey, "LaplacianEdges");
  RequireValid(params, "LaplacianEdges");
  cv::Mat positive = cv::max(LaplacianOfGaussian(grey, params.sigma, params.mask), 0.0);
  return BinariseResponse(positive, params.threshold);
}

CannyThresholds ChooseCannyThresholds(const cv::Mat& grey, const CannyParams& params) {
  RequireGrey8(grey, "ChooseCannyThresholds");
  RequireValid(params, "ChooseCannyThresholds");
  const CannyDerivatives d = ComputeCannyDerivatives(grey, params.sigma);
  return ThresholdsFor(d, params);
}

cv::Mat CannyEdges(const cv::Mat& grey, const CannyParams& params) {
  RequireGrey8(grey, "CannyEdges");
  RequireValid(params, "CannyEdges");
  const CannyDerivatives d = ComputeCannyDerivatives(grey, params.sigma);
  const CannyThresholds thresholds = ThresholdsFor(d, params);
  // Thesis 4.2.3: non-maximum suppression and hysteresis by cv::Canny.
  cv::Mat edges;
  cv::Canny(d.dx, d.dy, edges, thresholds.low, thresholds.high, params.l2_gradient);
  return edges;
}

}  // namespace bsls::extraction
