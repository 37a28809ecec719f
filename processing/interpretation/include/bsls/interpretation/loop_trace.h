// Loop tracing of thesis 5.1.4 and boundary tracing of thesis 5.2.3, on the
// faces of the skeleton graph.
//
// A loop (brick) is a face of the skeleton walked with its inside on the left
// (thesis: inverse directional code, 5.1.4.1). Its record holds the loop
// network (end points E_L and junctions T_L, eq. 5.14), the difference code
// sequence (DCS, eq. 5.15) and the junction sequence (JS, eq. 5.16-5.17), and
// a classification into the cases of Table 5.5 and 5.1.4.8. The outside of a
// connected pattern is one face too: its record is the boundary network N_B of
// eq. 5.2.
#ifndef BSLS_INTERPRETATION_LOOP_TRACE_H_
#define BSLS_INTERPRETATION_LOOP_TRACE_H_

#include <string_view>
#include <vector>

#include "bsls/interpretation/chain_code.h"
#include "bsls/interpretation/junction_network.h"

namespace bsls::interpretation {

// Table 5.5 and section 5.1.4.8.
enum class LoopClass {
  kComplete,             // six junctions (five on line 0), alternating kinds, no end point
  kBoundary,             // the outside of a connected pattern (boundary network)
  kOneDiscontinuity,     // n_e = 2 facing ends (5.1.4.4 a)
  kDoubleDiscontinuity,  // n_e = 4, two facing pairs (5.1.4.4 b)
  kMissingJunction,      // n_e = 3: a line gap and a segment end (5.1.4.5)
  kTwoMissingJunctions,  // n_e = 4, two line gaps without segment ends (5.1.4.6)
  kLargeArea,            // n_e > 4 (5.1.4.7)
  kOverlap,              // crossing points or a broken junction order (5.1.4.8)
  kIncomplete,           // closed but not a brick (e.g. a missing median junction)
};

// Name of a class, e.g. "missing_junction".
std::string_view ToString(LoopClass c);

// One event of a loop walk: a junction visit (an entry of JS) or an end point.
struct LoopEvent {
  bool is_end = false;
  int node = -1;
  JunctionAttribute attribute = JunctionAttribute::kCross3;  // junction visits
  EndDirection end = EndDirection::kTop;                     // end points
  cv::Point2d position;
  int walk_index = 0;  // index of the half-edge arriving at the event
};

struct LoopRecord {
  std::vector<int> walk;          // half-edges, in walking order
  std::vector<LoopEvent> events;  // JS and end points, in walking order
  std::vector<int> dcs;           // inverse difference codes along the walk (eq. 5.10)
  int n_e = 0;                    // end points
  int n_t = 0;                    // junction visits, repeats included
  int repeated = 0;               // junction visits beyond the first of each node
  int crossings = 0;              // visits of crossing points (a_t = 3 or 4)
  double area2 = 0.0;             // twice the signed area (negative: outside face)
  LoopClass cls = LoopClass::kIncomplete;

  // Ends of the loop network E_L.
  std::vector<LoopEvent> Ends() const;
};

// Thesis 5.1.4.1-5.1.4.2: the record of one face walk.
LoopRecord TraceLoop(const JunctionNetwork& network, const std::vector<int>& face);

// Thesis 5.1.4.3 / Table 5.5: classifies a record (sets and returns cls).
LoopClass ClassifyLoop(LoopRecord& record);

// Every face of the network, traced and classified.
std::vector<LoopRecord> TraceLoops(const JunctionNetwork& network);

}  // namespace bsls::interpretation

#endif  // BSLS_INTERPRETATION_LOOP_TRACE_H_
