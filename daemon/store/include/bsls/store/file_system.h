// The filesystem seam of the capture store: every call the store makes to
// put frame files on disk, read them back and check free space goes through
// this small interface, so a fault-injecting wrapper (faulty_file_system.h)
// can fail any single step of the real code path.
//
// Calls mirror POSIX one to one (same arguments, same partial-write
// semantics); errors come back as a Status whose code is derived from errno
// (ErrnoToCode) and whose message names the call, the path and strerror.
//
// Thread-safety: implementations must be safe to call from several threads
// at once (the POSIX one is stateless).
#ifndef BSLS_STORE_FILE_SYSTEM_H_
#define BSLS_STORE_FILE_SYSTEM_H_

#include <sys/types.h>

#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "bsls/common/status.h"

namespace bsls::store {

// Free space of the filesystem holding a path, in bytes (statvfs(3)).
struct SpaceInfo {
  std::uint64_t available_bytes = 0;  // f_bavail * f_frsize: usable without privilege
  std::uint64_t total_bytes = 0;      // f_blocks * f_frsize
};

// The status code for an errno value: ENOSPC/EDQUOT -> kResourceExhausted,
// ENOENT -> kNotFound, EEXIST -> kAlreadyExists, EACCES/EPERM/EROFS ->
// kPermissionDenied, EINVAL/ENAMETOOLONG -> kInvalidArgument, anything else
// (EIO, ...) -> kUnavailable.
ErrorCode ErrnoToCode(int error_number);
// A Status "<call>(<path>): <strerror>" with the code of ErrnoToCode.
Status ErrnoStatus(int error_number, const std::string& call, const std::string& path);

// The POSIX file calls the capture store needs.
class FileSystem {
 public:
  virtual ~FileSystem() = default;

  // open(2); returns the descriptor.
  virtual Result<int> Open(const std::string& path, int flags, mode_t mode) = 0;
  // write(2): writes at most `size` bytes; returns how many (a short count is
  // not an error, the caller continues). EINTR is retried inside.
  virtual Result<std::size_t> Write(int fd, const void* data, std::size_t size) = 0;
  // read(2): reads at most `size` bytes; 0 at end of file.
  virtual Result<std::size_t> Read(int fd, void* data, std::size_t size) = 0;
  // fsync(2): the file's data and metadata are on stable storage when ok.
  virtual Status Fsync(int fd) = 0;
  // close(2); the descriptor is gone even when an error is returned.
  virtual Status Close(int fd) = 0;
  // rename(2): atomically replaces `to` with `from` (same filesystem).
  virtual Status Rename(const std::string& from, const std::string& to) = 0;
  // unlink(2).
  virtual Status Unlink(const std::string& path) = 0;
  // mkdir(2); kAlreadyExists when the path exists.
  virtual Status MakeDirectory(const std::string& path, mode_t mode) = 0;
  // Opens the directory read-only, fsync(2)s it and closes it: the names
  // created, renamed or removed in it are on stable storage when ok.
  virtual Status FsyncDirectory(const std::string& path) = 0;
  // statvfs(3) of the filesystem holding `path`.
  virtual Result<SpaceInfo> Statvfs(const std::string& path) = 0;
  // The names in a directory (without "." and ".."), in no particular order.
  virtual Result<std::vector<std::string>> ListDirectory(const std::string& path) = 0;
};

// Permissions of the store's files: the daemon's group may read them.
inline constexpr mode_t kFileMode = 0640;

// Prefix of files being written (WriteFileDurably); such files are never
// part of a capture or a result.
inline constexpr std::string_view kTempFilePrefix = ".tmp-";

// Writes the concatenated `pieces` to directory/<temp prefix>name, fsyncs it
// and renames it to directory/name: a reader sees no file or the whole file.
// The directory itself is not fsynced (the caller does, once per batch).
// On failure the temporary file is removed (best effort) and the error names
// the step and the file.
Status WriteFileDurably(FileSystem& fs, const std::string& directory, const std::string& name,
                        const std::vector<std::string_view>& pieces, mode_t mode);

// The whole file at `path`; kDataLoss when it is larger than `max_bytes`.
Result<std::string> ReadWholeFile(FileSystem& fs, const std::string& path, std::uint64_t max_bytes);

// The real thing: the POSIX calls themselves. Stateless, thread-safe.
std::unique_ptr<FileSystem> MakePosixFileSystem();

}  // namespace bsls::store

#endif  // BSLS_STORE_FILE_SYSTEM_H_
