// Thesis 5.2.2: the features of the common line (the reference line, p = 0,
// on the facial midline) that the two sides are matched on: the turning
// points of its depth profile, the nose and the mouth.
//
// Frame and units: the frame of the curve's points (a side's own world frame,
// contracts section 3), millimetres. The profile is the height z as a
// function of y, read from the top of the face (largest y) downwards; "below"
// means smaller y.
#ifndef BSLS_JOINING_FEATURES_H_
#define BSLS_JOINING_FEATURES_H_

#include <Eigen/Core>
#include <string>
#include <vector>

#include "bsls/joining/stripe_curve.h"

namespace bsls::joining {

struct FeatureParams {
  // The profile is resampled on a regular y grid of this step (mm, > 0).
  double resample_step_mm = 0.5;
  // Gaussian smoothing of the resampled profile, sigma along y (mm, >= 0):
  // removes the turning points of noise (thesis eq. 5.32 is a 3-tap version).
  double smoothing_mm = 1.5;
  // A turning point counts only when the profile turns back by at least this
  // much on both sides of it (mm, > 0): a hysteresis on eq. 5.33's sign test.
  double min_turn_mm = 0.5;
  // The mouth (its minimum) lies this far below the nose tip, along y (mm,
  // 0 < min < max): keeps the nostrils' and the chin's turns out of it
  // (adult faces: about 25-40 mm).
  double min_nose_to_mouth_mm = 15.0;
  double max_nose_to_mouth_mm = 50.0;

  // True when the numbers are in range; otherwise names the field and why.
  bool IsValid(std::string* error) const;
};

// A point where the profile's gradient changes sign.
struct TurningPoint {
  Eigen::Vector3d position = Eigen::Vector3d::Zero();  // on the (smoothed) profile, mm
  bool maximum = false;  // a peak of z (towards the cameras); else a valley
};

// The features of one side's common line.
struct LineFeatures {
  std::vector<TurningPoint> turning_points;  // top to bottom
  // Thesis 5.2.2: the nose, and the mouth as top lip (max), mouth (min),
  // bottom lip (max); indices into turning_points. A top lip that is no
  // turning point of z (a philtrum sloping back, as on the simulator's face)
  // is a turning point of the profile seen along the nose-to-mouth line (the
  // last maximum after a minimum there), inserted into turning_points.
  int nose = -1;
  int upper_lip = -1;
  int mouth = -1;
  int lower_lip = -1;

  // Positions of nose, upper lip, mouth, lower lip (in that order).
  std::vector<Eigen::Vector3d> ControlPoints() const;
};

// Thesis 5.2.2: turning points of the profile z(y) of `curve` (eq. 5.33 on
// the smoothed profile, with the min_turn hysteresis); the nose is the
// maximum of largest z that is not the lowest turning point; the mouth is the
// first maximum/minimum/maximum below it whose minimum lies within the
// nose-to-mouth range, or else the valley right after the nose with the top
// lip found on the profile relative to the nose-to-mouth line (see
// LineFeatures). Throws JoinError(kFeaturesNotFound) naming `side` when
// the curve is too short or no nose or mouth is found; `params` must be valid.
LineFeatures FindLineFeatures(const StripeCurve& curve, const FeatureParams& params,
                              const std::string& side);

}  // namespace bsls::joining

#endif  // BSLS_JOINING_FEATURES_H_
