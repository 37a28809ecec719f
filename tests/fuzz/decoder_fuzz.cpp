// libFuzzer target: arbitrary bytes through the frame loader and the decoder.
// Byte 0 chooses the path: even = the bytes are an image file (PNG or PNM;
// others are refused), odd = raw 8-bit pixels of a small frame whose size
// and side come from bytes 1-3. Bit 2 of byte 0 chooses the decoding chain (skeleton
// or tracks). Neither path may crash, hang or leak; errors are fine.
#include <cstddef>
#include <cstdint>
#include <vector>

#include "bsls/common/errors.h"
#include "bsls/decoder/decoder.h"
#include "bsls/io/frame_file.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size < 4) return 0;
  const bsls::pattern::Side side =
      (data[0] & 2) ? bsls::pattern::Side::kRight : bsls::pattern::Side::kLeft;
  cv::Mat frame;
  if ((data[0] & 1) == 0) {
    const std::vector<unsigned char> bytes(data + 1, data + size);
    bsls::io::FrameLimits limits;
    limits.max_side = 1024;  // keep each run short
    try {
      frame = bsls::io::DecodeGreyFrame(bytes, "fuzz input", nullptr, limits);
    } catch (const bsls::InputError&) {
      return 0;
    }
  } else {
    const int width = 16 + data[1] % 241;
    const int height = 16 + data[2] % 241;
    frame = cv::Mat(height, width, CV_8UC1);
    const std::size_t payload = size - 4;
    for (int i = 0; i < width * height; ++i)
      frame.data[i] =
          payload ? data[4 + (i * 7919u) % payload] ^ static_cast<std::uint8_t>(i * data[3]) : 0;
  }
  bsls::decoder::DecodeParams params;
  params.chain =
      (data[0] & 4) ? bsls::decoder::DecodeChain::kTracks : bsls::decoder::DecodeChain::kSkeleton;
  const bsls::decoder::DecodeResult result = bsls::decoder::Decode(frame, side, params);
  (void)result;
  return 0;
}
