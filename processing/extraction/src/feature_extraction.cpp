#include "bsls/extraction/feature_extraction.h"

#include <future>

#include "input_checks.h"
#include "neighbourhood.h"
#include "skeleton_in_place.h"

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
  if (params.method == ExtractionMethod::kModern) {
    // The skeleton stages one after the other on one padded buffer.
    result.mask = DetectStripes(grey, params.stripe);
    // The re-centring reads the grey image smoothed, which the skeleton does
    // not change: where a second core is free, it is smoothed there while
    // this one thins (the same image either way).
    std::future<cv::Mat> smoothing;
    if (params.recentre && cv::getNumThreads() > 1)
      smoothing = std::async(std::launch::async, [&grey, &params] {
        return internal::RecentreSmoothing(grey, params.recentre_params, false);
      });
    internal::PaddedBinary skeleton(result.mask);
    internal::ZhangSuenThinInPlace(&skeleton, params.zhang_suen);
    internal::MakeOnePixelWideInPlace(&skeleton, params.t_junctions);
    if (params.recentre) {
      const cv::Mat smoothed = smoothing.valid()
                                   ? smoothing.get()
                                   : internal::RecentreSmoothing(grey, params.recentre_params, true);
      internal::RecentreOnRidgeInPlace(&skeleton, smoothed, params.recentre_params);
    }
    internal::PruneSpursInPlace(&skeleton, params.spurs);
    internal::RemoveSmallComponentsInPlace(&skeleton, params.min_component_pixels);
    internal::MakeOnePixelWideInPlace(&skeleton, params.t_junctions);
    result.skeleton = skeleton.ToMat();
    return result;
  }
  // Thesis Figure 4.2: enhancement, edge detection, line thinning, pruning.
  result.smoothed = Enhance(grey, params.enhance);
  result.mask = CannyEdges(result.smoothed, params.canny);
  cv::Mat skeleton = LineFollowingThin(result.mask, params.line_following);
  skeleton = ApplyPruningWindows(skeleton, params.pruning_windows);
  result.skeleton = MakeOnePixelWide(skeleton, params.t_junctions);
  return result;
}

}  // namespace bsls::extraction
