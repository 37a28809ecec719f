// Hysteresis on precomputed masks, shared by the edge and stripe detectors
// (not installed).
#ifndef BSLS_EXTRACTION_SRC_HYSTERESIS_H_
#define BSLS_EXTRACTION_SRC_HYSTERESIS_H_

#include <opencv2/core.hpp>
#include <string_view>

#include "bsls/common/cancellation.h"

namespace bsls::extraction::internal {

// The 8-connected components of `weak` (CV_8UC1, non-zero = set) that contain
// at least one pixel set in `strong` (same size and type), as 0/255. Asks
// `cancel` every few thousand strong pixels (Cancelled naming `stage`).
cv::Mat KeepComponentsTouching(const cv::Mat& weak, const cv::Mat& strong,
                               const Cancellation& cancel = {},
                               std::string_view stage = "the hysteresis");

}  // namespace bsls::extraction::internal

#endif  // BSLS_EXTRACTION_SRC_HYSTERESIS_H_
