#include "bsls/extraction/enhance.h"

#include <cmath>
#include <opencv2/imgproc.hpp>

#include "input_checks.h"

namespace bsls::extraction {
namespace {

using internal::RequireGrey8;
using internal::RequireValid;

cv::Mat ToFloat(const cv::Mat& grey) {
  cv::Mat out;
  grey.convertTo(out, CV_32F);
  return out;
}

cv::Mat ToGrey8(const cv::Mat& values) {
  cv::Mat out;
  values.convertTo(out, CV_8U);  // rounds to nearest and saturates
  return out;
}

}  // namespace

bool AdaptiveContrastParams::IsValid(std::string* error) const {
  auto fail = [error](const char* why) {
    if (error) *error = why;
    return false;
  };
  if (window < 3 || window % 2 == 0) return fail("adaptive window must be odd and >= 3");
  if (!(k > 0.0 && k <= 1.0)) return fail("adaptive gain constant k must lie in (0, 1]");
  if (!(min_sigma > 0.0)) return fail("adaptive min_sigma must be > 0 grey levels");
  if (!(max_gain > 0.0)) return fail("adaptive max_gain must be > 0");
  return true;
}

bool EnhanceParams::IsValid(std::string* error) const {
  auto fail = [error](const char* why) {
    if (error) *error = why;
    return false;
  };
  switch (method) {
    case EnhanceMethod::kGaussian:
      if (!(gaussian_sigma > 0.0 && gaussian_sigma <= 50.0))
        return fail("gaussian_sigma must lie in (0, 50] pixels");
      return true;
    case EnhanceMethod::kIteratedBinomial:
      if (binomial_iterations < 1 || binomial_iterations > 100)
        return fail("binomial_iterations must lie in 1..100");
      return true;
    case EnhanceMethod::kMedian:
      if (median_size != 3 && median_size != 5) return fail("median_size must be 3 or 5");
      return true;
    case EnhanceMethod::kAdaptiveContrast:
      return adaptive.IsValid(error);
    case EnhanceMethod::kNone:
    case EnhanceMethod::kDavies:
    case EnhanceMethod::kHistogramEqualisation:
      return true;
  }
  return fail("unknown enhancement method");
}

cv::Mat DaviesKernel() {
  // Thesis 4.1.3, eq. 4.7 (Davies' accurate 3x3 Gaussian).
  cv::Mat kernel = (cv::Mat_<float>(3, 3) << 3, 7, 3, 7, 16, 7, 3, 7, 3);
  return kernel / 56.0f;
}

cv::Mat BinomialKernel() {
  // Thesis 4.1.3, eq. 4.6.
  cv::Mat kernel = (cv::Mat_<float>(3, 3) << 1, 2, 1, 2, 4, 2, 1, 2, 1);
  return kernel / 16.0f;
}

cv::Mat GaussianSmooth(const cv::Mat& grey, double sigma) {
  RequireGrey8(grey, "GaussianSmooth");
  if (!(sigma > 0.0 && sigma <= 50.0))
    throw std::invalid_argument("GaussianSmooth: sigma must lie in (0, 50] pixels");
  // Thesis 4.1.3, eq. 4.4; separable, +-3 sigma support.
  cv::Mat out;
  const int half = static_cast<int>(std::ceil(3.0 * sigma));
  cv::GaussianBlur(grey, out, cv::Size(2 * half + 1, 2 * half + 1), sigma, sigma,
                   cv::BORDER_REPLICATE);
  return out;
}

cv::Mat DaviesSmooth(const cv::Mat& grey) {
  RequireGrey8(grey, "DaviesSmooth");
  cv::Mat out;
  cv::filter2D(grey, out, CV_8U, DaviesKernel(), cv::Point(-1, -1), 0.0, cv::BORDER_REPLICATE);
  return out;
}

cv::Mat IteratedBinomialSmooth(const cv::Mat& grey, int iterations) {
  RequireGrey8(grey, "IteratedBinomialSmooth");
  if (iterations < 1 || iterations > 100)
    throw std::invalid_argument("IteratedBinomialSmooth: iterations must lie in 1..100");
  // Thesis 4.1.3, eq. 4.5-4.6: N passes of the binomial kernel, rounded once at the end.
  const cv::Mat kernel = BinomialKernel();
  cv::Mat values = ToFloat(grey);
  for (int i = 0; i < iterations; ++i)
    cv::filter2D(values, values, CV_32F, kernel, cv::Point(-1, -1), 0.0, cv::BORDER_REPLICATE);
  return ToGrey8(values);
}

cv::Mat MedianSmooth(const cv::Mat& grey, int size) {
  RequireGrey8(grey, "MedianSmooth");
  if (size != 3 && size != 5) throw std::invalid_argument("MedianSmooth: size must be 3 or 5");
  // Thesis 4.1.2. cv::medianBlur replicates the border for these sizes.
  cv::Mat out;
  cv::medianBlur(grey, out, size);
  return out;
}

cv::Mat AdaptiveContrast(const cv::Mat& grey, const AdaptiveContrastParams& params) {
  RequireGrey8(grey, "AdaptiveContrast");
  RequireValid(params, "AdaptiveContrast");
  // Thesis 4.1.1.1, eq. 4.2: g = A (f - m) + m, eq. 4.3: A = k M / sigma.
  const cv::Mat f = ToFloat(grey);
  const cv::Size window(params.window, params.window);
  cv::Mat mean, mean_sq;
  cv::boxFilter(f, mean, CV_32F, window, cv::Point(-1, -1), true, cv::BORDER_REPLICATE);
  cv::boxFilter(f.mul(f), mean_sq, CV_32F, window, cv::Point(-1, -1), true, cv::BORDER_REPLICATE);
  const double global_mean = cv::mean(grey)[0];
  const float kM = static_cast<float>(params.k * global_mean);
  const float min_sigma = static_cast<float>(params.min_sigma);
  const float max_gain = static_cast<float>(params.max_gain);
  cv::Mat g(f.size(), CV_32F);
  for (int y = 0; y < f.rows; ++y) {
    const float* fr = f.ptr<float>(y);
    const float* mr = mean.ptr<float>(y);
    const float* sr = mean_sq.ptr<float>(y);
    float* gr = g.ptr<float>(y);
    for (int x = 0; x < f.cols; ++x) {
      // Guard: sigma ~ 0 in flat areas would give an unbounded gain.
      const float sigma = std::sqrt(std::max(0.0f, sr[x] - mr[x] * mr[x]));
      const float gain = std::min(max_gain, kM / std::max(sigma, min_sigma));
      gr[x] = gain * (fr[x] - mr[x]) + mr[x];
    }
  }
  return ToGrey8(g);
}

cv::Mat HistogramEqualise(const cv::Mat& grey) {
  RequireGrey8(grey, "HistogramEqualise");
  cv::Mat out;
  cv::equalizeHist(grey, out);
  return out;
}

cv::Mat Enhance(const cv::Mat& grey, const EnhanceParams& params) {
  RequireGrey8(grey, "Enhance");
  RequireValid(params, "Enhance");
  switch (params.method) {
    case EnhanceMethod::kNone:
      return grey.clone();
    case EnhanceMethod::kGaussian:
      return GaussianSmooth(grey, params.gaussian_sigma);
    case EnhanceMethod::kDavies:
      return DaviesSmooth(grey);
    case EnhanceMethod::kIteratedBinomial:
      return IteratedBinomialSmooth(grey, params.binomial_iterations);
    case EnhanceMethod::kMedian:
      return MedianSmooth(grey, params.median_size);
    case EnhanceMethod::kAdaptiveContrast:
      return AdaptiveContrast(grey, params.adaptive);
    case EnhanceMethod::kHistogramEqualisation:
      return HistogramEqualise(grey);
  }
  throw std::invalid_argument("Enhance: unknown enhancement method");
}

}  // namespace bsls::extraction
