// Slide 1, the reference cross (contracts section 1, thesis Figure 1.1): one
// vertical and one horizontal line through the slide centre (u, v) = (0, 0).
// Seen on the calibration screen, the image point of its centre ties the
// brick slide's relative rows q to the slide rows v (contracts section 2):
// the brick's line 0 and its row v = 0 pass through the same world point.
//
// Coordinates: image pixels, x = column, y = row, origin at the centre of
// the top-left pixel (contracts section 5).
#ifndef BSLS_CALIBRATION_REFERENCE_CROSS_H_
#define BSLS_CALIBRATION_REFERENCE_CROSS_H_

#include <opencv2/core.hpp>
#include <optional>
#include <string>
#include <vector>

#include "bsls/extraction/feature_extraction.h"
#include "bsls/extraction/stripe_centre.h"

namespace bsls::calibration {

struct CrossParams {
  extraction::ExtractionParams extraction;  // finds the two strokes' skeleton
  extraction::StripeCentreParams centre;    // sub-pixel centres across each stroke
  int min_arm_px = 20;       // each stroke must show this much on both sides of the centre
  int clearance_px = 6;      // samples this close to the other stroke are biased: skipped
  int fit_reach_px = 120;    // samples this far from the centre are fitted (a parabola
                             // each, which follows the camera's distortion)
  double max_rms_px = 0.5;   // a stroke whose centres scatter more is not a line
  double max_lean_deg = 20;  // how far the strokes may lean from vertical / horizontal

  // True when the numbers are usable; otherwise says why.
  bool IsValid(std::string* error) const;
};

struct ReferenceCross {
  cv::Point2d centre;                   // image point of slide point (0, 0)
  std::vector<cv::Point2d> vertical;    // sub-pixel centres of the vertical stroke (one per row)
  std::vector<cv::Point2d> horizontal;  // ... of the horizontal stroke (one per column)
  double vertical_rms_px = 0;           // scatter of each about its fit
  double horizontal_rms_px = 0;
};

// Finds the cross in a CV_8UC1 frame of slide 1 on a plane. nullopt, with
// the reason in `why`, when either stroke is missing, too short on a side of
// the centre, or not straight enough; a frame of another slide (the brick)
// is refused, never read as a cross. Throws std::invalid_argument for an
// empty or non-CV_8UC1 frame or invalid params.
std::optional<ReferenceCross> FindReferenceCross(const cv::Mat& grey, const CrossParams& params,
                                                 std::string* why);

}  // namespace bsls::calibration

#endif  // BSLS_CALIBRATION_REFERENCE_CROSS_H_
