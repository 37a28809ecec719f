// The SQLite index of the capture store: one row per acknowledged capture in
// `captures`, one row per frame file in `frames` and at most one processing
// record per capture in `processing` (foreign keys, ON DELETE CASCADE). docs/capture-store.md lists
// the schema.
//
// Durability: the database runs in WAL mode with synchronous=FULL, so a
// successful Insert or Remove has synced the WAL before it returns.
// Schema versions live in PRAGMA user_version; Open applies the missing
// migrations (kMigrations in the .cpp, one SQL script per version step) in
// one transaction each, and refuses a database newer than this software.
//
// Thread-safety: all members are thread-safe. Writes go through one
// connection (serialised by a mutex); Find/List/OldestFirst use a second,
// read-only connection with its own mutex, so readers never wait for a
// writer's commit fsync (WAL readers see the last committed state).
#ifndef BSLS_STORE_CAPTURE_INDEX_H_
#define BSLS_STORE_CAPTURE_INDEX_H_

#include <chrono>
#include <cstdint>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

#include "bsls/store/capture.h"
#include "bsls/store/file_system.h"

struct sqlite3;

namespace bsls::store {

// Which captures List returns, a page at a time, ordered by taken_wall then id.
struct CaptureFilter {
  std::optional<std::string> session_id;                              // exact match
  std::optional<std::string> patient_reference;                       // exact match
  std::optional<std::chrono::system_clock::time_point> taken_from;    // inclusive
  std::optional<std::chrono::system_clock::time_point> taken_before;  // exclusive
  int page_size = 0;       // 0: kDefaultPageSize; 1..kMaxPageSize otherwise
  std::string page_token;  // empty: the first page; else a CapturePage::next_page_token
};
inline constexpr int kDefaultPageSize = 100;
inline constexpr int kMaxPageSize = 1000;

// One page of a listing.
struct CapturePage {
  std::vector<CaptureInfo> captures;
  std::string next_page_token;  // empty on the last page
};

// What retention needs to know of a capture.
struct RetentionCandidate {
  CaptureId id;
  std::chrono::system_clock::time_point taken_wall;
  std::uint64_t total_bytes = 0;
};

// How much the index holds.
struct IndexTotals {
  std::uint64_t captures = 0;
  std::uint64_t total_bytes = 0;  // sum of the captures' frame file sizes
};

// The SQLite index.
class CaptureIndex {
 public:
  // Opens (creating if missing) the database at `path` with the SQLite VFS
  // named `vfs` ("" for the default), migrates it to the latest schema.
  // kFailedPrecondition for a schema newer than this software; database
  // errors mapped as in the .cpp (SQLITE_FULL -> kResourceExhausted, ...).
  static Result<std::unique_ptr<CaptureIndex>> Open(const std::string& path,
                                                    const std::string& vfs);
  // The schema version this software writes.
  static int LatestSchemaVersion();

  ~CaptureIndex();
  CaptureIndex(const CaptureIndex&) = delete;
  CaptureIndex& operator=(const CaptureIndex&) = delete;

  // The database's schema version (== LatestSchemaVersion() after Open).
  Result<int> SchemaVersion();
  // PRAGMA integrity_check and foreign_key_check; kDataLoss with SQLite's
  // first complaints when either finds a problem.
  Status CheckIntegrity();
  // Adds a capture and its frames in one transaction; ok only once committed
  // (WAL synced). kAlreadyExists for an id already present.
  Status Insert(const CaptureInfo& info);
  // The capture with that id; kNotFound if there is none.
  Result<CaptureInfo> Find(const CaptureId& id);
  // A page of captures matching `filter`; kInvalidArgument for a bad page
  // size or a page token this index did not make.
  Result<CapturePage> List(const CaptureFilter& filter);
  // Removes the capture's rows in one committed transaction; kNotFound if absent.
  Status Remove(const CaptureId& id);
  // Every capture, oldest (taken_wall, then id) first.
  Result<std::vector<RetentionCandidate>> OldestFirst();
  // The number of captures and their bytes.
  Result<IndexTotals> Totals();
  // Writes (replaces) the processing record of a capture in one committed
  // transaction; kNotFound when the capture is not indexed.
  Status PutProcessing(const CaptureId& id, const ProcessingRecord& record);
  // The processing record of a capture; nullopt when it has none yet.
  Result<std::optional<ProcessingRecord>> FindProcessing(const CaptureId& id);
  // Captures not yet done or failed (no record, or pending), oldest first.
  Result<std::vector<CaptureId>> Unprocessed();

 private:
  CaptureIndex(sqlite3* writer, sqlite3* reader, std::string path);
  Result<std::vector<StoredFrameInfo>> FramesOf(sqlite3* db, const std::string& id);

  std::mutex write_mutex_;
  sqlite3* writer_;
  std::mutex read_mutex_;
  sqlite3* reader_;
  std::string path_;
};

}  // namespace bsls::store

#endif  // BSLS_STORE_CAPTURE_INDEX_H_
