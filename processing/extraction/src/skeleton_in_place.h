// The thinning and pruning stages working in place on one PaddedBinary, so
// that the modern chain (feature_extraction.cpp) runs them back to back
// without converting to and from cv::Mat in between (not installed). Each
// does exactly what the public function of the same name does; the public
// functions are these wrapped in conversions.
#ifndef BSLS_EXTRACTION_SRC_SKELETON_IN_PLACE_H_
#define BSLS_EXTRACTION_SRC_SKELETON_IN_PLACE_H_

#include <opencv2/core.hpp>

#include "bsls/common/cancellation.h"
#include "bsls/extraction/pruning.h"
#include "bsls/extraction/thinning.h"
#include "neighbourhood.h"

namespace bsls::extraction::internal {

// ZhangSuenThin (thinning.h) on *img; asks `cancel` before every iteration.
void ZhangSuenThinInPlace(PaddedBinary* img, const ZhangSuenParams& params,
                          const Cancellation& cancel = {});

// MakeOnePixelWide (thinning.h) on *img; asks `cancel` before every sweep.
void MakeOnePixelWideInPlace(PaddedBinary* img, TJunctionShape t_junctions,
                             const Cancellation& cancel = {});

// Skeleton pixels RecentreOnRidgeInPlace looks at between two questions to
// its Cancellation.
constexpr int kRecentrePixelsPerQuestion = 4096;

// The grey image (CV_8UC1) smoothed as RecentreOnRidge reads it, CV_32FC1 in a
// buffer laid out like a PaddedBinary of its size, its frame -infinity: band by
// band on OpenCV's thread pool, or on the calling thread (the same values);
// asks `cancel` before every band (throws Cancelled after the bands).
cv::Mat RecentreSmoothing(const cv::Mat& grey, const RecentreParams& params, bool in_parallel,
                          const Cancellation& cancel = {});

// RecentreOnRidge (thinning.h) on *img, reading `smoothed`: RecentreSmoothing
// of the grey image, of the image's size; asks `cancel` every
// kRecentrePixelsPerQuestion pixels it looks at.
void RecentreOnRidgeInPlace(PaddedBinary* img, const cv::Mat& smoothed,
                            const RecentreParams& params, const Cancellation& cancel = {});

// PruneSpurs (pruning.h) on *img.
void PruneSpursInPlace(PaddedBinary* img, const SpurPruneParams& params);

// RemoveSmallComponents (pruning.h) on *img; min_pixels >= 1. Asks
// `cancel` every few thousand components.
void RemoveSmallComponentsInPlace(PaddedBinary* img, int min_pixels,
                                  const Cancellation& cancel = {});

}  // namespace bsls::extraction::internal

#endif  // BSLS_EXTRACTION_SRC_SKELETON_IN_PLACE_H_
