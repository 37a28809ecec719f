#include "bsls/store/sha256.h"

#include <cstddef>

#include "bsls/common/sha256.h"

namespace bsls::store {

Result<std::string> PixelSha256(const framestore::GreyFrame& frame) {
  const auto rows = static_cast<std::size_t>(frame.height);
  const auto width = static_cast<std::size_t>(frame.width);
  const auto stride = static_cast<std::size_t>(frame.stride);
  if (frame.width <= 0 || frame.height <= 0 || frame.stride < frame.width ||
      frame.pixels.size() / stride < rows)
    return Status(ErrorCode::kInvalidArgument,
                  "frame of " + std::to_string(frame.width) + " x " + std::to_string(frame.height) +
                      " pixels, stride " + std::to_string(frame.stride) + ", has " +
                      std::to_string(frame.pixels.size()) + " bytes: not a well-formed frame");
  try {
    Sha256 digest;
    if (stride == width) {
      digest.Update(frame.pixels.data(), width * rows);
    } else {
      for (std::size_t row = 0; row < rows; ++row)
        digest.Update(frame.pixels.data() + row * stride, width);
    }
    return digest.HexDigest();
  } catch (const DigestError& e) {
    return Status(ErrorCode::kInternal, e.what());
  }
}

Result<std::string> BytesSha256(std::string_view bytes) {
  try {
    return Sha256Hex(bytes);
  } catch (const DigestError& e) {
    return Status(ErrorCode::kInternal, e.what());
  }
}

}  // namespace bsls::store
