#include "bsls/extraction/feature_extraction.h"

#include "input_checks.h"

namespace bsls::extraction {
namespace {

using internal::RequireGrey8;
using internal::RequireValid;

}  // namespace

bool ExtractionParams::IsValid(std::string* error) const {
  if (!enhance.IsValid(error)) return false;
  if (method == ExtractionMethod::kModern) {
    if (!stripe.IsValid(error) || !zhang_suen.IsValid(error) || !spurs.IsValid(error) ||
        !recentre_params.IsValid(error))
      return false;
    if (min_component_pixels < 1) {
      if (error) *error = "min_component_pixels must be >= 1";
      return false;
    }
    return true;
  }
  return canny.IsValid(error) && line_following.IsValid(error) && pruning_windows.IsValid(error);
}

ExtractionResult ExtractFeatures(const cv::Mat& grey, const ExtractionParams& params) {
  RequireGrey8(grey, "ExtractFeatures");
  RequireValid(params, "ExtractFeatures");
  ExtractionResult result;
  result.smoothed = Enhance(grey, params.enhance);
  if (params.method == ExtractionMethod::kModern) {
    result.mask = DetectStripes(grey, params.stripe);
    cv::Mat skeleton =
        MakeOnePixelWide(ZhangSuenThin(result.mask, params.zhang_suen), params.t_junctions);
    if (params.recentre) skeleton = RecentreOnRidge(skeleton, grey, params.recentre_params);
    skeleton = PruneSpurs(skeleton, params.spurs);
    skeleton = RemoveSmallComponents(skeleton, params.min_component_pixels);
    result.skeleton = MakeOnePixelWide(skeleton, params.t_junctions);
    return result;
  }
  // Thesis Figure 4.2: enhancement, edge detection, line thinning, pruning.
  result.mask = CannyEdges(result.smoothed, params.canny);
  cv::Mat skeleton = LineFollowingThin(result.mask, params.line_following);
  skeleton = ApplyPruningWindows(skeleton, params.pruning_windows);
  result.skeleton = MakeOnePixelWide(skeleton, params.t_junctions);
  return result;
}

}  // namespace bsls::extraction
