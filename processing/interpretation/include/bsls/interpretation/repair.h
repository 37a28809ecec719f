// Repair of discontinuities found by loop and boundary tracing: thesis
// 5.1.4.4 (one and double breaks), 5.1.4.5 (a missing junction), 5.1.4.6-7
// (two missing junctions, large areas, corrected line by line), 5.1.4.8
// (overlaps: the crossing point taken as the missing end point) and boundary
// correction 5.2.3.4. Every repair is a Bresenham fill (5.2.2) between end
// points of one loop, or from an end point to the line it should meet.
//
// Image coordinates: x right, y down; lengths in pixels.
#ifndef BSLS_INTERPRETATION_REPAIR_H_
#define BSLS_INTERPRETATION_REPAIR_H_

#include <string>
#include <string_view>
#include <vector>

#include "bsls/interpretation/loop_trace.h"

namespace bsls::interpretation {

struct RepairParams {
  double max_line_gap = 40.0;       // px: longest gap sealed on a line (TEP-BEP)
  double max_segment_gap = 22.0;    // px: longest gap sealed on a segment (LEP-REP)
  double max_segment_reach = 20.0;  // px: how far a segment end is extended to meet a line
  double max_line_reach = 8.0;      // px: how far a line end is extended to meet a segment
  // Largest sideways miss (px) of an end's extrapolated direction at its
  // partner, as a fraction of the gap plus a constant.
  double miss_fraction = 0.25;
  double miss_constant = 2.0;
  int direction_probe = 6;  // px of the piece used to extrapolate an end
  // px: an end extended onto a line must meet it at least this far from the
  // line's junctions (two junctions cannot sit closer on one line).
  double min_junction_distance = 6.0;

  // True when the numbers are usable; otherwise says why.
  bool IsValid(std::string* error) const;
};

enum class RepairKind {
  kLineGap,       // TEP-BEP sealed
  kSegmentGap,    // LEP-REP sealed
  kSegmentReach,  // a segment end extended to a line: a new junction
  kLineReach,     // a line end extended to a segment or line
};

// "line_gap", "segment_gap", "segment_reach" or "line_reach".
std::string_view ToString(RepairKind kind);

struct Repair {
  RepairKind kind = RepairKind::kLineGap;
  cv::Point from, to;
  LoopClass loop_class = LoopClass::kIncomplete;  // class of the loop it was found in
};

// Plans the repairs of one round over all loops (boundary included) and
// draws them into `skeleton`. Line gaps are sealed before segments are
// extended, so that a segment end can meet a line sealed in the same round
// (thesis 5.1.4.5). Returns the repairs made.
std::vector<Repair> RepairRound(const JunctionNetwork& network,
                                const std::vector<LoopRecord>& loops, const RepairParams& params,
                                cv::Mat& skeleton);

}  // namespace bsls::interpretation

#endif  // BSLS_INTERPRETATION_REPAIR_H_
