#include "bsls/store/file_system.h"

#include <dirent.h>
#include <fcntl.h>
#include <sys/stat.h>
#include <sys/statvfs.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <string>
#include <vector>

namespace bsls::store {

ErrorCode ErrnoToCode(int error_number) {
  switch (error_number) {
    case ENOSPC:
    case EDQUOT:
      return ErrorCode::kResourceExhausted;
    case ENOENT:
      return ErrorCode::kNotFound;
    case EEXIST:
      return ErrorCode::kAlreadyExists;
    case EACCES:
    case EPERM:
    case EROFS:
      return ErrorCode::kPermissionDenied;
    case EINVAL:
    case ENAMETOOLONG:
      return ErrorCode::kInvalidArgument;
    default:
      return ErrorCode::kUnavailable;
  }
}

Status ErrnoStatus(int error_number, const std::string& call, const std::string& path) {
  return Status(ErrnoToCode(error_number), call + "(" + path + "): " + std::strerror(error_number));
}

namespace {

std::string FdName(int fd) { return "fd " + std::to_string(fd); }

class PosixFileSystem final : public FileSystem {
 public:
  Result<int> Open(const std::string& path, int flags, mode_t mode) override {
    int fd;
    do {
      fd = ::open(path.c_str(), flags | O_CLOEXEC, mode);
    } while (fd < 0 && errno == EINTR);
    if (fd < 0) return ErrnoStatus(errno, "open", path);
    return fd;
  }

  Result<std::size_t> Write(int fd, const void* data, std::size_t size) override {
    ssize_t written;
    do {
      written = ::write(fd, data, size);
    } while (written < 0 && errno == EINTR);
    if (written < 0) return ErrnoStatus(errno, "write", FdName(fd));
    return static_cast<std::size_t>(written);
  }

  Result<std::size_t> Read(int fd, void* data, std::size_t size) override {
    ssize_t got;
    do {
      got = ::read(fd, data, size);
    } while (got < 0 && errno == EINTR);
    if (got < 0) return ErrnoStatus(errno, "read", FdName(fd));
    return static_cast<std::size_t>(got);
  }

  Status Fsync(int fd) override {
    // Never retried on failure: after a failed fsync the kernel may have
    // dropped the dirty pages, and a second fsync would report success.
    if (::fsync(fd) != 0) return ErrnoStatus(errno, "fsync", FdName(fd));
    return {};
  }

  Status Close(int fd) override {
    // Linux releases the descriptor even when close fails (EINTR included).
    if (::close(fd) != 0) return ErrnoStatus(errno, "close", FdName(fd));
    return {};
  }

  Status Rename(const std::string& from, const std::string& to) override {
    if (::rename(from.c_str(), to.c_str()) != 0) {
      return ErrnoStatus(errno, "rename", from + " -> " + to);
    }
    return {};
  }

  Status Unlink(const std::string& path) override {
    if (::unlink(path.c_str()) != 0) return ErrnoStatus(errno, "unlink", path);
    return {};
  }

  Status MakeDirectory(const std::string& path, mode_t mode) override {
    if (::mkdir(path.c_str(), mode) != 0) return ErrnoStatus(errno, "mkdir", path);
    return {};
  }

  Status FsyncDirectory(const std::string& path) override {
    const int fd = ::open(path.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
    if (fd < 0) return ErrnoStatus(errno, "open", path);
    Status status;
    if (::fsync(fd) != 0) status = ErrnoStatus(errno, "fsync", path);
    ::close(fd);
    return status;
  }

  Result<SpaceInfo> Statvfs(const std::string& path) override {
    struct statvfs info {};
    if (::statvfs(path.c_str(), &info) != 0) return ErrnoStatus(errno, "statvfs", path);
    SpaceInfo space;
    space.available_bytes = static_cast<std::uint64_t>(info.f_bavail) * info.f_frsize;
    space.total_bytes = static_cast<std::uint64_t>(info.f_blocks) * info.f_frsize;
    return space;
  }

  Result<std::vector<std::string>> ListDirectory(const std::string& path) override {
    DIR* dir = ::opendir(path.c_str());
    if (dir == nullptr) return ErrnoStatus(errno, "opendir", path);
    std::vector<std::string> names;
    errno = 0;
    while (const dirent* entry = ::readdir(dir)) {
      const std::string name = entry->d_name;
      if (name != "." && name != "..") names.push_back(name);
      errno = 0;
    }
    const int error_number = errno;
    ::closedir(dir);
    if (error_number != 0) return ErrnoStatus(error_number, "readdir", path);
    return names;
  }
};

}  // namespace

std::unique_ptr<FileSystem> MakePosixFileSystem() { return std::make_unique<PosixFileSystem>(); }

namespace {

Status Prefixed(const Status& status, const std::string& what) {
  return Status(status.code(), what + ": " + status.message());
}

}  // namespace

Status WriteFileDurably(FileSystem& fs, const std::string& directory, const std::string& name,
                        const std::vector<std::string_view>& pieces, mode_t mode) {
  const std::string final_path = directory + "/" + name;
  const std::string temp_path = directory + "/" + std::string(kTempFilePrefix) + name;
  auto fd = fs.Open(temp_path, O_WRONLY | O_CREAT | O_EXCL, mode);
  if (!fd.ok()) return Prefixed(fd.status(), "creating " + temp_path);
  Status status;
  for (std::string_view piece : pieces) {
    while (status.ok() && !piece.empty()) {
      auto written = fs.Write(*fd, piece.data(), piece.size());
      if (!written.ok()) {
        status = Prefixed(written.status(), "writing " + temp_path);
      } else if (*written == 0) {
        status =
            Status(ErrorCode::kUnavailable, "writing " + temp_path + ": write returned 0 bytes");
      } else {
        piece.remove_prefix(*written);
      }
    }
  }
  // The data must be on disk before the rename can make the name point at it.
  if (status.ok()) {
    if (Status synced = fs.Fsync(*fd); !synced.ok())
      status = Prefixed(synced, "fsync of " + temp_path);
  }
  if (Status closed = fs.Close(*fd); !closed.ok() && status.ok())
    status = Prefixed(closed, "closing " + temp_path);
  if (status.ok()) {
    if (Status renamed = fs.Rename(temp_path, final_path); !renamed.ok())
      status = Prefixed(renamed, "publishing " + final_path);
  }
  if (!status.ok()) fs.Unlink(temp_path);  // best effort; recovery removes what is left
  return status;
}

Result<std::string> ReadWholeFile(FileSystem& fs, const std::string& path,
                                  std::uint64_t max_bytes) {
  auto fd = fs.Open(path, O_RDONLY, 0);
  if (!fd.ok()) return Prefixed(fd.status(), "opening " + path);
  // Read through one modest buffer and append: the string grows with what
  // the file holds, never zero-filled ahead of it.
  constexpr std::size_t kChunk = 64 * 1024;
  std::vector<char> chunk(kChunk);
  std::string bytes;
  Status status;
  while (status.ok()) {
    if (bytes.size() > max_bytes) {
      status = Status(ErrorCode::kDataLoss,
                      path + " is larger than " + std::to_string(max_bytes) + " bytes");
      break;
    }
    auto got = fs.Read(*fd, chunk.data(), kChunk);
    if (!got.ok()) {
      status = Prefixed(got.status(), "reading " + path);
      break;
    }
    if (*got == 0) break;
    bytes.append(chunk.data(), *got);
  }
  fs.Close(*fd);  // read-only: nothing to lose on a failed close
  if (!status.ok()) return status;
  return bytes;
}

}  // namespace bsls::store
