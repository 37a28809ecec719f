// 8-bit grey frames in the contracts' Frame message (bsls/v1/capture.proto):
// row major, top row first, `stride` bytes per row. The processing service
// and its clients convert through here, so a frame is checked the same way
// wherever it arrives.
//
// Thread-safety: pure functions.
#ifndef BSLS_CONTRACT_FRAME_MESSAGE_H_
#define BSLS_CONTRACT_FRAME_MESSAGE_H_

#include <opencv2/core.hpp>
#include <string>

#include "bsls/contract/message_error.h"
#include "bsls/v1/capture.pb.h"

namespace bsls::contract {

// The largest frame side the processing service accepts, pixels (a frame
// of this size in both dimensions is 16 MiB).
inline constexpr int kMaxFrameSide = 4096;

// The frame's pixels as a CV_8UC1 image without a copy (valid while `frame`
// lives). Throws MessageError naming `name` when a side is 0 or above
// kMaxFrameSide, the stride is below the width, or the pixels are fewer or
// more than stride * height bytes.
cv::Mat FrameView(const v1::Frame& frame, const std::string& name);

// Fills `out`'s size, stride (= width) and packed pixels from a CV_8UC1 image.
void ToFrameMessage(const cv::Mat& grey, v1::Frame* out);

}  // namespace bsls::contract

#endif  // BSLS_CONTRACT_FRAME_MESSAGE_H_
