// Image enhancement before stripe detection (thesis 4.1).
//
// Images: every function takes an 8-bit grey frame (CV_8UC1, row-major,
// x = column to the right, y = row downwards, origin at the centre of the
// top-left pixel) and returns a new CV_8UC1 frame of the same size; grey
// levels are rounded and saturated to 0..255. Borders are handled by
// replicating the edge pixels (cv::BORDER_REPLICATE).
//
// Errors: an empty image or one that is not CV_8UC1, and parameters that fail
// IsValid, throw std::invalid_argument("<Function>: <reason>").
//
// Thread-safety: pure functions of their arguments.
#ifndef BSLS_EXTRACTION_ENHANCE_H_
#define BSLS_EXTRACTION_ENHANCE_H_

#include <opencv2/core.hpp>
#include <string>

namespace bsls::extraction {

// Thesis 4.1.1.1, equations 4.2-4.3: g = A (f - m) + m with A = k M / sigma,
// m and sigma the local mean and standard deviation, M the global mean.
struct AdaptiveContrastParams {
  int window = 7;          // side of the square local neighbourhood, pixels, odd >= 3
  double k = 0.5;          // gain constant of eq. 4.3, 0 < k <= 1
  double min_sigma = 2.0;  // grey levels; sigma is clamped to at least this (flat areas)
  double max_gain = 8.0;   // upper bound of A, > 0 (limits noise amplification)

  // True when the values are usable; otherwise says why in *error.
  bool IsValid(std::string* error) const;
};

// Which enhancement Enhance() applies.
enum class EnhanceMethod {
  kNone,                   // copy of the input
  kGaussian,               // thesis 4.1.3, eq. 4.4: cv::GaussianBlur with gaussian_sigma
  kDavies,                 // thesis 4.1.3, eq. 4.7: Davies' 3x3 kernel, once
  kIteratedBinomial,       // thesis 4.1.3, eq. 4.5-4.6: [1 2 1]^T[1 2 1]/16, N times
  kMedian,                 // thesis 4.1.2: median filter of median_size
  kAdaptiveContrast,       // thesis 4.1.1.1, eq. 4.2-4.3
  kHistogramEqualisation,  // thesis 4.1.1: global histogram equalisation
};

struct EnhanceParams {
  EnhanceMethod method = EnhanceMethod::kGaussian;
  double gaussian_sigma = 1.0;  // pixels, > 0; kernel spans +-3 sigma
  int binomial_iterations = 2;  // N of eq. 4.5, >= 1 (approximates sigma = sqrt(N / 2))
  int median_size = 3;          // side of the median window, pixels: 3 or 5 (thesis Fig. 4.7)
  AdaptiveContrastParams adaptive;

  // True when the parameters of the chosen method are usable; otherwise says why.
  bool IsValid(std::string* error) const;
};

// Davies' 3x3 Gaussian approximation [3 7 3; 7 16 7; 3 7 3] / 56 (eq. 4.7), CV_32FC1, sums to 1.
cv::Mat DaviesKernel();

// The 3x3 binomial kernel [1 2 1; 2 4 2; 1 2 1] / 16 (eq. 4.6), CV_32FC1, sums to 1.
cv::Mat BinomialKernel();

// Thesis 4.1.3, eq. 4.4: Gaussian smoothing with standard deviation sigma (pixels, > 0).
cv::Mat GaussianSmooth(const cv::Mat& grey, double sigma);

// Thesis 4.1.3, eq. 4.7: one convolution with DaviesKernel().
cv::Mat DaviesSmooth(const cv::Mat& grey);

// Thesis 4.1.3, eq. 4.5-4.6: `iterations` (>= 1) convolutions with BinomialKernel(),
// accumulated in floating point and rounded once; approximates a Gaussian of
// sigma = sqrt(iterations / 2).
cv::Mat IteratedBinomialSmooth(const cv::Mat& grey, int iterations);

// Thesis 4.1.2: median of the size x size neighbourhood (size 3 or 5).
cv::Mat MedianSmooth(const cv::Mat& grey, int size);

// Thesis 4.1.1.1, eq. 4.2-4.3: adaptive local contrast enhancement; raises the
// local standard deviation of low-contrast areas (and their noise).
cv::Mat AdaptiveContrast(const cv::Mat& grey, const AdaptiveContrastParams& params);

// Thesis 4.1.1, eq. 4.1: global histogram equalisation (cv::equalizeHist).
cv::Mat HistogramEqualise(const cv::Mat& grey);

// Applies params.method to a grey frame and returns the enhanced frame.
cv::Mat Enhance(const cv::Mat& grey, const EnhanceParams& params);

}  // namespace bsls::extraction

#endif  // BSLS_EXTRACTION_ENHANCE_H_
