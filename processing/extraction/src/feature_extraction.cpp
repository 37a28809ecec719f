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

ExtractionResult ExtractFeatures(const cv::Mat& grey, const ExtractionParams& params,
                                 const Cancellation& cancel) {
  RequireGrey8(grey, "ExtractFeatures");
  RequireValid(params, "ExtractFeatures");
  ExtractionResult result;
  if (params.method == ExtractionMethod::kModern) {
    // The skeleton stages one after the other on one padded buffer.
    result.mask = DetectStripes(grey, params.stripe, cancel);
    cancel.ThrowIfRequested("the stripe mask");
    // The re-centring reads the grey image smoothed, which the skeleton does
    // not change: where a second core is free, it is smoothed there while
    // this one thins (the same image either way).
    std::future<cv::Mat> smoothing;
    if (params.recentre && cv::getNumThreads() > 1)
      smoothing = std::async(std::launch::async, [&grey, &params, &cancel] {
        return internal::RecentreSmoothing(grey, params.recentre_params, false, cancel);
      });
    internal::PaddedBinary skeleton(result.mask);
    internal::ZhangSuenThinInPlace(&skeleton, params.zhang_suen, cancel);
    internal::MakeOnePixelWideInPlace(&skeleton, params.t_junctions, cancel);
    if (params.recentre) {
      const cv::Mat smoothed = smoothing.valid() ? smoothing.get()
                                                 : internal::RecentreSmoothing(
                                                       grey, params.recentre_params, true, cancel);
      internal::RecentreOnRidgeInPlace(&skeleton, smoothed, params.recentre_params, cancel);
      cancel.ThrowIfRequested("the re-centring on ridges");
    }
    internal::PruneSpursInPlace(&skeleton, params.spurs);
    cancel.ThrowIfRequested("the spur pruning");
    internal::RemoveSmallComponentsInPlace(&skeleton, params.min_component_pixels, cancel);
    internal::MakeOnePixelWideInPlace(&skeleton, params.t_junctions, cancel);
    result.skeleton = skeleton.ToMat();
    return result;
  }
  // Thesis Figure 4.2: enhancement, edge detection, line thinning, pruning.
  result.smoothed = Enhance(grey, params.enhance);
  cancel.ThrowIfRequested("the enhancement");
  result.mask = CannyEdges(result.smoothed, params.canny);
  cancel.ThrowIfRequested("the edge detection");
  cv::Mat skeleton = LineFollowingThin(result.mask, params.line_following);
  cancel.ThrowIfRequested("the line-following thinning");
  skeleton = ApplyPruningWindows(skeleton, params.pruning_windows);
  cancel.ThrowIfRequested("the pruning windows");
  result.skeleton = MakeOnePixelWide(skeleton, params.t_junctions);
  return result;
}

}  // namespace bsls::extraction
