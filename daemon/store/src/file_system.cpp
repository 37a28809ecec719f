#include "bsls/store/file_system.h"

#include <dirent.h>
#include <fcntl.h>
#include <sys/stat.h>
#include <sys/statvfs.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>

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

}  // namespace bsls::store
