#include "bsls/store/frame_file.h"

#include <fcntl.h>

#include <cctype>
#include <charconv>

namespace bsls::store {

namespace {

constexpr std::string_view kSuffix = ".pgm";
constexpr mode_t kFileMode = 0640;
// The largest file ReadFrameFile accepts: the biggest frame plus a header.
constexpr std::uint64_t kMaxFileBytes = static_cast<std::uint64_t>(8192) * 8192 + 4096;

// Writes all `size` bytes, continuing after short writes.
Status WriteAll(FileSystem& fs, int fd, const std::uint8_t* data, std::size_t size,
                const std::string& path) {
  while (size > 0) {
    auto written = fs.Write(fd, data, size);
    if (!written.ok()) {
      return Status(written.status().code(), "writing " + path + ": " + written.status().message());
    }
    if (*written == 0) {
      return Status(ErrorCode::kUnavailable, "writing " + path + ": write returned 0 bytes");
    }
    data += *written;
    size -= *written;
  }
  return {};
}

Status Prefixed(const Status& status, const std::string& what) {
  return Status(status.code(), what + ": " + status.message());
}

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
  const std::string final_path = directory + "/" + name;
  const std::string temp_path = directory + "/" + std::string(kTempFilePrefix) + name;
  auto fd = fs.Open(temp_path, O_WRONLY | O_CREAT | O_EXCL, kFileMode);
  if (!fd.ok()) return Prefixed(fd.status(), "creating " + temp_path);

  const std::string header = FrameFileHeader(id, frame.camera, frame.width, frame.height);
  Status status = WriteAll(fs, *fd, reinterpret_cast<const std::uint8_t*>(header.data()),
                           header.size(), temp_path);
  if (status.ok() && frame.stride == frame.width) {
    status = WriteAll(fs, *fd, frame.pixels.data(),
                      static_cast<std::size_t>(frame.width) * frame.height, temp_path);
  } else {
    for (int row = 0; status.ok() && row < frame.height; ++row) {
      status = WriteAll(fs, *fd, frame.pixels.data() + static_cast<std::size_t>(row) * frame.stride,
                        static_cast<std::size_t>(frame.width), temp_path);
    }
  }
  if (status.ok()) {
    // The data must be on disk before the rename can make the name point at it.
    if (Status synced = fs.Fsync(*fd); !synced.ok()) {
      status = Prefixed(synced, "fsync of " + temp_path);
    }
  }
  if (Status closed = fs.Close(*fd); !closed.ok() && status.ok()) {
    status = Prefixed(closed, "closing " + temp_path);
  }
  if (status.ok()) {
    if (Status renamed = fs.Rename(temp_path, final_path); !renamed.ok()) {
      status = Prefixed(renamed, "publishing " + final_path);
    }
  }
  if (!status.ok()) {
    fs.Unlink(temp_path);  // best effort; recovery removes what is left
    return status;
  }
  return static_cast<std::uint64_t>(header.size()) +
         static_cast<std::uint64_t>(frame.width) * frame.height;
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
  auto fd = fs.Open(path, O_RDONLY, 0);
  if (!fd.ok()) return Prefixed(fd.status(), "opening frame file");
  std::vector<std::uint8_t> bytes;
  Status status;
  constexpr std::size_t kChunk = 1 << 20;
  while (status.ok()) {
    const std::size_t old_size = bytes.size();
    if (old_size > kMaxFileBytes) {
      status = Status(ErrorCode::kDataLoss, path + " is larger than any frame file");
      break;
    }
    bytes.resize(old_size + kChunk);
    auto got = fs.Read(*fd, bytes.data() + old_size, kChunk);
    if (!got.ok()) {
      status = Prefixed(got.status(), "reading " + path);
      bytes.resize(old_size);
      break;
    }
    bytes.resize(old_size + *got);
    if (*got == 0) break;
  }
  fs.Close(*fd);  // read-only: nothing to lose on a failed close
  if (!status.ok()) return status;

  const std::string_view data(reinterpret_cast<const char*>(bytes.data()), bytes.size());
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
