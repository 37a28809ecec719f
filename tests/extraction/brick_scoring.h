// Scores of stripe masks and skeletons against a rendered brick scene.
#ifndef BSLS_TESTS_EXTRACTION_BRICK_SCORING_H_
#define BSLS_TESTS_EXTRACTION_BRICK_SCORING_H_

#include <opencv2/core.hpp>
#include <ostream>
#include <vector>

#include "synthetic_images.h"

namespace bsls::extraction::testing {

struct MaskScore {
  double recall = 0.0;          // line-centre pixels inside the mask, outside the dark patch
  double recall_dark = 0.0;     // ... inside the dark patch
  double false_positive = 0.0;  // mask pixels more than 2 px from every stroke
  double width_error = 0.0;     // mean (mask run width - true line width), px, bright lines
  int bridges = 0;              // rows where the mask joins two neighbouring lines off segments
};

struct SkeletonScore {
  double junctions_within_1_5 = 0.0;  // true junctions with a junction pixel within 1.5 px
  double junctions_within_1_5_dark = 0.0;
  double worst_junction = 0.0;  // px, largest distance over all true junctions
  double line_coverage = 0.0;   // line-centre rows with a skeleton pixel within 1.5 px
  double line_coverage_dark = 0.0;
  int merges = 0;           // skeleton pixels between two lines, off the segment rows
  int false_junctions = 0;  // junction clusters > 3 px from every true junction, > 20 px inside
  bool one_pixel_wide = false;
};

std::ostream& operator<<(std::ostream& os, const MaskScore& s);
std::ostream& operator<<(std::ostream& os, const SkeletonScore& s);

// Pixels of a skeleton with 3 or more set 8-neighbours.
std::vector<cv::Point> JunctionPixels(const cv::Mat& skeleton);

// Interior of the face (away from its rim) where scores are taken.
cv::Mat ScoredRegion(const BrickTruth& truth);

MaskScore ScoreMask(const cv::Mat& mask, const BrickTruth& truth);
SkeletonScore ScoreSkeleton(const cv::Mat& skeleton, const BrickTruth& truth);

}  // namespace bsls::extraction::testing

#endif  // BSLS_TESTS_EXTRACTION_BRICK_SCORING_H_
