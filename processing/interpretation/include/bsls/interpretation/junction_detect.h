// T-junction detection and classification, thesis algorithm 5.2.3.1
// (Figure 5.18-5.20): a square window grown around a candidate pixel, the
// connected subsets of skeleton pixels on its border, the shortest paths from
// them to the candidate, and the angles of those paths.
//
// Image coordinates: x right, y down. The skeleton is CV_8UC1, non-zero = line.
#ifndef BSLS_INTERPRETATION_JUNCTION_DETECT_H_
#define BSLS_INTERPRETATION_JUNCTION_DETECT_H_

#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "bsls/pattern/brick_pattern.h"

namespace bsls::interpretation {

// Thesis a_t: 0 corresponding, 1 direct, 3 and 4 crossing points of three or
// four lines that do not make a T-junction of the pattern.
enum class JunctionAttribute { kCorresponding = 0, kDirect = 1, kCross3 = 3, kCross4 = 4 };

struct JunctionParams {
  int max_radius = 3;  // the 7x7 window of the thesis
  int min_radius = 2;  // the 5x5 fall-back window
  // How far (degrees) a path may lean from vertical and still be a line, or
  // from horizontal and still be a segment (thesis: compared with 0 and 45).
  // A line may lean far: on a skirt turned away from the projector (a lump's,
  // the outer cheek) it runs at 60-75 degrees; of three branches the segment
  // is still the most horizontal one.
  double vertical_tolerance_deg = 80.0;
  double horizontal_tolerance_deg = 55.0;
  // How far (degrees) the two line paths may be from opposite (a line can
  // fold sharply at a junction, e.g. at the lips).
  double opposite_tolerance_deg = 89.0;
  // px: the longest edge from a junction to a neighbouring junction that
  // takes it for its line, read as a line merging at a fold (JunctionNetwork).
  int max_merge_edge = 4;

  // True when the numbers are usable; otherwise says why.
  bool IsValid(std::string* error) const;
};

struct JunctionDetection {
  bool is_junction = false;  // false: a degree-2 point (stage 3)
  JunctionAttribute attribute = JunctionAttribute::kCross3;
  cv::Point2d centre;  // the junction centre point (JCP), sub-pixel
  int radius = 0;      // window radius used
  // Border pixels with the shortest paths (stage 4); side is (-1, -1) for crossings.
  cv::Point top{-1, -1}, bottom{-1, -1}, side{-1, -1};
  std::vector<cv::Point> border;  // every border pixel kept, one per subset
};

// Thesis 5.2.3.1 stages 2-7 for one candidate pixel, for the brick slide of
// `side` (whose segments leave direct junctions towards growing p).
JunctionDetection DetectJunction(const cv::Mat& skeleton, cv::Point candidate, pattern::Side side,
                                 const JunctionParams& params = {});

// The attribute a T-junction with a segment leaving towards image direction
// `side_dx` (< 0 left, > 0 right) has on `side`.
JunctionAttribute AttributeForSegment(pattern::Side side, double side_dx);

// True for the two attributes of pattern junctions.
inline bool IsPatternJunction(JunctionAttribute a) {
  return a == JunctionAttribute::kDirect || a == JunctionAttribute::kCorresponding;
}

}  // namespace bsls::interpretation

#endif  // BSLS_INTERPRETATION_JUNCTION_DETECT_H_
