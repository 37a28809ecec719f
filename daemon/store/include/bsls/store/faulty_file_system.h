// A FileSystem wrapper that fails chosen calls: the Nth call of a kind from
// now fails with EIO or ENOSPC, or writes only part of its bytes, and
// statvfs can report less free space than there is. Everything else goes to
// the wrapped FileSystem, so the store's real code path runs up to the fault.
//
// The same object is the fault plan of the SQLite shim (faulty_sqlite_vfs.h):
// the kinds kDbWrite and kDbSync count and fail the index's own writes and
// syncs (database file and WAL), so one counter set covers a whole put.
//
// Used by the tests and the benchmark; product code never arms faults.
// Thread-safety: all members may be called from several threads at once;
// counting and arming are serialised by one mutex.
#ifndef BSLS_STORE_FAULTY_FILE_SYSTEM_H_
#define BSLS_STORE_FAULTY_FILE_SYSTEM_H_

#include <array>
#include <cstdint>
#include <mutex>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "bsls/store/file_system.h"

namespace bsls::store {

// The kinds of call that are counted and can be failed.
enum class FsOp : int {
  kOpen,
  kWrite,
  kRead,
  kFsync,
  kClose,
  kRename,
  kUnlink,
  kMakeDirectory,
  kFsyncDirectory,
  kStatvfs,
  kListDirectory,
  kDbWrite,  // a write (or truncate) of the SQLite database or WAL file
  kDbSync,   // a sync of the SQLite database or WAL file
};
inline constexpr int kFsOpCount = 13;

// "open", "write", ..., "db-sync".
std::string_view ToString(FsOp op);

// How an armed call fails.
enum class Fault {
  kEio,         // the call fails with EIO (SQLite: SQLITE_IOERR_*)
  kEnospc,      // the call fails with ENOSPC (SQLite: SQLITE_FULL)
  kShortWrite,  // kWrite only: writes half the bytes (at least 1) and succeeds
};

// A FileSystem whose calls can be made to fail, one at a time.
class FaultyFileSystem final : public FileSystem {
 public:
  // Wraps `inner`, which must outlive this object.
  explicit FaultyFileSystem(FileSystem& inner);

  // Arms a fault: the `nth` (1-based) call of kind `op` counted from now
  // fails with `fault`. Replaces an earlier arming of the same kind.
  void FailNth(FsOp op, int nth, Fault fault);
  // From now on every call of kind `op` fails with `fault` until Disarm().
  void FailAll(FsOp op, Fault fault);
  // Removes every armed fault and the free-space override.
  void Disarm();
  // Statvfs reports `bytes` available (nullopt: the real figure).
  void SetAvailableBytes(std::optional<std::uint64_t> bytes);
  // Calls of kind `op` since construction or the last ResetCounts().
  int count(FsOp op) const;
  // Zeroes every counter (armed faults keep their own countdown).
  void ResetCounts();
  // Faults that have fired since construction.
  int faults_fired() const;

  // Counts one call of kind `op` and returns the fault to inject, if armed.
  // Called by this class and by the SQLite shim.
  std::optional<Fault> Check(FsOp op);

  Result<int> Open(const std::string& path, int flags, mode_t mode) override;
  Result<std::size_t> Write(int fd, const void* data, std::size_t size) override;
  Result<std::size_t> Read(int fd, void* data, std::size_t size) override;
  Status Fsync(int fd) override;
  Status Close(int fd) override;
  Status Rename(const std::string& from, const std::string& to) override;
  Status Unlink(const std::string& path) override;
  Status MakeDirectory(const std::string& path, mode_t mode) override;
  Status FsyncDirectory(const std::string& path) override;
  Result<SpaceInfo> Statvfs(const std::string& path) override;
  Result<std::vector<std::string>> ListDirectory(const std::string& path) override;

 private:
  struct Arming {
    int remaining = 0;  // calls until the fault fires; 0: not armed
    bool always = false;
    Fault fault = Fault::kEio;
  };

  FileSystem& inner_;
  mutable std::mutex mutex_;
  std::array<int, kFsOpCount> counts_{};
  std::array<Arming, kFsOpCount> armed_{};
  std::optional<std::uint64_t> available_bytes_;
  int faults_fired_ = 0;
};

}  // namespace bsls::store

#endif  // BSLS_STORE_FAULTY_FILE_SYSTEM_H_
