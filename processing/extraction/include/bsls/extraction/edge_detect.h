// Edge detection and thresholding (thesis 4.2).
//
// Images: grey inputs are CV_8UC1; magnitude / response images are CV_32FC1
// in grey levels per pixel (first derivatives) or grey levels per pixel^2
// (Laplacians); binary outputs are CV_8UC1 with 0 = background and
// 255 = edge. x = column, y = row, origin at the top-left pixel centre.
// Borders are replicated (cv::BORDER_REPLICATE).
//
// Note on stripes: the first-derivative detectors (Sobel, Canny) answer on
// both flanks of a bright stripe, two responses per stripe; the Laplacian
// answers on its centre (thesis 4.2.1-4.2.3 and 4.5).
//
// Errors: empty images, wrong image types and parameters that fail IsValid
// throw std::invalid_argument("<Function>: <reason>").
//
// Thread-safety: pure functions of their arguments.
#ifndef BSLS_EXTRACTION_EDGE_DETECT_H_
#define BSLS_EXTRACTION_EDGE_DETECT_H_

#include <opencv2/core.hpp>
#include <optional>
#include <span>
#include <string>

namespace bsls::extraction {

// Thesis 4.2 (text before 4.2.1), after Parker [70]: the automatic two-peak
// threshold. The histogram is smoothed by a moving average; the first peak is
// its highest bin p1; the second peak is the bin p2 maximising
// (p2 - p1)^2 * h(p2) (a peak far from the first one); the threshold is the
// lowest bin strictly between the two peaks.
struct TwoPeakParams {
  int smoothing_radius = 2;     // bins; moving-average half-width, >= 0
  int min_peak_separation = 3;  // bins; the peaks must be at least this far apart, >= 2

  // True when the values are usable; otherwise says why.
  bool IsValid(std::string* error) const;
};

// Bin indices found by TwoPeakThreshold: low_peak < threshold < high_peak.
struct TwoPeakResult {
  int low_peak = 0;   // the peak with the smaller bin index
  int high_peak = 0;  // the peak with the larger bin index
  int threshold = 0;  // the histogram minimum between them
};

// Thesis 4.2: two-peak threshold of a histogram (counts >= 0, any scale);
// nullopt when there are no two peaks min_peak_separation apart with a lower
// bin between them (e.g. an empty or unimodal histogram).
std::optional<TwoPeakResult> TwoPeakThreshold(std::span<const double> histogram,
                                              const TwoPeakParams& params);

// Thesis 4.2: two-peak threshold of a non-negative image (CV_8U/16U/16S/32F,
// one channel) using `bins` equal bins over [0, max]; the value returned is in
// the image's units (the lower edge of the threshold bin). nullopt as above,
// or when the image is constant zero.
std::optional<double> TwoPeakThresholdOfImage(const cv::Mat& magnitude, int bins,
                                              const TwoPeakParams& params);

// Thresholding with hysteresis (thesis 4.2, 4.2.3): a pixel is set when it is
// >= low and 8-connected through pixels >= low to a pixel >= high.
// `magnitude` is single-channel 8U/16U/16S/32F; requires low <= high.
cv::Mat HysteresisThreshold(const cv::Mat& magnitude, double low, double high);

// How the detectors below binarise their response.
struct EdgeThresholdParams {
  bool automatic = true;     // true: two-peak threshold of the response histogram
  double fixed = 50.0;       // single-band threshold when !automatic, response units, > 0
  int histogram_bins = 256;  // bins of the automatic threshold, >= 16
  TwoPeakParams two_peak;
  // Used when automatic and the histogram has no two peaks: the threshold
  // becomes the (1 - fallback_fraction) quantile of the response.
  double fallback_fraction = 0.1;

  // True when the values are usable; otherwise says why.
  bool IsValid(std::string* error) const;
};

// Thesis 4.2.1, eq. 4.11-4.12: |Gx| + |Gy| with the 3x3 Sobel masks, CV_32FC1.
cv::Mat SobelMagnitude(const cv::Mat& grey);

// Thesis 4.2.1: SobelMagnitude binarised by a single-band threshold (0/255).
cv::Mat SobelEdges(const cv::Mat& grey, const EdgeThresholdParams& params);

// The two Laplacian masks of the thesis: h1 (eq. 4.15) uses the 4-neighbours
// [0 -1 0; -1 4 -1; 0 -1 0], h2 (eq. 4.16) the 8-neighbours [-1 ... 8 ... -1].
enum class LaplacianMask { kH1FourNeighbour, kH2EightNeighbour };

// The 3x3 mask of eq. 4.15 or 4.16 as CV_32FC1 (sums to 0).
cv::Mat LaplacianKernel(LaplacianMask mask);

// Thesis 4.2.2: Laplacian of Gaussian, Gaussian smoothing of `sigma` pixels
// (0 = none) then the mask; CV_32FC1, positive on bright ridges (the masks are
// minus the Laplacian).
cv::Mat LaplacianOfGaussian(const cv::Mat& grey, double sigma, LaplacianMask mask);

struct LaplacianParams {
  double sigma = 1.0;  // pixels, >= 0 (0 = no smoothing)
  LaplacianMask mask = LaplacianMask::kH2EightNeighbour;
  EdgeThresholdParams threshold;  // applied to the positive part of the response

  // True when the values are usable; otherwise says why.
  bool IsValid(std::string* error) const;
};

// Thesis 4.2.2: pixels whose LoG response exceeds the threshold (0/255).
cv::Mat LaplacianEdges(const cv::Mat& grey, const LaplacianParams& params);

// Thesis 4.2.3: Canny's detector with hysteresis (cv::Canny on our own Sobel
// derivatives), thresholds from the two-peak method on the gradient magnitude.
struct CannyParams {
  double sigma = 1.0;        // Gaussian pre-smoothing, pixels, >= 0 (0 = none)
  bool l2_gradient = true;   // magnitude sqrt(Gx^2 + Gy^2) (true) or |Gx| + |Gy|
  bool automatic = true;     // thresholds from the two-peak method
  double low_ratio = 0.5;    // automatic: low = low_ratio * high, in (0, 1]
  double high = 120.0;       // fixed thresholds when !automatic (3x3 Sobel units), > 0
  double low = 60.0;         // fixed, 0 < low <= high
  int histogram_bins = 256;  // bins of the automatic threshold, >= 16
  TwoPeakParams two_peak;
  double fallback_fraction = 0.1;  // as in EdgeThresholdParams

  // True when the values are usable; otherwise says why.
  bool IsValid(std::string* error) const;
};

// The thresholds CannyEdges uses for this image, in 3x3-Sobel magnitude units.
struct CannyThresholds {
  double low = 0.0;
  double high = 0.0;
  bool from_two_peaks = false;  // false: fixed thresholds or the quantile fallback
};

// Thesis 4.2.3: the thresholds CannyEdges would use on `grey`.
CannyThresholds ChooseCannyThresholds(const cv::Mat& grey, const CannyParams& params);

// Thesis 4.2.3: thin (non-maximum suppressed) Canny edges, 0/255.
cv::Mat CannyEdges(const cv::Mat& grey, const CannyParams& params);

}  // namespace bsls::extraction

#endif  // BSLS_EXTRACTION_EDGE_DETECT_H_
