// Private to bsls::decoder: the working resolution of the topology stages
// (docs/decoding.md, "Frame size"). Feature extraction and interpretation
// have pixel-sized parameters tuned for stripes about 10-21 px apart (the
// thesis's 512 x 512 frames); a frame with a wider pitch is binned n x n for
// them, as a sensor bins its pixels, and what they found is mapped back onto
// the full frame, where the sub-pixel centres are measured.
//
// Coordinates: pixel (x, y) of the binned frame covers the full frame's
// pixels n x .. n x + n - 1 (and likewise in y), so its centre is at
// n x + (n - 1) / 2 in full-frame pixel coordinates (origin at the centre of
// the top-left pixel, contracts section 5).
#ifndef BSLS_DECODER_SRC_WORKING_RESOLUTION_H_
#define BSLS_DECODER_SRC_WORKING_RESOLUTION_H_

#include <opencv2/core.hpp>

#include "bsls/decoder/decoder.h"
#include "bsls/interpretation/interpreter.h"

namespace bsls::decoder::internal {

// The binning n for a frame of measured stripe pitch `pitch` (px; 0: none):
// params.binning when set, else round(pitch / tuned_pitch) within
// 1..params.max_binning.
int BinningFor(double pitch, double tuned_pitch, const DecodeParams& params);

// The frame (CV_8UC1) binned n x n: every block of n x n pixels averaged
// and rounded into one; the last cols % n columns and rows % n rows, which
// fill no whole block, are left out. n == 1 returns the frame itself.
cv::Mat BinFrame(const cv::Mat& grey, int n);

// The grey levels of a CV_8UC1 image counted: the frame check's range and
// the dark ground of PatternColumns.
class GreyHistogram {
 public:
  explicit GreyHistogram(const cv::Mat& grey);
  // The lowest level at or below which at least `fraction` of the pixels lie.
  int Percentile(double fraction) const;
  // The share of the pixels at `level` or above.
  double ShareFrom(int level) const;

 private:
  int count_[256] = {};
  double total_ = 0.0;
};

// The columns of `grey` (CV_8UC1) that can hold the pattern, as a rectangle
// of full height: from `margin` px left of the first to `margin` px right of
// the last column of 4 x 4 blocks whose mean rises more than `rise` grey
// levels above the frame's dark ground (the 5th percentile of the block
// means), the left edge on the binning grid of n. The whole frame when no
// block is that bright or `rise` is 0. Only columns are cut: the
// interpretation finds the reference line among the frame's central rows.
cv::Rect PatternColumns(const cv::Mat& grey, int n, double rise, int margin);

// The track chain's working frame: full-frame pixels per working pixel along
// x and y (above 1: the frame was reduced, below 1: enlarged).
struct WorkingScale {
  double x = 1.0, y = 1.0;

  bool IsIdentity() const { return x == 1.0 && y == 1.0; }
  // A working frame's point in full-frame pixel coordinates (pixel centres
  // at whole numbers in both).
  cv::Point2d ToFull(const cv::Point2d& p) const {
    return {(p.x + 0.5) * x - 0.5, (p.y + 0.5) * y - 0.5};
  }
};

// The factor (full-frame px per working px) that brings a measured stripe
// pitch `pitch` (px; 0: none) to the track chain's tuned pitch:
// params.binning when set; 1 when the pitch is unknown or within the
// chain's native range; otherwise pitch / tuned_pitch within
// [min_scale, params.max_binning].
double WorkingFactor(double pitch, const DecodeParams& params);

// `grey` (CV_8UC1) resampled by `factor` (full px per working px) into
// `working`: reduced by area averaging (a whole factor is the exact block
// mean), enlarged by cubic interpolation; the frame itself for factor 1.
// Returns the exact scale of the sizes made.
WorkingScale ResampleFrame(const cv::Mat& grey, double factor, cv::Mat* working);

// A binned frame's point in full-frame pixel coordinates.
cv::Point2d ToFullFrame(const cv::Point2d& p, int n);

// Maps an interpretation of the n x n binned frame of the part of the full
// frame from `offset` on onto the full frame of `full` size: the skeleton
// and every labelled line are redrawn through the full-frame centres of
// their pixels (8-neighbours joined by straight runs, so they stay
// connected), each junction's segment likewise in its order, junction
// positions moved; the labels are kept. The reference line, repairs,
// corners and boundary records stay in working coordinates (nothing after
// the interpretation reads them).
void MapToFullFrame(int n, cv::Point offset, cv::Size full,
                    interpretation::InterpretationResult* r);

}  // namespace bsls::decoder::internal

#endif  // BSLS_DECODER_SRC_WORKING_RESOLUTION_H_
