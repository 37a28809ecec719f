// Row bands of an image processed in parallel (not installed).
#ifndef BSLS_EXTRACTION_SRC_BANDS_H_
#define BSLS_EXTRACTION_SRC_BANDS_H_

#include <algorithm>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

namespace bsls::extraction::internal {

// Rows per band: large enough that the halo rows a band's filters read
// beyond it cost little, small enough that a band's buffers stay in cache.
constexpr int kBandRows = 64;

// Calls body(first_row, end_row) for consecutive bands of kBandRows rows
// covering 0 .. rows - 1, on OpenCV's thread pool (cv::parallel_for_);
// bands may run concurrently and in any order, so body must write only its
// own rows.
template <typename Body>
void ForEachBand(int rows, const Body& body) {
  const int count = (rows + kBandRows - 1) / kBandRows;
  cv::parallel_for_(cv::Range(0, count), [&](const cv::Range& r) {
    for (int b = r.start; b < r.end; ++b) body(b * kBandRows, std::min(rows, (b + 1) * kBandRows));
  });
}

// The Gaussian smoothing of a CV_8UC1 or CV_32FC1 image as CV_32FC1: the
// separable kernel of 2 half + 1 taps of cv::getGaussianKernel, borders
// replicated -- what cv::GaussianBlur does to the image converted to float,
// without the conversion. On a ROI the filter reads the parent image beyond
// the ROI, so a band of rows comes out exactly as in the whole image.
inline void GaussianInto(const cv::Mat& src, double sigma, int half, cv::Mat* out) {
  const cv::Mat kernel = cv::getGaussianKernel(2 * half + 1, sigma, CV_32F);
  cv::sepFilter2D(src, *out, CV_32F, kernel, kernel, cv::Point(-1, -1), 0.0, cv::BORDER_REPLICATE);
}

// GaussianInto over the whole image, band by band in parallel, into *out
// (CV_32FC1 of src's size, e.g. a ROI of a larger buffer).
inline void GaussianBandsInto(const cv::Mat& src, double sigma, int half, cv::Mat* out) {
  ForEachBand(src.rows, [&](int y0, int y1) {
    cv::Mat rows = out->rowRange(y0, y1);
    GaussianInto(src.rowRange(y0, y1), sigma, half, &rows);
  });
}

}  // namespace bsls::extraction::internal

#endif  // BSLS_EXTRACTION_SRC_BANDS_H_
