// Ridge points: the bright stripes' crossings of every image row, found as
// local maxima of the smoothed grey level that fall off on both sides (not a
// thesis algorithm: the thesis finds stripe pixels with a threshold or edge
// detector, 4.2, and thins them, 4.3; this finds each stripe's centre in a
// row directly, docs/decoding.md "The track chain").
//
// A vertical line crosses a row as a narrow peak; a horizontal segment lying
// along the row is a plateau there, with no fall on its own side, and is not
// a ridge point of the row. Run on the transposed image, the same function
// finds the segments' crossings of the columns.
//
// Images: CV_8UC1, x = column, y = row. Positions: pixels, origin at the
// centre of the top-left pixel.
//
// Thread-safety: pure function of its arguments.
#ifndef BSLS_EXTRACTION_RIDGE_POINTS_H_
#define BSLS_EXTRACTION_RIDGE_POINTS_H_

#include <opencv2/core.hpp>
#include <span>
#include <string>
#include <vector>

#include "bsls/common/cancellation.h"

namespace bsls::extraction {

struct RidgeParams {
  // px: a ridge point must fall by min_prominence within this many pixels on
  // each side: more than a stripe's half width and blur, less than the gap
  // to the next stripe (the pitch minus a stripe width), 1..64.
  int half_window = 8;
  // grey levels (of the smoothed image): the smaller of the two falls, 1..255.
  int min_prominence = 6;

  // True when the values are usable; otherwise says why.
  bool IsValid(std::string* error) const;
};

struct RidgePoint {
  float x = 0;         // sub-pixel column of the peak (parabola through three pixels)
  int y = 0;           // row
  int prominence = 0;  // grey levels: the smaller fall within half_window
};

// The ridge points of an image, row by row, each row's from left to right.
struct RidgePoints {
  std::vector<RidgePoint> points;
  std::vector<int>
      row_start;  // rows + 1 entries: row y holds points [row_start[y], row_start[y+1])

  // The points of row y (empty outside the image).
  std::span<const RidgePoint> Row(int y) const;
};

// The ridge points along the rows of `smoothed` (CV_8UC1; the caller smooths,
// e.g. a Gaussian of 1 px). A plateau (equal neighbours) is one point at its
// middle. Throws std::invalid_argument for an empty or non-CV_8UC1 image or
// invalid params; asks `cancel` once per band of rows (Cancelled).
RidgePoints FindRidgePoints(const cv::Mat& smoothed, const RidgeParams& params = {},
                            const Cancellation& cancel = {});

// The same along the columns: FindRidgePoints of the transposed image,
// without transposing it. A point's x is its sub-pixel row, its y its
// column, and RidgePoints::Row(x) holds column x's points from top to bottom;
// asks `cancel` once per block of columns.
RidgePoints FindColumnRidgePoints(const cv::Mat& smoothed, const RidgeParams& params = {},
                                  const Cancellation& cancel = {});

}  // namespace bsls::extraction

#endif  // BSLS_EXTRACTION_RIDGE_POINTS_H_
