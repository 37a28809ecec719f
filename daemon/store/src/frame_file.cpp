#include "bsls/store/frame_file.h"

#include <fcntl.h>

#include <cctype>
#include <charconv>

namespace bsls::store {

namespace {

constexpr std::string_view kSuffix = ".pgm";

// The largest file ReadFrameFile accepts: the biggest frame plus a header.
constexpr std::uint64_t kMaxFileBytes = static_cast<std::uint64_t>(8192) * 8192 + 4096;

}  // namespace

std::string FrameFileName(const CaptureId& id, framestore::Camera camera) {
  return id.str() + "-" + framestore::ToString(camera) + std::string(kSuffix);
}

std::optional<FrameFileNameParts> ParseFrameFileName(std::string_view name) {
  if (name.size() < 32 + 1 + kSuffix.size() || name[32] != '-' ||
      name.substr(name.size() - kSuffix.size()) != kSuffix) {
    return std::nullopt;
  }
  auto id = CaptureId::Parse(name.substr(0, 32));
  auto camera = framestore::ParseCamera(name.substr(33, name.size() - 33 - kSuffix.size()));
  if (!id || !camera) return std::nullopt;
  return FrameFileNameParts{*id, *camera};
}

std::string FrameFileHeader(const CaptureId& id, framestore::Camera camera, int width, int height) {
  return "P5\n# bsls-frame 1 capture=" + id.str() + " camera=" + framestore::ToString(camera) +
         "\n" + std::to_string(width) + " " + std::to_string(height) + "\n255\n";
}

std::uint64_t FrameFileBytes(const CaptureId& id, framestore::Camera camera, int width,
                             int height) {
  return FrameFileHeader(id, camera, width, height).size() +
         static_cast<std::uint64_t>(width) * height;
}

Result<std::uint64_t> WriteFrameFile(FileSystem& fs, const std::string& directory,
                                     const std::string& name, const CaptureId& id,
                                     const framestore::GreyFrame& frame) {
  const std::string header = FrameFileHeader(id, frame.camera, frame.width, frame.height);
  std::vector<std::string_view> pieces = {header};
  const auto* pixels = reinterpret_cast<const char*>(frame.pixels.data());
  const std::size_t width = static_cast<std::size_t>(frame.width);
  if (frame.stride == frame.width) {
    pieces.emplace_back(pixels, width * frame.height);
  } else {
    for (int row = 0; row < frame.height; ++row)
      pieces.emplace_back(pixels + static_cast<std::size_t>(row) * frame.stride, width);
  }
  if (Status status = WriteFileDurably(fs, directory, name, pieces, kFileMode); !status.ok())
    return status;
  return static_cast<std::uint64_t>(header.size()) + width * frame.height;
}

namespace {

// Reads the next header token (skipping whitespace and '#' comment lines).
std::optional<std::string_view> NextToken(std::string_view data, std::size_t& pos) {
  while (pos < data.size()) {
    if (data[pos] == '#') {
      while (pos < data.size() && data[pos] != '\n') ++pos;
    } else if (std::isspace(static_cast<unsigned char>(data[pos]))) {
      ++pos;
    } else {
      break;
    }
  }
  const std::size_t start = pos;
  while (pos < data.size() && !std::isspace(static_cast<unsigned char>(data[pos])) &&
         data[pos] != '#') {
    ++pos;
  }
  if (pos == start) return std::nullopt;
  return data.substr(start, pos - start);
}

std::optional<int> ParseInt(std::optional<std::string_view> token) {
  if (!token) return std::nullopt;
  int value = 0;
  auto [end, error] = std::from_chars(token->data(), token->data() + token->size(), value);
  if (error != std::errc() || end != token->data() + token->size()) return std::nullopt;
  return value;
}

}  // namespace

Result<FrameFileContent> ReadFrameFile(FileSystem& fs, const std::string& path) {
  auto read = ReadWholeFile(fs, path, kMaxFileBytes);
  if (!read.ok()) {
    if (read.status().code() == ErrorCode::kDataLoss)
      return Status(ErrorCode::kDataLoss, path + " is larger than any frame file");
    return read.status();
  }
  const std::string& bytes = *read;
  const std::string_view data(bytes);
  std::size_t pos = 0;
  const auto magic = NextToken(data, pos);
  const auto width = ParseInt(NextToken(data, pos));
  const auto height = ParseInt(NextToken(data, pos));
  const auto maxval = ParseInt(NextToken(data, pos));
  if (!magic || *magic != "P5" || !width || !height || !maxval || *width < 1 || *height < 1 ||
      *width > 8192 || *height > 8192 || *maxval != 255 || pos >= data.size() ||
      !std::isspace(static_cast<unsigned char>(data[pos]))) {
    return Status(ErrorCode::kDataLoss, path + " is not an 8-bit binary PGM frame file");
  }
  ++pos;  // the single whitespace after maxval
  const std::size_t pixel_bytes = static_cast<std::size_t>(*width) * *height;
  if (data.size() - pos != pixel_bytes) {
    return Status(ErrorCode::kDataLoss, path + " has " + std::to_string(data.size() - pos) +
                                            " pixel bytes, " + std::to_string(*width) + "x" +
                                            std::to_string(*height) + " needs " +
                                            std::to_string(pixel_bytes));
  }
  FrameFileContent content;
  content.width = *width;
  content.height = *height;
  content.file_bytes = bytes.size();
  content.pixels.assign(bytes.begin() + static_cast<std::ptrdiff_t>(pos), bytes.end());
  return content;
}

}  // namespace bsls::store
