// Private to bsls::decoder: placing a junction where its line's sub-pixel
// centre curve meets its segment's (thesis 5.2: the junction's image
// position), one stage for both chains. A chain says which of its line's
// centres and which of its segment's columns to fit (a JunctionPlan), the
// columns are measured once each (ColumnCentres), and RefineJunction meets
// the two fits: straight, as a parabola where the line curves, branch by
// branch where it folds.
#ifndef BSLS_DECODER_SRC_JUNCTION_PLACEMENT_H_
#define BSLS_DECODER_SRC_JUNCTION_PLACEMENT_H_

#include <algorithm>
#include <opencv2/core.hpp>
#include <optional>
#include <utility>
#include <vector>

#include "bsls/decoder/decoder.h"

namespace bsls::decoder::internal {

// What placing a junction needs besides its segment's centres: the line
// near the junction as x = a + b (y - y0) through `vertical` ((y - y0, x)
// pairs), and the segment's skeleton pixels whose column centres are fitted.
struct JunctionPlan {
  bool ok = false;  // false: the line has too few centres near the junction
  double a = 0.0, b = 0.0;
  std::vector<std::pair<double, double>> vertical;
  // The line's measured centres twice as far each side (empty where the fit
  // fell back to the skeleton): a fold's branch curving into it is fitted
  // over these.
  std::vector<std::pair<double, double>> wide;
  std::vector<cv::Point> columns;  // (column, approximate row) of each centre to measure
  // The centre measured in each of `columns` (ColumnCentres::Fill, or the
  // track chain measuring them itself), in their order; nullopt where none.
  std::vector<std::optional<double>> centres;
};

// Sub-pixel centres of segment columns, measured once each (a segment is
// seen from both its junctions over nearly the same columns): `keys` sorted
// (x, then y), `centres` the column centre measured for each.
struct ColumnCentres {
  std::vector<std::pair<int, int>> keys;
  std::vector<std::optional<double>> centres;

  // The columns every plan asks for, each once, with no centre yet.
  static ColumnCentres Wanted(const std::vector<JunctionPlan>& plans);
  // The centre measured at p (a key).
  const std::optional<double>& At(cv::Point p) const {
    const auto it = std::lower_bound(keys.begin(), keys.end(), std::make_pair(p.x, p.y));
    return centres[static_cast<size_t>(it - keys.begin())];
  }
  // Gives `plan` the centres measured in its columns.
  void Fill(JunctionPlan* plan) const;
};

// The segment of `plan` as y = *c + *e (x - plan.a), fitted through its
// columns' measured centres (plan.centres; those far off the others' line
// dropped); false when fewer than two are left.
bool FitMeasuredSegment(const JunctionPlan& plan, const DecodeParams& params, double* c, double* e);

// The junction where the line's centre curve meets the segment's: the line's
// measured centres near the junction fitted as x(y), the segment's centres
// measured column by column along its skeleton (plan.columns, plan.centres)
// and fitted as y(x). An interpolated junction, or one whose segment cannot be
// measured, is placed on the line's fit at its row. nullopt when the line has
// too few centres near it.
std::optional<cv::Point2d> RefineJunction(const JunctionPlan& plan, double y0,
                                          const DecodeParams& params, int n);

}  // namespace bsls::decoder::internal

#endif  // BSLS_DECODER_SRC_JUNCTION_PLACEMENT_H_
