// Finds the calibration target of contracts section 3 in one camera image:
// rows x cols dark squares on a white ground, each with its sub-pixel centre
// of gravity and its (row, col) in the grid (thesis 6.1: "the squares were
// detected in the camera images by using auto extraction algorithm and their
// centres of gravity were used as the calibration points"; thesis 6.3).
//
// Stages: local-mean threshold; connected dark regions kept as squares by
// area, convexity, fill of their minimum-area rectangle, aspect and similar
// size; a grey-level centre of gravity of each square's darkness (the local
// white level, fitted as a plane on the ground around the square, minus the
// grey level) over the square and a small border; the grid fitted through a
// homography from its four extreme corners, refitted on all squares, and
// every square assigned to the nearest grid node.
//
// Coordinates: image pixels, x = column, y = row, origin at the centre of the
// top-left pixel (contracts section 5). Ordering (contracts section 3): row 0
// is the top row and column 0 the left-most as seen in the image; the grid may
// be seen in perspective and rotated by less than 45 degrees.
//
// A view where the full grid is not found (a square missing, cut by the image
// border, an extra square-like blob, squares that do not form the grid) comes
// back with ok == false and a reason; never a partial grid.
//
// Thread-safety: DetectTarget is a pure function of its arguments.
#ifndef BSLS_CALIBRATION_TARGET_DETECT_H_
#define BSLS_CALIBRATION_TARGET_DETECT_H_

#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "bsls/calibration/manifest.h"

namespace bsls::calibration {

struct TargetDetectParams {
  // Thresholding: a pixel is dark when it lies more than threshold_offset
  // grey levels below the mean of the threshold_block_px square around it.
  // The block must be at least about twice a square's size in the image.
  int threshold_block_px = 51;     // odd, >= 3
  double threshold_offset = 15.0;  // grey levels, > 0
  double pre_blur_sigma_px = 0.8;  // Gaussian before thresholding only; 0 = none

  // Shape filters of a candidate square (its outer contour).
  int min_area_px = 12;             // pixels, >= 4
  double max_area_fraction = 0.02;  // of the image area, (0, 1]
  // Ratios of pixel counts: pixels / pixels of the convex hull, and pixels /
  // pixels of the minimum-area rectangle (about 0.9 for squares of 8 x 8 px
  // seen obliquely, 0.5 for a triangle).
  double min_solidity = 0.85;   // (0, 1]
  double min_fill = 0.65;       // (0, 1]
  double max_aspect = 3.0;      // long / short side of that rectangle, >= 1
  double max_area_ratio = 2.5;  // to the median candidate area (either way), > 1
  // A candidate whose nearest other candidate is further away than this times
  // the median nearest-neighbour distance is clutter, not part of the grid.
  double max_isolation = 2.5;  // > 1

  // Grid: a square further than this (in grid cells) from its grid node
  // under the fitted homography makes the grid unorderable.
  double max_grid_residual = 0.3;  // cells, in (0, 0.5)

  // Centre of gravity: pixels within centroid_border_px of the square's
  // thresholded region (and nearer to it than to any other square) are
  // weighted by their darkness, so the whole blurred edge counts. The white
  // level is a plane fitted to the ground: pixels further than
  // ground_clearance_px from every square, within centroid_border_px +
  // ground_window_px of this one.
  int centroid_border_px = 3;   // >= 0
  int ground_clearance_px = 2;  // >= 0
  int ground_window_px = 4;     // >= 1

  // True when every field is in range; otherwise names the field and why.
  bool IsValid(std::string* error) const;
};

// One square of the grid.
struct TargetSquare {
  int row = 0;           // 0 = top row in the image
  int col = 0;           // 0 = left-most column in the image
  cv::Point2d centre;    // sub-pixel centre of gravity, image pixels
  double area_px = 0.0;  // thresholded region, pixels
};

struct TargetDetection {
  bool ok = false;
  std::string error;   // why the full grid was not found (ok == false)
  int candidates = 0;  // dark blobs accepted as squares before the grid fit
  // When ok: rows x cols squares, row-major (index row * cols + col).
  std::vector<TargetSquare> squares;
  double max_grid_residual = 0.0;  // cells: worst square vs its node (ok == true)
};

// Detects the full rows x cols grid of `target` (pitch and square size are
// not used: the image scale is unknown). Throws CalibrationError
// (kInvalidInput) for an empty or non-CV_8UC1 image, (kInvalidParams) for
// invalid params or target.
TargetDetection DetectTarget(const cv::Mat& grey, const TargetGeometry& target,
                             const TargetDetectParams& params = {});

}  // namespace bsls::calibration

#endif  // BSLS_CALIBRATION_TARGET_DETECT_H_
