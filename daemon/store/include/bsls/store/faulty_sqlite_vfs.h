// A SQLite VFS shim that routes the capture index's file writes and syncs
// through a FaultyFileSystem's fault plan (FsOp::kDbWrite, FsOp::kDbSync):
// the database and its WAL are written by SQLite's own "unix" VFS, but an
// armed fault makes a write fail with SQLITE_IOERR_WRITE / SQLITE_FULL or a
// sync with SQLITE_IOERR_FSYNC, exactly as a failing disk would.
//
// Lifetime: registers a uniquely named VFS on construction and unregisters it
// on destruction; every connection opened with name() must be closed first.
// Thread-safety: SQLite may call the shim from any thread; it holds no state
// of its own besides the FaultyFileSystem pointer.
#ifndef BSLS_STORE_FAULTY_SQLITE_VFS_H_
#define BSLS_STORE_FAULTY_SQLITE_VFS_H_

#include <memory>
#include <string>

#include "bsls/store/faulty_file_system.h"

namespace bsls::store {

// A registered SQLite VFS whose writes and syncs obey `faults`.
class FaultySqliteVfs {
 public:
  // Registers the shim over SQLite's default VFS; `faults` must outlive it.
  explicit FaultySqliteVfs(FaultyFileSystem& faults);
  ~FaultySqliteVfs();
  FaultySqliteVfs(const FaultySqliteVfs&) = delete;
  FaultySqliteVfs& operator=(const FaultySqliteVfs&) = delete;

  // The VFS name to give CaptureStoreOptions::sqlite_vfs.
  const std::string& name() const;

  struct Impl;  // the sqlite3_vfs and its forwarding functions (in the .cpp)

 private:
  std::unique_ptr<Impl> impl_;
};

}  // namespace bsls::store

#endif  // BSLS_STORE_FAULTY_SQLITE_VFS_H_
