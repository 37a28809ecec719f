// Labelling of thesis 5.1.4.9: every junction gets its pattern label (p, v)
// and every vertical line its p, starting from line 0 and spreading through
// the loops line by line.
//
// Labels spread from the junctions of line 0 along lines (v changes by one
// row per junction, the kinds alternating) and across segments (p changes by
// one, v stays). Links inside complete loops are trusted first; a label must
// agree with the junction's kind (a direct junction on line p lies on a row
// v = p mod 2), and a junction whose neighbours mostly disagree with it is
// dropped rather than guessed. v is relative: line 0's junction nearest the
// image's centre row gets v = 0 (thesis point O); consumers add an even offset
// when the calibration knows the slide's centre row.
//
// Image coordinates: x right, y down.
#ifndef BSLS_INTERPRETATION_LABELLING_H_
#define BSLS_INTERPRETATION_LABELLING_H_

#include <map>
#include <string>
#include <vector>

#include "bsls/interpretation/loop_trace.h"
#include "bsls/interpretation/reference_line.h"
#include "bsls/pattern/brick_pattern.h"

namespace bsls::interpretation {

struct LabellingParams {
  // Thesis 5.1.4.6: junctions missing between labelled ones on a continuous
  // line are placed from their relative junctions; at most this many in a row.
  int max_interpolated_run = 3;
  bool interpolate_missing = true;
  // Fraction of line-0 junctions allowed to have their segment on the inner
  // side before the line is rejected as line 0.
  double max_inner_fraction = 0.2;
  int min_reference_junctions = 2;
  // Radius (px) within which row spacings are pooled to judge a line step.
  double spacing_radius = 60.0;

  // True when the numbers are usable; otherwise says why.
  bool IsValid(std::string* error) const;
};

struct LabelledJunction {
  int node = -1;         // skeleton-graph node, -1 when interpolated
  cv::Point2d position;  // junction centre point, pixels
  int p = 0;
  int v = 0;  // slide row, relative (see above)
  pattern::JunctionKind kind = pattern::JunctionKind::kDirect;
  bool interpolated = false;       // placed from relative junctions, not seen
  std::vector<cv::Point> segment;  // skeleton pixels of its segment, from the junction on
};

struct LabelledLine {
  int p = 0;
  std::vector<cv::Point> pixels;  // skeleton pixels, ordered from top to bottom
};

struct Labelling {
  std::vector<LabelledJunction> junctions;  // ordered by p, then v
  std::vector<LabelledLine> lines;          // ordered by p
  // For each labelled node, the node its label came from (-1 for line 0's
  // junctions) and the cost of its path: how far it trusts untrusted links.
  std::map<int, std::pair<int, double>> provenance;
  int conflicts = 0;  // labels dropped because their neighbours disagreed
  int reference_junctions = 0;
};

// Labels the network. Fails (returns false, says why) when line 0 carries too
// few junctions or carries segments on its inner side, i.e. the traced line is
// not the reference line.
bool LabelNetwork(const JunctionNetwork& network, const std::vector<LoopRecord>& loops,
                  const ReferenceLine& reference, const pattern::PatternSpec& spec,
                  const LabellingParams& params, Labelling* out, std::string* why);

}  // namespace bsls::interpretation

#endif  // BSLS_INTERPRETATION_LABELLING_H_
