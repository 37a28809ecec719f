// Test fixture: an ideal one-pixel skeleton of the brick pattern drawn
// straight into image space (no optics), with its true labels, and the
// defects of thesis Table 5.5 and 5.1.4.8 cut into it.
//
// Image coordinates: x right, y down, pixels.
#ifndef BSLS_TESTING_SYNTHETIC_BRICK_H_
#define BSLS_TESTING_SYNTHETIC_BRICK_H_

#include <opencv2/core.hpp>
#include <vector>

#include "bsls/pattern/brick_pattern.h"

namespace bsls::testing {

struct SyntheticBrickParams {
  pattern::Side side = pattern::Side::kLeft;
  cv::Size size{512, 512};
  pattern::PatternSpec spec{};
  int visible_lines = 14;  // lines 0 .. visible_lines-1 are drawn
  int first_row = -16;     // slide rows drawn
  int last_row = 16;
  double line_pitch = 15.0;   // px between neighbouring lines
  double row_spacing = 13.0;  // px between consecutive rows
  double line0_x = 420.0;     // px, column of line 0 at the centre row (left side)
  double centre_y = 255.5;    // px, row of v = 0
  double bend = 6.0;          // px, sideways bow of the lines over the image height
  double tilt = 0.08;         // segments' slope (dy/dx)
};

struct TruthJunction {
  int p = 0;
  int v = 0;
  pattern::JunctionKind kind = pattern::JunctionKind::kDirect;
  cv::Point2d position;
};

struct SyntheticBrick {
  cv::Mat skeleton;  // CV_8UC1, 255 = line
  std::vector<TruthJunction> junctions;
  // Image position of slide point (u, v) under this fixture's mapping.
  cv::Point2d Map(double u, double v) const;
  SyntheticBrickParams params;
};

// Draws the skeleton and lists its junctions.
SyntheticBrick DrawSyntheticBrick(const SyntheticBrickParams& params);

// A grey frame of the skeleton as a camera would see it: every stroke
// dilated to 3 px, blurred (Gaussian, 1 px), 200 grey levels on a ground of
// 20, with seeded Gaussian noise of `noise_sigma` grey levels.
cv::Mat RenderGrey(const SyntheticBrick& brick, double noise_sigma = 2.0, unsigned seed = 1);

// Cuts line 0 away (every pixel from 3 px beyond the middle between lines 0
// and 1 on), leaving line 1 outermost with the stubs of the segments that
// came from line 0: the frame a labelling must not take line 1 for line 0 in.
void CutAwayLineZero(SyntheticBrick& brick);

// The truth junction (p, v), or nullptr.
const TruthJunction* FindTruth(const SyntheticBrick& brick, int p, int v);

// Erases every skeleton pixel within `radius` of a point.
void EraseDisk(cv::Mat& skeleton, cv::Point2d centre, double radius);

// Erases the pixels of line p between slide rows v0 and v1 (v0 < v1), i.e. a
// gap in the line, leaving 2 px next to each junction untouched.
void EraseLineBetween(SyntheticBrick& brick, int p, double v0, double v1);

// Erases the middle of the segment on row v between lines p and p + 1.
void EraseSegmentMiddle(SyntheticBrick& brick, int p, int v, double fraction);

}  // namespace bsls::testing

#endif  // BSLS_TESTING_SYNTHETIC_BRICK_H_
