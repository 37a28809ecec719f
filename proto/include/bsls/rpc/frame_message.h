// 8-bit grey frames in the contracts' Frame message (bsls/v1/capture.proto):
// row major, top row first, `stride` bytes per row. Both services and their
// clients convert through here, so a frame is checked the same way wherever
// it arrives.
//
// Thread-safety: pure functions.
#ifndef BSLS_RPC_FRAME_MESSAGE_H_
#define BSLS_RPC_FRAME_MESSAGE_H_

#include <opencv2/core.hpp>
#include <stdexcept>
#include <string>

#include "bsls/v1/capture.pb.h"

namespace bsls::rpc {

// The largest frame side the services accept, pixels (a frame of this size
// in both dimensions is 16 MiB).
inline constexpr int kMaxFrameSide = 4096;

// A frame message that does not describe a usable frame; what() names it
// and the field.
class FrameMessageError : public std::invalid_argument {
 public:
  using std::invalid_argument::invalid_argument;
};

// The frame's pixels as a CV_8UC1 image without a copy (valid while `frame`
// lives). Throws FrameMessageError naming `name` when a side is 0 or above
// kMaxFrameSide, the stride is below the width, or the pixels are fewer or
// more than stride * height bytes.
cv::Mat FrameView(const v1::Frame& frame, const std::string& name);

// Fills `out`'s size, stride (= width) and packed pixels from a CV_8UC1 image.
void ToFrameMessage(const cv::Mat& grey, v1::Frame* out);

}  // namespace bsls::rpc

#endif  // BSLS_RPC_FRAME_MESSAGE_H_
