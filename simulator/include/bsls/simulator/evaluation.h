// Scores a decode against the simulator's ground truth: which lit and visible
// junctions were found, with which labels, and how far the decoded line
// centres lie from the true ones. Used by the tests, the benchmarks and
// `bsls evaluate`.
//
// Positions are image pixels. q of the decoder is relative (one even offset
// per image, contracts section 2): the offset is taken from the majority of
// matched junctions and every junction off that offset counts as wrong.
#ifndef BSLS_SIMULATOR_EVALUATION_H_
#define BSLS_SIMULATOR_EVALUATION_H_

#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "bsls/simulator/ground_truth.h"

namespace bsls::simulator {

struct PointLabel {
  int p = 0;
  int v = 0;
  cv::Point2d position;
};

struct LabelScore {
  int truth = 0;                   // truth junctions considered
  int found = 0;                   // truth junctions with a decoded junction within reach
  int wrong_p = 0;                 // found, but p differs
  int wrong_v = 0;                 // found, p right, v off the image's common offset
  int unmatched = 0;               // decoded junctions with no truth within reach
  int v_offset = 0;                // decoded v - true v of the majority
  double position_rms = 0.0;       // px, over found junctions with the right label
  std::vector<PointLabel> missed;  // truth junctions not found
  std::vector<PointLabel> wrong;   // truth junctions found with a wrong label

  // Share of truth junctions found, whatever their labels.
  double Recall() const { return truth ? static_cast<double>(found) / truth : 0.0; }
  int Wrong() const { return wrong_p + wrong_v; }
  // Found with the right label.
  int Right() const { return found - Wrong(); }
  // Share of truth junctions found with the right label.
  double RightRecall() const { return truth ? static_cast<double>(Right()) / truth : 0.0; }
  // One line for test failure messages.
  std::string Summary() const;
};

// Sampled centre line of one vertical line p, image pixels.
struct LinePoints {
  int p = 0;
  std::vector<cv::Point2d> points;
};

struct LineScore {
  int points = 0;    // decoded points with a true crossing on their row
  double rms = 0.0;  // px, horizontal distance to the nearest true crossing of the row
};

// Scores decoded line points against the true crossings of the same row.
LineScore ScoreLines(const std::vector<LinePoints>& truth, const std::vector<LinePoints>& decoded);

// The lit and visible junctions of a ground truth, labelled with their slide row v.
std::vector<PointLabel> VisibleJunctions(const GroundTruth& truth);

// The true centre lines of a ground truth.
std::vector<LinePoints> TruthLines(const GroundTruth& truth);

// Matches each truth junction to the nearest decoded one within `reach` px
// (each decoded junction used once) and scores the labels.
LabelScore ScoreLabels(const std::vector<PointLabel>& truth, const std::vector<PointLabel>& decoded,
                       double reach);

}  // namespace bsls::simulator

#endif  // BSLS_SIMULATOR_EVALUATION_H_
