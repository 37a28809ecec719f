#include "bsls/common/atomic_file.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <filesystem>
#include <random>

#include "bsls/common/errors.h"

namespace bsls {
namespace {

std::string Errno() { return std::strerror(errno); }

}  // namespace

void WriteFileAtomically(const std::string& path, std::string_view bytes) {
  namespace fs = std::filesystem;
  const fs::path target(path);
  const fs::path folder = target.has_parent_path() ? target.parent_path() : fs::path(".");
  std::random_device rd;
  const fs::path temp =
      folder / ("." + target.filename().string() + ".tmp" + std::to_string(rd() % 1000000));
  const int fd = ::open(temp.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0644);
  if (fd < 0) throw OutputError(path + ": cannot create a temporary file: " + Errno());
  size_t done = 0;
  while (done < bytes.size()) {
    const ssize_t n = ::write(fd, bytes.data() + done, bytes.size() - done);
    if (n < 0) {
      if (errno == EINTR) continue;
      const std::string why = Errno();
      ::close(fd);
      ::unlink(temp.c_str());
      throw OutputError(path + ": write failed: " + why);
    }
    done += static_cast<size_t>(n);
  }
  if (::fsync(fd) != 0 || ::close(fd) != 0) {
    const std::string why = Errno();
    ::unlink(temp.c_str());
    throw OutputError(path + ": cannot flush to disk: " + why);
  }
  if (::rename(temp.c_str(), target.c_str()) != 0) {
    const std::string why = Errno();
    ::unlink(temp.c_str());
    throw OutputError(path + ": cannot be put in place: " + why);
  }
  const int dir = ::open(folder.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  if (dir >= 0) {
    ::fsync(dir);
    ::close(dir);
  }
}

}  // namespace bsls
