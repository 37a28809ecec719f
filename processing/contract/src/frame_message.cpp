#include "bsls/contract/frame_message.h"

#include <cassert>

namespace bsls::contract {

cv::Mat FrameView(const v1::Frame& frame, const std::string& name) {
  const auto side_ok = [](std::uint32_t v) { return v >= 1 && v <= kMaxFrameSide; };
  if (!side_ok(frame.width()) || !side_ok(frame.height()))
    throw MessageError(name + ": " + std::to_string(frame.width()) + " x " +
                       std::to_string(frame.height()) + " pixels; each side must be 1.." +
                       std::to_string(kMaxFrameSide));
  if (frame.stride() < frame.width() || frame.stride() > 2u * kMaxFrameSide)
    throw MessageError(name + ": stride " + std::to_string(frame.stride()) +
                       " does not fit width " + std::to_string(frame.width()));
  const std::size_t expected = static_cast<std::size_t>(frame.stride()) * frame.height();
  if (frame.pixels().size() != expected)
    throw MessageError(name + ": " + std::to_string(frame.pixels().size()) +
                       " bytes of pixels, but " + std::to_string(frame.width()) + " x " +
                       std::to_string(frame.height()) + " 8-bit grey with stride " +
                       std::to_string(frame.stride()) + " needs " + std::to_string(expected));
  return cv::Mat(static_cast<int>(frame.height()), static_cast<int>(frame.width()), CV_8UC1,
                 const_cast<char*>(frame.pixels().data()), frame.stride());
}

void ToFrameMessage(const cv::Mat& grey, v1::Frame* out) {
  assert(grey.type() == CV_8UC1);
  out->set_width(static_cast<std::uint32_t>(grey.cols));
  out->set_height(static_cast<std::uint32_t>(grey.rows));
  out->set_stride(static_cast<std::uint32_t>(grey.cols));
  std::string* pixels = out->mutable_pixels();
  pixels->resize(grey.total());
  for (int y = 0; y < grey.rows; ++y)
    std::copy(grey.ptr<char>(y), grey.ptr<char>(y) + grey.cols,
              pixels->data() + static_cast<std::size_t>(y) * grey.cols);
}

}  // namespace bsls::contract
