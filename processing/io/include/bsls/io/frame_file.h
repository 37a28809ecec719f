// Frames in image files: reading PNG and PNM as 8-bit grey, and writing PNG
// so that a reader never sees it half-written (contracts section 5).
//
// Errors: InputError and OutputError (bsls/common/errors.h).
#ifndef BSLS_IO_FRAME_FILE_H_
#define BSLS_IO_FRAME_FILE_H_

#include <cstdint>
#include <opencv2/core.hpp>
#include <string>
#include <string_view>
#include <vector>

#include "bsls/common/errors.h"

namespace bsls::io {

struct FrameLimits {
  int min_side = 16;     // px: smaller frames cannot hold the pattern
  int max_side = 16384;  // px: larger ones are refused as absurd
  // width x height: the largest frame the processing API carries (4096 x
  // 4096). A PNG's header is checked against it before anything is decoded
  // or allocated (a 16384 x 16384 16-bit RGBA header claims 2 GiB).
  std::int64_t max_pixels = std::int64_t{4096} * 4096;
};

// What LoadGreyFrame had to do to the file's pixels, for the user to know.
struct FrameConversion {
  int source_channels = 1;
  int source_depth_bits = 8;
  bool converted() const { return source_channels != 1 || source_depth_bits != 8; }
  // e.g. "converted 3-channel 16-bit to 8-bit grey"; empty when nothing was done.
  std::string Describe() const;
};

// Reads an image file, PNG or PNM (P2, P3, P5, P6), as an 8-bit grey frame
// (CV_8UC1); its size is checked against `limits` from its header, before
// anything is decoded. Colour is converted to grey and 16-bit to 8-bit
// (scaled by 1/257); `conversion` says what was done. Throws InputError
// naming the file for a missing, unreadable, empty, truncated or undecodable
// file, another format, or a size outside `limits` (sides or pixels).
cv::Mat LoadGreyFrame(const std::string& path, FrameConversion* conversion = nullptr,
                      const FrameLimits& limits = {});

// The same for an image already in memory; `name` stands for the file in
// error messages.
cv::Mat DecodeGreyFrame(const std::vector<unsigned char>& bytes, const std::string& name,
                        FrameConversion* conversion = nullptr, const FrameLimits& limits = {});

// Encodes an image as PNG and writes it atomically. Throws OutputError.
void WritePngAtomically(const std::string& path, const cv::Mat& image);

}  // namespace bsls::io

#endif  // BSLS_IO_FRAME_FILE_H_
