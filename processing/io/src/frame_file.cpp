#include "bsls/io/frame_file.h"

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "bsls/common/atomic_file.h"

namespace bsls::io {
namespace {

std::string Errno() { return std::strerror(errno); }

}  // namespace

std::string FrameConversion::Describe() const {
  if (!converted()) return {};
  return "converted " + std::to_string(source_channels) + "-channel " +
         std::to_string(source_depth_bits) + "-bit to 8-bit grey";
}

cv::Mat LoadGreyFrame(const std::string& path, FrameConversion* conversion,
                      const FrameLimits& limits) {
  std::error_code ec;
  const auto status = std::filesystem::status(path, ec);
  if (ec || !std::filesystem::exists(status)) throw InputError(path + ": no such file");
  if (std::filesystem::is_directory(status)) throw InputError(path + ": is a folder, not an image");
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(path + ": cannot be opened: " + Errno());
  std::vector<uchar> bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  if (in.bad()) throw InputError(path + ": read failed: " + Errno());
  return DecodeGreyFrame(bytes, path, conversion, limits);
}

cv::Mat DecodeGreyFrame(const std::vector<unsigned char>& bytes, const std::string& path,
                        FrameConversion* conversion, const FrameLimits& limits) {
  if (bytes.empty()) throw InputError(path + ": file is empty");
  auto check_size = [&](std::uint64_t width, std::uint64_t height) {
    if (width < static_cast<std::uint64_t>(limits.min_side) ||
        height < static_cast<std::uint64_t>(limits.min_side) ||
        width > static_cast<std::uint64_t>(limits.max_side) ||
        height > static_cast<std::uint64_t>(limits.max_side))
      throw InputError(path + ": size " + std::to_string(width) + "x" + std::to_string(height) +
                       " is outside " + std::to_string(limits.min_side) + ".." +
                       std::to_string(limits.max_side) + " pixels a side");
    if (width * height > static_cast<std::uint64_t>(limits.max_pixels))
      throw InputError(path + ": size " + std::to_string(width) + "x" + std::to_string(height) +
                       " = " + std::to_string(width * height) + " pixels is above the budget of " +
                       std::to_string(limits.max_pixels));
  };
  // Only PNG and PNM are read, and their size is read from their header and
  // checked before anything is decoded or allocated for it. OpenCV decodes
  // many more formats, and some of those decoders allocate from a header
  // field before any check (its DICOM reader, GDCM, asked for 3.5 GB for a
  // 200-byte input the PNG fuzz target found; its GDAL reader writes the
  // bytes to a temporary file first): no frame of this project comes in them.
  static constexpr unsigned char kPngStart[] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'};
  static constexpr unsigned char kPngHeader[] = {0, 0, 0, 13, 'I', 'H', 'D', 'R'};
  if (bytes.size() >= 8 && std::equal(std::begin(kPngStart), std::end(kPngStart), bytes.begin())) {
    // PNG: the first chunk is IHDR, width and height big-endian.
    if (bytes.size() < 24 ||
        !std::equal(std::begin(kPngHeader), std::end(kPngHeader), bytes.begin() + 8))
      throw InputError(path + ": a PNG without its header (IHDR)");
    auto be32 = [&](size_t at) {
      return std::uint64_t{bytes[at]} << 24 | std::uint64_t{bytes[at + 1]} << 16 |
             std::uint64_t{bytes[at + 2]} << 8 | std::uint64_t{bytes[at + 3]};
    };
    check_size(be32(16), be32(20));
  } else if (bytes.size() >= 2 && bytes[0] == 'P' &&
             (bytes[1] == '2' || bytes[1] == '3' || bytes[1] == '5' || bytes[1] == '6')) {
    // PNM (the capture store's frames are PGM): "P5", then width and height
    // in decimal, separated by white space and # comments.
    std::size_t at = 2;
    auto number = [&]() -> std::uint64_t {
      for (;;) {
        while (at < bytes.size() && std::isspace(bytes[at])) ++at;
        if (at < bytes.size() && bytes[at] == '#') {
          while (at < bytes.size() && bytes[at] != '\n') ++at;
          continue;
        }
        break;
      }
      std::uint64_t value = 0;
      int digits = 0;
      for (; at < bytes.size() && std::isdigit(bytes[at]) && digits < 12; ++at, ++digits)
        value = value * 10 + (bytes[at] - '0');
      if (digits == 0 || digits == 12)
        throw InputError(path + ": a PNM without a readable size in its header");
      return value;
    };
    const std::uint64_t width = number();
    check_size(width, number());
  } else {
    throw InputError(path + ": not a PNG or PNM image (frames are read in these formats only)");
  }
  cv::Mat raw;
  try {
    raw = cv::imdecode(bytes, cv::IMREAD_UNCHANGED);
  } catch (const cv::Exception& e) {
    throw InputError(path + ": cannot be decoded as an image: " + e.err);
  }
  if (raw.empty()) throw InputError(path + ": not a readable image (truncated or unknown format)");
  if (raw.dims != 2) throw InputError(path + ": not a two-dimensional image");
  check_size(static_cast<std::uint64_t>(raw.cols), static_cast<std::uint64_t>(raw.rows));
  FrameConversion conv;
  conv.source_channels = raw.channels();
  switch (raw.depth()) {
    case CV_8U:
      conv.source_depth_bits = 8;
      break;
    case CV_16U:
      conv.source_depth_bits = 16;
      break;
    default:
      throw InputError(path + ": pixel depth is neither 8 nor 16 bits");
  }
  cv::Mat grey;
  switch (raw.channels()) {
    case 1:
      grey = raw;
      break;
    case 3:
      cv::cvtColor(raw, grey, cv::COLOR_BGR2GRAY);
      break;
    case 4:
      cv::cvtColor(raw, grey, cv::COLOR_BGRA2GRAY);
      break;
    case 2: {
      std::vector<cv::Mat> planes;
      cv::split(raw, planes);  // grey + alpha
      grey = planes[0];
      break;
    }
    default:
      throw InputError(path + ": " + std::to_string(raw.channels()) + " channels per pixel");
  }
  if (grey.depth() == CV_16U) grey.convertTo(grey, CV_8U, 1.0 / 257.0);
  if (conversion) *conversion = conv;
  return grey.isContinuous() ? grey : grey.clone();
}

void WritePngAtomically(const std::string& path, const cv::Mat& image) {
  std::vector<uchar> png;
  try {
    if (!cv::imencode(".png", image, png)) throw OutputError(path + ": PNG encoding failed");
  } catch (const cv::Exception& e) {
    throw OutputError(path + ": PNG encoding failed: " + e.err);
  }
  WriteFileAtomically(path,
                      std::string_view(reinterpret_cast<const char*>(png.data()), png.size()));
}

}  // namespace bsls::io
