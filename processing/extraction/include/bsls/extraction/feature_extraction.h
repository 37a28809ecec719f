// Feature extraction in one call (thesis chapter 4, Figure 4.2): grey frame
// in, one-pixel-wide skeleton of the stripes out, for the tracing of
// chapter 5.
//
//  kModern (default): mask = DetectStripes(grey, stripe); skeleton =
//    Zhang-Suen (4.3.2) -> MakeOnePixelWide -> RecentreOnRidge (on the grey
//    input) -> PruneSpurs -> RemoveSmallComponents -> MakeOnePixelWide.
//    smoothed is left empty: nothing in this chain (nor the decoder's
//    sub-pixel centres, which read the grey frame) uses it; call Enhance
//    for it.
//  kThesis: smoothed = Enhance(grey, enhance) (Gaussian or Davies, 4.1);
//    mask = CannyEdges(smoothed, canny) with the two-peak thresholds (4.2.3);
//    skeleton = LineFollowingThin (4.3.1) -> ApplyPruningWindows (4.4) ->
//    MakeOnePixelWide. Canny marks both flanks of a stripe; line following
//    merges flanks up to line_following.margin px apart (thin stripes), wider
//    stripes give two skeleton lines, as in the thesis (4.5).
//
// Images: input CV_8UC1 grey (x = column, y = row, origin at the centre of
// the top-left pixel). Outputs are new images of the input's size:
// smoothed CV_8UC1 (kThesis; empty for kModern), mask and skeleton CV_8UC1
// 0/255. The skeleton is
// 8-connected and strictly one pixel wide (MakeOnePixelWide): plain line
// pixels have exactly 2 set 8-neighbours, line ends 1. With the default
// t_junctions = kCentreKept a T-junction is a cluster of 4 pixels with 3 or 4
// neighbours (the T-centre on the line, its two line neighbours and the
// branch's first pixel): merge 8-adjacent junction pixels into one junction.
// kNotched gives a single degree-3 pixel per T, one pixel off the line.
//
// Errors: empty or non-CV_8UC1 input (e.g. CV_8UC3, CV_16U) and invalid
// parameters throw std::invalid_argument("<Function>: <reason>").
//
// Thread-safety: pure function of its arguments. The Hessian stripe mask and
// the Gaussian smoothing of RecentreOnRidge run band by band on OpenCV's
// thread pool (cv::parallel_for_; cv::setNumThreads(1) makes them serial).
#ifndef BSLS_EXTRACTION_FEATURE_EXTRACTION_H_
#define BSLS_EXTRACTION_FEATURE_EXTRACTION_H_

#include <opencv2/core.hpp>
#include <string>

#include "bsls/common/cancellation.h"
#include "bsls/extraction/edge_detect.h"
#include "bsls/extraction/enhance.h"
#include "bsls/extraction/pruning.h"
#include "bsls/extraction/stripe_detect.h"
#include "bsls/extraction/thinning.h"

namespace bsls::extraction {

enum class ExtractionMethod {
  kModern,  // stripe_detect + Zhang-Suen + spur / component pruning
  kThesis,  // Gaussian/Davies + Canny(two-peak) + line following + pruning windows
};

struct ExtractionParams {
  ExtractionMethod method = ExtractionMethod::kModern;
  EnhanceParams enhance;  // kThesis: the `smoothed` output, the input of Canny
  TJunctionShape t_junctions = TJunctionShape::kCentreKept;  // both: skeleton junction shape
  // kModern.
  StripeDetectParams stripe;
  ZhangSuenParams zhang_suen;
  bool recentre = true;  // move the skeleton onto the grey ridge (RecentreOnRidge)
  RecentreParams recentre_params;
  SpurPruneParams spurs;
  int min_component_pixels = 10;  // smaller skeleton components are dropped, >= 1
  // kThesis.
  CannyParams canny{.sigma = 0.0};  // no extra smoothing: `enhance` smooths already
  LineFollowingParams line_following;
  PruningWindowParams pruning_windows;

  // True when the parameters of the chosen method are usable; otherwise says why.
  bool IsValid(std::string* error) const;
};

struct ExtractionResult {
  cv::Mat smoothed;  // CV_8UC1, the enhanced grey frame (kThesis; empty for kModern)
  cv::Mat mask;      // CV_8UC1 0/255: stripe pixels (kModern) or Canny edges (kThesis)
  cv::Mat skeleton;  // CV_8UC1 0/255, one pixel wide, 8-connected
};

// Runs the chosen chain on a grey frame, asking `cancel` between its stages
// and before every thinning iteration (Cancelled when asked to stop).
ExtractionResult ExtractFeatures(const cv::Mat& grey, const ExtractionParams& params = {},
                                 const Cancellation& cancel = {});

}  // namespace bsls::extraction

#endif  // BSLS_EXTRACTION_FEATURE_EXTRACTION_H_
