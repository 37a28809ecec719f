// The durable capture store of bslsd: every
// grab is kept as frame files (frame_file.h) plus rows in a SQLite index
// (capture_index.h) under one root directory:
//
//   <root>/LOCK            flock(2)ed by the one process that has the store open
//   <root>/index.sqlite    the index (+ -wal, -shm while open)
//   <root>/frames/<id>-<camera>.pgm
//   <root>/results/<id>-<name>   processing results
//
// Put returns only when the capture is durable -- that return is the
// acknowledgement: each frame file is written to a temporary name, fsynced,
// renamed into place, the frames directory is fsynced, and then the index
// rows are committed (WAL, synchronous=FULL). A failure at any step fails the
// Put and nothing is acknowledged. Open recovers: it checks the index
// (PRAGMA integrity_check), verifies every indexed capture's files and
// hashes, reports every missing or corrupt acknowledged capture (never drops
// one), and removes leftovers of unacknowledged puts (temporary files, frame
// files without index rows). docs/capture-store.md gives the reasons.
//
// Thread-safety: every member is safe to call from several threads at once.
// Puts write their files in parallel and commit one at a time; Gets and Lists
// read through their own SQLite connection and do not wait for commits.
// Delete waits for Gets of the same capture to finish; retention skips
// captures being read or not yet acknowledged.
#ifndef BSLS_STORE_CAPTURE_STORE_H_
#define BSLS_STORE_CAPTURE_STORE_H_

#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <set>
#include <string>
#include <string_view>
#include <vector>

#include "bsls/store/capture.h"
#include "bsls/store/capture_id.h"
#include "bsls/store/capture_index.h"
#include "bsls/store/file_system.h"
#include "bsls/store/provenance.h"

namespace bsls::store {

// Which captures ApplyRetention deletes, oldest (taken_wall) first. Unset
// limits do not apply; with neither set nothing is ever deleted by retention.
struct RetentionPolicy {
  std::optional<std::uint64_t> max_total_bytes;  // frame file bytes of all captures
  std::optional<std::chrono::seconds> max_age;   // now - taken_wall
};

// How to open a store.
struct CaptureStoreOptions {
  std::string root;  // the store's directory; created if missing (its parent must exist)
  // A Put is refused (kResourceExhausted) unless, after writing the capture,
  // at least this many bytes stay free on the root's filesystem.
  std::uint64_t free_space_reserve_bytes = 256ull << 20;
  // Open reads every frame file and checks its SHA-256 (else: only that it exists).
  bool verify_hashes_on_open = true;
  RetentionPolicy retention;
  // The filesystem seam; borrowed, must outlive the store. nullptr: POSIX.
  FileSystem* file_system = nullptr;
  // The SQLite VFS of the index ("" : SQLite's default), e.g. FaultySqliteVfs::name().
  std::string sqlite_vfs;

  // True when the options can be used; otherwise `error` names the field.
  bool IsValid(std::string* error) const;
};

// An acknowledged capture that is missing or damaged: data loss to surface.
struct CaptureProblem {
  std::string id;  // as indexed
  Status status;   // kDataLoss (or the I/O error that prevented the check)
};

// What Open found and did.
struct RecoveryReport {
  int captures_checked = 0;
  std::vector<CaptureProblem> problems;    // acknowledged captures lost or corrupt
  int temp_files_removed = 0;              // leftovers of puts interrupted mid-file
  int orphan_files_removed = 0;            // frame files whose put never committed
  int result_files_removed = 0;            // results without a committed record, temporaries
  std::vector<std::string> unknown_files;  // names in frames/ not made by the store; kept

  // True when every acknowledged capture is intact.
  bool ok() const { return problems.empty(); }
};

// What ApplyRetention deleted.
struct RetentionReport {
  std::vector<CaptureId> deleted;  // oldest first
  std::uint64_t bytes_freed = 0;
  int skipped_busy = 0;  // captures retention would delete but that were being read
};

// What the store holds and how much room is left.
struct StoreUsage {
  std::uint64_t captures = 0;
  std::uint64_t total_bytes = 0;  // frame files of all captures
  std::uint64_t free_bytes = 0;   // available to new captures (after the reserve)
};

// The store. Open one per root directory and process (LOCK enforces it).
class CaptureStore {
 public:
  // Opens or creates the store at options.root and recovers it (see the file
  // comment). Fails with kFailedPrecondition if another process has it open,
  // kDataLoss if the index fails its integrity check, kInvalidArgument for bad
  // options, I/O errors otherwise. Damaged acknowledged captures do NOT fail
  // Open: they are listed in recovery_report() for the daemon to surface.
  static Result<std::unique_ptr<CaptureStore>> Open(const CaptureStoreOptions& options);

  ~CaptureStore();
  CaptureStore(const CaptureStore&) = delete;
  CaptureStore& operator=(const CaptureStore&) = delete;

  // What Open found and did.
  const RecoveryReport& recovery_report() const { return recovery_; }

  // Stores a grab; returns its metadata (with a new id) once it is durable.
  // kInvalidArgument for a malformed request, kResourceExhausted before
  // anything is written when free space would drop below the reserve (or on
  // ENOSPC), I/O errors (kUnavailable, ...) naming the step and the file.
  // A failed Put acknowledged nothing.
  Result<CaptureInfo> Put(const CaptureRequest& request);

  // The capture's metadata and frames, every frame's SHA-256 verified.
  // kInvalidArgument for a malformed id, kNotFound for an unknown (or
  // just deleted) one, kDataLoss for a missing or corrupt frame file.
  Result<Capture> Get(std::string_view id);

  // A page of capture metadata (no pixels), see CaptureFilter.
  Result<CapturePage> List(const CaptureFilter& filter);

  // Deletes a capture: its index row first (committed), then its files. Waits
  // for Gets of that capture to finish. kInvalidArgument / kNotFound as Get.
  Status Delete(std::string_view id);

  // Applies options.retention at wall-clock time `now`: deletes the oldest
  // captures while any is older than max_age or the total exceeds
  // max_total_bytes, skipping captures being read or not yet acknowledged.
  Result<RetentionReport> ApplyRetention(std::chrono::system_clock::time_point now);

  // Re-verifies every acknowledged capture now (files and hashes); the list
  // is empty when all are intact. For a periodic scrub or an admin request.
  Result<std::vector<CaptureProblem>> VerifyAll();

  // PRAGMA integrity_check of the index; kDataLoss with SQLite's findings.
  Status CheckIndexIntegrity();

  // How many captures the store holds, their bytes, and the free space left
  // for new ones (filesystem free space minus the reserve, never negative).
  Result<StoreUsage> Usage();

  // The store's root directory.
  const std::string& root() const { return options_.root; }

  // Processing: every capture is processed once by the processing
  // service; its results are stored beside it as <root>/results/<id>-<name>,
  // each written durably, then the record (state done, each file's SHA-256)
  // is committed. Captures not yet done or failed, oldest first.
  Result<std::vector<CaptureId>> Unprocessed();
  // The processing record of a capture; nullopt when it was never tried.
  Result<std::optional<ProcessingRecord>> Processing(std::string_view id);
  // Counts a failed attempt (the capture stays pending) with its reason.
  Status NoteProcessingAttempt(std::string_view id, const std::string& error);
  // Marks a capture as not processable (not tried again) with the reason.
  Status PutProcessingFailure(std::string_view id, const std::string& error);
  // Stores the result files (name -> bytes; names of [A-Za-z0-9._-], at
  // most 64 bytes, record.json reserved) with the sealed record of where
  // they came from (record.json, written here from the capture's metadata
  // and `provenance`), and marks the capture done. kResourceExhausted when
  // the disk reserve would be broken; nothing is committed on failure.
  Status PutProcessingResult(std::string_view id, const std::map<std::string, std::string>& files,
                             const ProcessingProvenance& provenance);
  // The stored result files (or only `only` when not empty), each verified
  // against its SHA-256; kNotFound before the capture is done, kDataLoss for
  // a missing or damaged file.
  Result<std::map<std::string, std::string>> ReadProcessingFiles(std::string_view id,
                                                                 const std::string& only = "");

 private:
  CaptureStore(const CaptureStoreOptions& options, std::unique_ptr<FileSystem> owned_fs,
               FileSystem& fs, int lock_fd);
  Status Recover();
  Status RecoverResults();
  // Reads and verifies one indexed frame; `out` receives the pixels if given.
  Status VerifyFrame(const CaptureInfo& info, const StoredFrameInfo& frame,
                     framestore::GreyFrame* out);
  // Removes the index rows, then the files, of a capture marked deleting.
  Status RemoveCapture(const CaptureInfo& info);
  Status CheckFreeSpace(const CaptureId& id, std::uint64_t bytes);
  // Calls `visit` on every indexed capture, page by page in index order; the
  // first failing page read is returned.
  Status ForEachCapture(const std::function<void(const CaptureInfo&)>& visit);

  CaptureStoreOptions options_;
  std::unique_ptr<FileSystem> owned_fs_;
  FileSystem& fs_;
  int lock_fd_;
  std::string frames_dir_;
  std::string results_dir_;
  std::unique_ptr<CaptureIndex> index_;
  CaptureIdGenerator ids_;
  RecoveryReport recovery_;

  std::mutex mutex_;  // guards the three sets below
  std::condition_variable readers_done_;
  std::map<std::string, int> readers_;  // Gets in progress, by id
  std::set<std::string> deleting_;      // captures being deleted
  std::set<std::string> in_flight_;     // Puts not yet acknowledged
};

}  // namespace bsls::store

#endif  // BSLS_STORE_CAPTURE_STORE_H_
