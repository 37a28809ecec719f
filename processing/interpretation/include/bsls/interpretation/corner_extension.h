// Thesis 5.2.3.3, ambiguity of a junction or line (Figures 5.21-5.23): where
// a line and a segment meet in a corner (a point of degree 2) the third
// stroke of the T-junction is missing, e.g. cut off by the face's outline or
// lost in a gap. The thesis extends such a point to degree 3 by adding a
// junction pixel p and an end pixel p1 one pixel on, along the line; the
// junction can then be found and labelled, and the end takes part in the
// repairs like any other.
//
// Image coordinates: x right, y down; the skeleton is CV_8UC1, non-zero = line.
#ifndef BSLS_INTERPRETATION_CORNER_EXTENSION_H_
#define BSLS_INTERPRETATION_CORNER_EXTENSION_H_

#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "bsls/interpretation/skeleton_graph.h"

namespace bsls::interpretation {

struct CornerParams {
  int leg = 5;                    // px of each leg used to measure its direction
  double leg_tolerance_deg = 40;  // how far a leg may lean from vertical / horizontal
  int stub = 3;                   // px added along the line beyond the corner (a shorter
                                  // stub melts into the corner's pixel cluster)
  // px: a segment whose far end is free (its partner line unseen) still makes
  // a corner when at least this long and the stripe mask shows the line going
  // on; shorter ones are hooks at line ends.
  int min_free_segment = 15;
  // px: the same for a corner whose line runs out of the imaged area (its
  // stub would leave the frame): there the corner is a T that the frame's
  // edge cut, not a hook at a line's end, and the segment along the edge is
  // often broken (half its profile is outside the frame).
  int min_free_segment_at_edge = 6;
  // px: the same for a corner that sits where the pattern puts the line's
  // next junction: one row pitch (within pitch_tolerance of the median
  // distance between neighbouring junctions along lines) from a T-junction
  // of its line whose segment leaves on the other side (the brick pattern's
  // segments alternate sides along a line). There the short segment is one
  // that the face's outline cut (the chin, the forehead's top), not a hook.
  int min_free_segment_in_pattern = 6;
  double pitch_tolerance = 0.3;  // fraction of the row pitch, in (0, 1)

  // True when the numbers are usable; otherwise says why.
  bool IsValid(std::string* error) const;
};

// Finds the corners on the graph's chains and draws their stubs into
// `skeleton`; returns the corner pixels extended. With a stripe mask (CV_8UC1,
// non-zero = stripe, e.g. the one the skeleton was thinned from), a stub is
// drawn only where the mask shows the line going on beyond the corner, i.e.
// where thinning or pruning lost a short stroke; a corner where a line really
// turns (along the face's outline) is left alone. `imaged` is the part of
// `skeleton` the camera saw (empty: all of it); beyond it lies a margin that
// takes the stubs of corners at the frame's edge.
std::vector<cv::Point> ExtendCorners(const SkeletonGraph& graph, const CornerParams& params,
                                     cv::Mat& skeleton, const cv::Mat& stripe_mask = cv::Mat(),
                                     cv::Rect imaged = cv::Rect());

}  // namespace bsls::interpretation

#endif  // BSLS_INTERPRETATION_CORNER_EXTENSION_H_
