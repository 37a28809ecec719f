// Reference-line tracing of thesis 5.2.1: find where a "moving" vertical line
// first meets line 0 (the reference line, right-most lit line on the left
// side, left-most on the right side), then follow line 0 forwards (down) and
// backwards (up) with the priority scan areas of Figures 5.5-5.8, sealing each
// gap with the line filling of 5.2.2.
//
// Image coordinates: x right, y down. The skeleton is CV_8UC1, non-zero = line.
#ifndef BSLS_INTERPRETATION_REFERENCE_LINE_H_
#define BSLS_INTERPRETATION_REFERENCE_LINE_H_

#include <opencv2/core.hpp>
#include <string>
#include <utility>
#include <vector>

#include "bsls/pattern/brick_pattern.h"

namespace bsls::interpretation {

struct ReferenceLineParams {
  int scan_area = 15;         // px: side of the square scan areas (thesis: 15x15)
  double cone_slope = 0.6;    // scan area 2: |across| <= cone_slope * along + 1
  int direction_memory = 8;   // px of trace used to estimate the running direction
  int lookahead = 4;          // px followed to break ties between neighbours
  double central_band = 0.6;  // fraction of the rows, centred, where the start is sought
  int start_tolerance = 6;    // px: a start must lie this close to the moving line
  int min_length = 30;        // px: a shorter trace is not line 0

  // True when the numbers are usable; otherwise says why.
  bool IsValid(std::string* error) const;
};

struct ReferenceLine {
  std::vector<cv::Point> pixels;  // ordered from Start0 (top) to Stop0 (bottom)
  cv::Point overlap;              // where the moving line met line 0
  std::vector<std::pair<cv::Point, cv::Point>> fills;  // gaps sealed, as (from, to)
  cv::Point start() const { return pixels.front(); }
  cv::Point stop() const { return pixels.back(); }
};

// Finds and traces line 0 of `side`, sealing its gaps in `skeleton`. Returns
// false and says why (e.g. no lit line, too short) when line 0 cannot be
// found; the skeleton is then unchanged.
bool TraceReferenceLine(cv::Mat& skeleton, pattern::Side side, const ReferenceLineParams& params,
                        ReferenceLine* line, std::string* why);

}  // namespace bsls::interpretation

#endif  // BSLS_INTERPRETATION_REFERENCE_LINE_H_
