// Feature interpretation (thesis chapter 5, Figure 5.2): reference line
// tracing, boundary and loop tracing with repair of discontinuities, and
// labelling, chained over a one-pixel skeleton.
//
// Image coordinates: x right, y down. The skeleton is CV_8UC1, non-zero = line.
#ifndef BSLS_INTERPRETATION_INTERPRETER_H_
#define BSLS_INTERPRETATION_INTERPRETER_H_

#include <map>
#include <string>
#include <vector>

#include "bsls/common/cancellation.h"
#include "bsls/interpretation/corner_extension.h"
#include "bsls/interpretation/labelling.h"
#include "bsls/interpretation/loop_trace.h"
#include "bsls/interpretation/reference_line.h"
#include "bsls/interpretation/repair.h"
#include "bsls/interpretation/skeleton_graph.h"

namespace bsls::interpretation {

struct InterpretationParams {
  GraphParams graph;
  JunctionParams junction;
  CornerParams corners;
  ReferenceLineParams reference;
  RepairParams repair;
  LabellingParams labelling;
  int max_repair_rounds = 8;     // thesis 5.1.4.7: retrace after each correction
  int min_component_pixels = 6;  // smaller skeleton pieces are noise (thesis 4.4)
  bool enable_repair = true;     // off: label what is there, seal nothing
  // px of empty frame put around the skeleton while interpreting, so that a
  // corner cut by the image's edge can still be extended (at least the stub).
  int frame_margin = 4;

  // True when every part is usable; otherwise says which and why.
  bool IsValid(std::string* error) const;
};

struct InterpretationResult {
  bool ok = false;
  std::string error;  // why the frame could not be labelled (ok == false)
  cv::Mat skeleton;   // the repaired skeleton
  ReferenceLine reference;
  std::vector<Repair> repairs;
  std::vector<cv::Point> corners;         // degree-2 corners extended to junctions (5.2.3.3)
  std::map<LoopClass, int> loop_classes;  // classes found before any repair
  std::vector<LoopRecord> boundary;       // boundary networks after repair
  Labelling labelling;
};

// Interprets a skeleton of the brick slide of `side`. A frame whose reference
// line cannot be found comes back with ok == false and the reason; nothing is
// guessed. `stripe_mask` (optional, CV_8UC1 of the same size) is the stripe
// mask the skeleton was thinned from; it lets corner extension (5.2.3.3) tell
// a stroke lost in thinning from a line that really turns. Throws
// std::invalid_argument for an empty or non-CV_8UC1 skeleton or invalid params.
// `cancel` is asked between the stages and every round of repair (Cancelled
// when asked to stop).
InterpretationResult Interpret(const cv::Mat& skeleton, pattern::Side side,
                               const pattern::PatternSpec& spec,
                               const InterpretationParams& params = {},
                               const cv::Mat& stripe_mask = cv::Mat(),
                               const Cancellation& cancel = {});

}  // namespace bsls::interpretation

#endif  // BSLS_INTERPRETATION_INTERPRETER_H_
