// What a calibration tells the decoder about labels (issue 25 part 4 in
// docs/decoding.md, "Islands placed by the geometry"): a part of the frame
// that no path of proven links joins to line 0 (the base plane beside an
// object, a region cut off by a shadow or an occluding edge) is labelled
// relative to itself, so its labels are known up to one shift (dp, dq). A
// calibrated side can say which shift, if any, the geometry allows: every
// junction's candidate labels are the projector's junctions along its
// epipolar line inside the measuring volume. The decoder asks through this
// interface; the calibration's implementation lives with reconstruction
// (bsls/reconstruction/island_placement.h), so the decoder does not depend on
// calibration.
//
// Coordinates: image pixels of the full frame, x = column, y = row.
// Thread-safety: implementations are immutable and safe to share.
#ifndef BSLS_DECODER_LABEL_GEOMETRY_H_
#define BSLS_DECODER_LABEL_GEOMETRY_H_

#include <opencv2/core.hpp>
#include <optional>
#include <string>
#include <vector>

#include "bsls/pattern/brick_pattern.h"

namespace bsls::decoder {

// A junction as the geometry sees it: where it is and its label in some
// frame (line 0's relative rows, or an island's own labels).
struct FramedJunction {
  cv::Point2d position;  // image pixels
  int p = 0;
  int q = 0;
};

// A shift of labels: (p + dp, q + dq), dp + dq even, and the junctions
// whose own place the geometry rules out under it.
struct LabelShift {
  int dp = 0;
  int dq = 0;
  // Per junction of the island judged: 1 where, shifted, it does not land on
  // its row (a label inside the island that is wrong) or cannot be placed.
  std::vector<char> ruled_out;
};

// A calibrated side's judgement of labels.
class LabelGeometry {
 public:
  virtual ~LabelGeometry() = default;

  // The one shift that takes `island`'s relative labels into the frame of
  // `labelled` (line 0's component, p absolute, q relative to its own even
  // offset), where the geometry allows exactly one, with the junctions it
  // rules out; nullopt, with the reason in `why`, where it allows none or
  // cannot tell the candidates apart. Asked with `island` == `labelled`, it
  // judges line 0's component itself ({0, 0} where it confirms it).
  virtual std::optional<LabelShift> PlaceIsland(const std::vector<FramedJunction>& labelled,
                                                const std::vector<FramedJunction>& island,
                                                std::string* why) const = 0;

  // Per junction of `labelled` (labels in one frame, p absolute): 1 where
  // the geometry rules its label out (its junction does not land on its
  // row, or on the slide, under the frame's own rows); all 0 where there are
  // too few junctions to fix the rows.
  virtual std::vector<char> RuleOut(const std::vector<FramedJunction>& labelled) const = 0;
};

}  // namespace bsls::decoder

#endif  // BSLS_DECODER_LABEL_GEOMETRY_H_
