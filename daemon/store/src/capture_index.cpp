#include "bsls/store/capture_index.h"

#include <sqlite3.h>

#include <cassert>
#include <charconv>

namespace bsls::store {

namespace {

// Schema migrations: kMigrations[i] takes a database from user_version i to
// i + 1. To change the schema, append a script; never edit a shipped one.
const char* const kMigrations[] = {
    // 0 -> 1: the first schema.
    R"sql(
CREATE TABLE captures (
  id                TEXT PRIMARY KEY NOT NULL,  -- 32 hex digits, time-ordered
  session_id        TEXT NOT NULL,
  patient_reference TEXT NOT NULL,
  side              INTEGER NOT NULL,           -- Side: 0 left, 1 right, 2 both
  slide             INTEGER NOT NULL,
  software_version  TEXT NOT NULL,
  operator_uid      INTEGER NOT NULL,
  operator_name     TEXT NOT NULL,
  taken_wall_ns     INTEGER NOT NULL,           -- Unix time, ns
  stored_wall_ns    INTEGER NOT NULL,           -- Unix time, ns
  total_bytes       INTEGER NOT NULL
) WITHOUT ROWID;
CREATE INDEX captures_by_time ON captures (taken_wall_ns, id);
CREATE INDEX captures_by_session ON captures (session_id, taken_wall_ns, id);
CREATE INDEX captures_by_patient ON captures (patient_reference, taken_wall_ns, id);
CREATE TABLE frames (
  capture_id      TEXT NOT NULL REFERENCES captures (id) ON DELETE CASCADE,
  camera          INTEGER NOT NULL,             -- framestore::Camera
  gain            INTEGER NOT NULL,
  sequence        INTEGER NOT NULL,
  width           INTEGER NOT NULL,
  height          INTEGER NOT NULL,
  requested_ns    INTEGER NOT NULL,             -- steady_clock, ns
  exposed_ns      INTEGER NOT NULL,
  delivered_ns    INTEGER NOT NULL,
  wall_ns         INTEGER NOT NULL,             -- Unix time, ns
  sha256          TEXT NOT NULL,                -- hex, of the width*height pixels
  file_name       TEXT NOT NULL UNIQUE,         -- in <root>/frames/
  file_bytes      INTEGER NOT NULL,
  PRIMARY KEY (capture_id, camera)
) WITHOUT ROWID;
)sql",
    // 1 -> 2: the processing queue. A capture without a row has not
    // been tried; `files` lists "name sha256" lines of the stored results.
    R"sql(
CREATE TABLE processing (
  capture_id       TEXT PRIMARY KEY NOT NULL REFERENCES captures (id) ON DELETE CASCADE,
  state            INTEGER NOT NULL,            -- ProcessingState: 1 pending, 2 done, 3 failed
  attempts         INTEGER NOT NULL,
  last_error       TEXT NOT NULL,
  replica          TEXT NOT NULL,
  software_version TEXT NOT NULL,
  files            TEXT NOT NULL,
  updated_wall_ns  INTEGER NOT NULL
) WITHOUT ROWID;
)sql",
};
constexpr int kLatestVersion = static_cast<int>(std::size(kMigrations));

ErrorCode CodeOf(int sqlite_code) {
  switch (sqlite_code & 0xFF) {
    case SQLITE_FULL:
      return ErrorCode::kResourceExhausted;
    case SQLITE_CONSTRAINT:
      return ErrorCode::kAlreadyExists;
    case SQLITE_CORRUPT:
    case SQLITE_NOTADB:
      return ErrorCode::kDataLoss;
    case SQLITE_READONLY:
    case SQLITE_PERM:
    case SQLITE_AUTH:
      return ErrorCode::kPermissionDenied;
    case SQLITE_BUSY:
    case SQLITE_LOCKED:
    case SQLITE_IOERR:
    case SQLITE_CANTOPEN:
    case SQLITE_PROTOCOL:
      return ErrorCode::kUnavailable;
    default:
      return ErrorCode::kInternal;
  }
}

Status DbError(sqlite3* db, int rc, const std::string& what) {
  const char* message = db ? sqlite3_errmsg(db) : sqlite3_errstr(rc);
  return Status(CodeOf(rc), what + ": " + message + " (sqlite code " + std::to_string(rc) + ")");
}

// A prepared statement, finalised on destruction.
class Statement {
 public:
  Statement(sqlite3* db, const std::string& sql) : db_(db) {
    rc_ = sqlite3_prepare_v2(db, sql.c_str(), static_cast<int>(sql.size()), &stmt_, nullptr);
  }
  ~Statement() { sqlite3_finalize(stmt_); }
  Statement(const Statement&) = delete;
  Statement& operator=(const Statement&) = delete;

  bool prepared() const { return rc_ == SQLITE_OK; }
  int prepare_rc() const { return rc_; }
  void Bind(int index, const std::string& text) {
    sqlite3_bind_text(stmt_, index, text.data(), static_cast<int>(text.size()), SQLITE_TRANSIENT);
  }
  void Bind(int index, std::int64_t value) { sqlite3_bind_int64(stmt_, index, value); }
  // SQLITE_ROW, SQLITE_DONE or an error code.
  int Step() { return sqlite3_step(stmt_); }
  std::int64_t Int(int column) const { return sqlite3_column_int64(stmt_, column); }
  std::string Text(int column) const {
    const auto* text = sqlite3_column_text(stmt_, column);
    return text ? std::string(reinterpret_cast<const char*>(text),
                              static_cast<std::size_t>(sqlite3_column_bytes(stmt_, column)))
                : std::string();
  }

 private:
  sqlite3* db_;
  sqlite3_stmt* stmt_ = nullptr;
  int rc_ = SQLITE_OK;
};

Status Exec(sqlite3* db, const std::string& sql, const std::string& what) {
  char* error = nullptr;
  const int rc = sqlite3_exec(db, sql.c_str(), nullptr, nullptr, &error);
  if (rc != SQLITE_OK) {
    std::string message = error ? error : sqlite3_errstr(rc);
    sqlite3_free(error);
    return Status(CodeOf(rc), what + ": " + message + " (sqlite code " + std::to_string(rc) + ")");
  }
  return {};
}

// Ends a failed transaction; harmless when SQLite rolled back already.
void RollBack(sqlite3* db) {
  if (sqlite3_get_autocommit(db) == 0) sqlite3_exec(db, "ROLLBACK", nullptr, nullptr, nullptr);
}

std::int64_t Nanos(std::chrono::system_clock::time_point t) {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(t.time_since_epoch()).count();
}
std::int64_t Nanos(std::chrono::steady_clock::time_point t) {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(t.time_since_epoch()).count();
}
std::chrono::system_clock::time_point WallAt(std::int64_t ns) {
  return std::chrono::system_clock::time_point(
      std::chrono::duration_cast<std::chrono::system_clock::duration>(
          std::chrono::nanoseconds(ns)));
}
std::chrono::steady_clock::time_point SteadyAt(std::int64_t ns) {
  return std::chrono::steady_clock::time_point(
      std::chrono::duration_cast<std::chrono::steady_clock::duration>(
          std::chrono::nanoseconds(ns)));
}

Result<sqlite3*> OpenConnection(const std::string& path, const std::string& vfs, bool writer) {
  sqlite3* db = nullptr;
  const int flags = SQLITE_OPEN_READWRITE | (writer ? SQLITE_OPEN_CREATE : 0) |
                    SQLITE_OPEN_NOMUTEX | SQLITE_OPEN_EXRESCODE;
  const int rc = sqlite3_open_v2(path.c_str(), &db, flags, vfs.empty() ? nullptr : vfs.c_str());
  if (rc != SQLITE_OK) {
    Status status = DbError(db, rc, "opening capture index " + path);
    sqlite3_close_v2(db);
    return status;
  }
  // synchronous=FULL: in WAL mode every commit syncs the WAL before it returns.
  std::string pragmas =
      "PRAGMA busy_timeout = 10000; PRAGMA foreign_keys = ON; PRAGMA synchronous = FULL;"
      " PRAGMA mmap_size = 0;";
  if (!writer) pragmas += " PRAGMA query_only = ON;";
  if (Status status = Exec(db, pragmas, "configuring capture index " + path); !status.ok()) {
    sqlite3_close_v2(db);
    return status;
  }
  return db;
}

// Reads one text/int result row of a single-value query.
Result<std::string> QueryText(sqlite3* db, const std::string& sql, const std::string& what) {
  Statement statement(db, sql);
  if (!statement.prepared()) return DbError(db, statement.prepare_rc(), what);
  const int rc = statement.Step();
  if (rc != SQLITE_ROW) return DbError(db, rc, what);
  return statement.Text(0);
}

constexpr const char* kCaptureColumns =
    "id, session_id, patient_reference, side, slide, software_version, operator_uid,"
    " operator_name, taken_wall_ns, stored_wall_ns, total_bytes";

CaptureInfo CaptureFromRow(const Statement& row) {
  CaptureInfo info{*CaptureId::Parse("00000000000000000000000000000000")};
  if (auto id = CaptureId::Parse(row.Text(0))) info.id = *id;
  info.session_id = row.Text(1);
  info.patient_reference = row.Text(2);
  info.side = static_cast<Side>(row.Int(3));
  info.slide = static_cast<int>(row.Int(4));
  info.software_version = row.Text(5);
  info.requested_by.uid = row.Int(6);
  info.requested_by.name = row.Text(7);
  info.taken_wall = WallAt(row.Int(8));
  info.stored_wall = WallAt(row.Int(9));
  info.total_bytes = static_cast<std::uint64_t>(row.Int(10));
  return info;
}

std::string PageToken(const CaptureInfo& last) {
  return std::to_string(Nanos(last.taken_wall)) + "." + last.id.str();
}

bool ParsePageToken(const std::string& token, std::int64_t* taken_ns, std::string* id) {
  const auto dot = token.find('.');
  if (dot == std::string::npos) return false;
  auto [end, error] = std::from_chars(token.data(), token.data() + dot, *taken_ns);
  if (error != std::errc() || end != token.data() + dot) return false;
  if (!CaptureId::Parse(std::string_view(token).substr(dot + 1))) return false;
  *id = token.substr(dot + 1);
  return true;
}

}  // namespace

int CaptureIndex::LatestSchemaVersion() { return kLatestVersion; }

Result<std::unique_ptr<CaptureIndex>> CaptureIndex::Open(const std::string& path,
                                                         const std::string& vfs) {
  auto writer = OpenConnection(path, vfs, /*writer=*/true);
  if (!writer.ok()) return writer.status();
  sqlite3* db = *writer;
  auto close_writer = [db](Status status) -> Result<std::unique_ptr<CaptureIndex>> {
    sqlite3_close_v2(db);
    return status;
  };
  auto mode = QueryText(db, "PRAGMA journal_mode = WAL", "switching " + path + " to WAL");
  if (!mode.ok()) return close_writer(mode.status());
  if (*mode != "wal") {
    return close_writer(Status(ErrorCode::kFailedPrecondition,
                               "capture index " + path + " cannot use WAL (journal mode " + *mode +
                                   "); is it on a network filesystem?"));
  }
  auto version_text = QueryText(db, "PRAGMA user_version", "reading schema version of " + path);
  if (!version_text.ok()) return close_writer(version_text.status());
  const int version = std::stoi(*version_text);
  if (version > kLatestVersion) {
    return close_writer(Status(ErrorCode::kFailedPrecondition,
                               "capture index " + path + " has schema version " +
                                   std::to_string(version) + ", newer than this software's " +
                                   std::to_string(kLatestVersion)));
  }
  for (int step = version; step < kLatestVersion; ++step) {
    const std::string script = std::string("BEGIN IMMEDIATE;") + kMigrations[step] +
                               "PRAGMA user_version = " + std::to_string(step + 1) + "; COMMIT;";
    if (Status status = Exec(
            db, script,
            "migrating capture index " + path + " from schema version " + std::to_string(step));
        !status.ok()) {
      RollBack(db);
      return close_writer(status);
    }
  }
  auto reader = OpenConnection(path, vfs, /*writer=*/false);
  if (!reader.ok()) return close_writer(reader.status());
  return std::unique_ptr<CaptureIndex>(new CaptureIndex(db, *reader, path));
}

CaptureIndex::CaptureIndex(sqlite3* writer, sqlite3* reader, std::string path)
    : writer_(writer), reader_(reader), path_(std::move(path)) {}

CaptureIndex::~CaptureIndex() {
  sqlite3_close_v2(reader_);
  sqlite3_close_v2(writer_);
}

Result<int> CaptureIndex::SchemaVersion() {
  std::lock_guard lock(read_mutex_);
  auto text = QueryText(reader_, "PRAGMA user_version", "reading schema version of " + path_);
  if (!text.ok()) return text.status();
  return std::stoi(*text);
}

Status CaptureIndex::CheckIntegrity() {
  std::lock_guard lock(write_mutex_);
  Statement integrity(writer_, "PRAGMA integrity_check(20)");
  if (!integrity.prepared()) {
    return DbError(writer_, integrity.prepare_rc(), "integrity check of " + path_);
  }
  std::string problems;
  int rc;
  while ((rc = integrity.Step()) == SQLITE_ROW) {
    const std::string line = integrity.Text(0);
    if (line != "ok") problems += (problems.empty() ? "" : "; ") + line;
  }
  if (rc != SQLITE_DONE) return DbError(writer_, rc, "integrity check of " + path_);
  Statement foreign(writer_, "PRAGMA foreign_key_check");
  if (!foreign.prepared()) {
    return DbError(writer_, foreign.prepare_rc(), "foreign key check of " + path_);
  }
  while ((rc = foreign.Step()) == SQLITE_ROW) {
    problems += (problems.empty() ? "" : "; ") + std::string("row of ") + foreign.Text(0) +
                " refers to a missing " + foreign.Text(2);
  }
  if (rc != SQLITE_DONE) return DbError(writer_, rc, "foreign key check of " + path_);
  if (!problems.empty()) {
    return Status(ErrorCode::kDataLoss, "capture index " + path_ + " is damaged: " + problems);
  }
  return {};
}

Status CaptureIndex::Insert(const CaptureInfo& info) {
  std::lock_guard lock(write_mutex_);
  const std::string what = "indexing capture " + info.id.str() + " in " + path_;
  if (Status status = Exec(writer_, "BEGIN IMMEDIATE", what); !status.ok()) return status;
  auto fail = [&](int rc) {
    Status status = DbError(writer_, rc, what);
    RollBack(writer_);
    return status;
  };
  {
    Statement insert(writer_, std::string("INSERT INTO captures (") + kCaptureColumns +
                                  ") VALUES (?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?)");
    if (!insert.prepared()) return fail(insert.prepare_rc());
    insert.Bind(1, info.id.str());
    insert.Bind(2, info.session_id);
    insert.Bind(3, info.patient_reference);
    insert.Bind(4, static_cast<std::int64_t>(info.side));
    insert.Bind(5, static_cast<std::int64_t>(info.slide));
    insert.Bind(6, info.software_version);
    insert.Bind(7, info.requested_by.uid);
    insert.Bind(8, info.requested_by.name);
    insert.Bind(9, Nanos(info.taken_wall));
    insert.Bind(10, Nanos(info.stored_wall));
    insert.Bind(11, static_cast<std::int64_t>(info.total_bytes));
    if (const int rc = insert.Step(); rc != SQLITE_DONE) return fail(rc);
  }
  for (const StoredFrameInfo& frame : info.frames) {
    Statement insert(writer_,
                     "INSERT INTO frames (capture_id, camera, gain, sequence, width, height,"
                     " requested_ns, exposed_ns, delivered_ns, wall_ns, sha256, file_name,"
                     " file_bytes) VALUES (?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?)");
    if (!insert.prepared()) return fail(insert.prepare_rc());
    insert.Bind(1, info.id.str());
    insert.Bind(2, static_cast<std::int64_t>(frame.camera));
    insert.Bind(3, static_cast<std::int64_t>(frame.gain));
    insert.Bind(4, static_cast<std::int64_t>(frame.sequence));
    insert.Bind(5, static_cast<std::int64_t>(frame.width));
    insert.Bind(6, static_cast<std::int64_t>(frame.height));
    insert.Bind(7, Nanos(frame.timestamps.requested));
    insert.Bind(8, Nanos(frame.timestamps.exposed));
    insert.Bind(9, Nanos(frame.timestamps.delivered));
    insert.Bind(10, Nanos(frame.timestamps.wall));
    insert.Bind(11, frame.sha256);
    insert.Bind(12, frame.file_name);
    insert.Bind(13, static_cast<std::int64_t>(frame.file_bytes));
    if (const int rc = insert.Step(); rc != SQLITE_DONE) return fail(rc);
  }
  if (const int rc = sqlite3_exec(writer_, "COMMIT", nullptr, nullptr, nullptr); rc != SQLITE_OK) {
    return fail(rc);
  }
  return {};
}

Result<std::vector<StoredFrameInfo>> CaptureIndex::FramesOf(sqlite3* db, const std::string& id) {
  Statement select(db,
                   "SELECT camera, gain, sequence, width, height, requested_ns, exposed_ns,"
                   " delivered_ns, wall_ns, sha256, file_name, file_bytes FROM frames"
                   " WHERE capture_id = ? ORDER BY camera");
  const std::string what = "reading frames of capture " + id + " from " + path_;
  if (!select.prepared()) return DbError(db, select.prepare_rc(), what);
  select.Bind(1, id);
  std::vector<StoredFrameInfo> frames;
  int rc;
  while ((rc = select.Step()) == SQLITE_ROW) {
    StoredFrameInfo frame;
    frame.camera = static_cast<framestore::Camera>(select.Int(0));
    frame.gain = static_cast<int>(select.Int(1));
    frame.sequence = static_cast<std::uint64_t>(select.Int(2));
    frame.width = static_cast<int>(select.Int(3));
    frame.height = static_cast<int>(select.Int(4));
    frame.timestamps.requested = SteadyAt(select.Int(5));
    frame.timestamps.exposed = SteadyAt(select.Int(6));
    frame.timestamps.delivered = SteadyAt(select.Int(7));
    frame.timestamps.wall = WallAt(select.Int(8));
    frame.sha256 = select.Text(9);
    frame.file_name = select.Text(10);
    frame.file_bytes = static_cast<std::uint64_t>(select.Int(11));
    frames.push_back(std::move(frame));
  }
  if (rc != SQLITE_DONE) return DbError(db, rc, what);
  return frames;
}

Result<CaptureInfo> CaptureIndex::Find(const CaptureId& id) {
  std::lock_guard lock(read_mutex_);
  const std::string what = "looking up capture " + id.str() + " in " + path_;
  // One read transaction so the capture row and its frame rows agree.
  if (Status status = Exec(reader_, "BEGIN", what); !status.ok()) return status;
  Result<CaptureInfo> result = [&]() -> Result<CaptureInfo> {
    Statement select(reader_,
                     std::string("SELECT ") + kCaptureColumns + " FROM captures WHERE id = ?");
    if (!select.prepared()) return DbError(reader_, select.prepare_rc(), what);
    select.Bind(1, id.str());
    const int rc = select.Step();
    if (rc == SQLITE_DONE) {
      return Status(ErrorCode::kNotFound, "no capture with id " + id.str());
    }
    if (rc != SQLITE_ROW) return DbError(reader_, rc, what);
    CaptureInfo info = CaptureFromRow(select);
    auto frames = FramesOf(reader_, id.str());
    if (!frames.ok()) return frames.status();
    info.frames = std::move(*frames);
    return info;
  }();
  RollBack(reader_);
  return result;
}

Result<CapturePage> CaptureIndex::List(const CaptureFilter& filter) {
  const int page_size = filter.page_size == 0 ? kDefaultPageSize : filter.page_size;
  if (page_size < 1 || page_size > kMaxPageSize) {
    return Status(ErrorCode::kInvalidArgument, "page size " + std::to_string(filter.page_size) +
                                                   " is outside 1.." +
                                                   std::to_string(kMaxPageSize));
  }
  std::int64_t after_ns = 0;
  std::string after_id;
  if (!filter.page_token.empty() && !ParsePageToken(filter.page_token, &after_ns, &after_id)) {
    // The token is the caller's: quoted only in part (a reply's metadata is small).
    constexpr std::size_t kQuoted = 40;
    const std::string quoted = filter.page_token.size() <= kQuoted
                                   ? filter.page_token
                                   : filter.page_token.substr(0, kQuoted) + "... (" +
                                         std::to_string(filter.page_token.size()) + " bytes)";
    return Status(ErrorCode::kInvalidArgument,
                  "page token \"" + quoted + "\" was not made by this store");
  }
  std::string sql = std::string("SELECT ") + kCaptureColumns + " FROM captures WHERE 1";
  if (filter.session_id) sql += " AND session_id = :session";
  if (filter.patient_reference) sql += " AND patient_reference = :patient";
  if (filter.taken_from) sql += " AND taken_wall_ns >= :from";
  if (filter.taken_before) sql += " AND taken_wall_ns < :before";
  if (!filter.page_token.empty()) {
    sql += " AND (taken_wall_ns > :after_ns OR (taken_wall_ns = :after_ns AND id > :after_id))";
  }
  sql += " ORDER BY taken_wall_ns, id LIMIT :limit";

  std::lock_guard lock(read_mutex_);
  const std::string what = "listing captures of " + path_;
  if (Status status = Exec(reader_, "BEGIN", what); !status.ok()) return status;
  Result<CapturePage> result = [&]() -> Result<CapturePage> {
    Statement select(reader_, sql);
    if (!select.prepared()) return DbError(reader_, select.prepare_rc(), what);
    // Named parameters are numbered in order of first appearance; a name used
    // twice (:after_ns) has one number.
    int index = 1;
    if (filter.session_id) select.Bind(index++, *filter.session_id);
    if (filter.patient_reference) select.Bind(index++, *filter.patient_reference);
    if (filter.taken_from) select.Bind(index++, Nanos(*filter.taken_from));
    if (filter.taken_before) select.Bind(index++, Nanos(*filter.taken_before));
    if (!filter.page_token.empty()) {
      select.Bind(index++, after_ns);
      select.Bind(index++, after_id);
    }
    select.Bind(index++, static_cast<std::int64_t>(page_size + 1));
    CapturePage page;
    int rc;
    while ((rc = select.Step()) == SQLITE_ROW) {
      if (static_cast<int>(page.captures.size()) == page_size) {
        page.next_page_token = PageToken(page.captures.back());
        break;
      }
      page.captures.push_back(CaptureFromRow(select));
    }
    if (rc != SQLITE_ROW && rc != SQLITE_DONE) return DbError(reader_, rc, what);
    for (CaptureInfo& info : page.captures) {
      auto frames = FramesOf(reader_, info.id.str());
      if (!frames.ok()) return frames.status();
      info.frames = std::move(*frames);
    }
    return page;
  }();
  RollBack(reader_);
  return result;
}

Status CaptureIndex::Remove(const CaptureId& id) {
  std::lock_guard lock(write_mutex_);
  const std::string what = "removing capture " + id.str() + " from " + path_;
  if (Status status = Exec(writer_, "BEGIN IMMEDIATE", what); !status.ok()) return status;
  Statement remove(writer_, "DELETE FROM captures WHERE id = ?");
  if (!remove.prepared()) {
    Status status = DbError(writer_, remove.prepare_rc(), what);
    RollBack(writer_);
    return status;
  }
  remove.Bind(1, id.str());
  if (const int rc = remove.Step(); rc != SQLITE_DONE) {
    Status status = DbError(writer_, rc, what);
    RollBack(writer_);
    return status;
  }
  if (sqlite3_changes(writer_) == 0) {
    RollBack(writer_);
    return Status(ErrorCode::kNotFound, "no capture with id " + id.str());
  }
  if (const int rc = sqlite3_exec(writer_, "COMMIT", nullptr, nullptr, nullptr); rc != SQLITE_OK) {
    Status status = DbError(writer_, rc, what);
    RollBack(writer_);
    return status;
  }
  return {};
}

Result<std::vector<RetentionCandidate>> CaptureIndex::OldestFirst() {
  std::lock_guard lock(read_mutex_);
  const std::string what = "listing captures of " + path_ + " for retention";
  Statement select(reader_,
                   "SELECT id, taken_wall_ns, total_bytes FROM captures"
                   " ORDER BY taken_wall_ns, id");
  if (!select.prepared()) return DbError(reader_, select.prepare_rc(), what);
  std::vector<RetentionCandidate> candidates;
  int rc;
  while ((rc = select.Step()) == SQLITE_ROW) {
    auto id = CaptureId::Parse(select.Text(0));
    if (!id) continue;  // not ours to judge here; recovery reports malformed rows
    candidates.push_back(
        RetentionCandidate{*id, WallAt(select.Int(1)), static_cast<std::uint64_t>(select.Int(2))});
  }
  if (rc != SQLITE_DONE) return DbError(reader_, rc, what);
  return candidates;
}

Result<IndexTotals> CaptureIndex::Totals() {
  std::lock_guard lock(read_mutex_);
  const std::string what = "counting the captures of " + path_;
  Statement select(reader_, "SELECT COUNT(*), COALESCE(SUM(total_bytes), 0) FROM captures");
  if (!select.prepared()) return DbError(reader_, select.prepare_rc(), what);
  const int rc = select.Step();
  if (rc != SQLITE_ROW) return DbError(reader_, rc, what);
  return IndexTotals{static_cast<std::uint64_t>(select.Int(0)),
                     static_cast<std::uint64_t>(select.Int(1))};
}

Status CaptureIndex::PutProcessing(const CaptureId& id, const ProcessingRecord& record) {
  std::lock_guard lock(write_mutex_);
  const std::string what = "recording the processing of capture " + id.str() + " in " + path_;
  std::string files;
  for (const auto& [name, sha256] : record.files) files += name + " " + sha256 + "\n";
  Statement upsert(writer_,
                   "INSERT OR REPLACE INTO processing (capture_id, state, attempts, last_error,"
                   " replica, software_version, files, updated_wall_ns)"
                   " SELECT id, ?, ?, ?, ?, ?, ?, ? FROM captures WHERE id = ?");
  if (!upsert.prepared()) return DbError(writer_, upsert.prepare_rc(), what);
  upsert.Bind(1, static_cast<std::int64_t>(record.state));
  upsert.Bind(2, static_cast<std::int64_t>(record.attempts));
  upsert.Bind(3, record.last_error);
  upsert.Bind(4, record.replica);
  upsert.Bind(5, record.software_version);
  upsert.Bind(6, files);
  upsert.Bind(7, Nanos(record.updated));
  upsert.Bind(8, id.str());
  if (const int rc = upsert.Step(); rc != SQLITE_DONE) return DbError(writer_, rc, what);
  if (sqlite3_changes(writer_) == 0)
    return Status(ErrorCode::kNotFound, "no capture with id " + id.str());
  return {};
}

Result<std::optional<ProcessingRecord>> CaptureIndex::FindProcessing(const CaptureId& id) {
  std::lock_guard lock(read_mutex_);
  const std::string what = "looking up the processing of capture " + id.str() + " in " + path_;
  Statement select(reader_,
                   "SELECT state, attempts, last_error, replica, software_version, files,"
                   " updated_wall_ns FROM processing WHERE capture_id = ?");
  if (!select.prepared()) return DbError(reader_, select.prepare_rc(), what);
  select.Bind(1, id.str());
  const int rc = select.Step();
  if (rc == SQLITE_DONE) return std::optional<ProcessingRecord>();
  if (rc != SQLITE_ROW) return DbError(reader_, rc, what);
  ProcessingRecord record;
  record.state = static_cast<ProcessingState>(select.Int(0));
  record.attempts = static_cast<int>(select.Int(1));
  record.last_error = select.Text(2);
  record.replica = select.Text(3);
  record.software_version = select.Text(4);
  const std::string files = select.Text(5);
  for (size_t at = 0; at < files.size();) {
    const size_t end = files.find('\n', at);
    const std::string line = files.substr(at, end - at);
    const size_t space = line.find(' ');
    if (space != std::string::npos) record.files[line.substr(0, space)] = line.substr(space + 1);
    if (end == std::string::npos) break;
    at = end + 1;
  }
  record.updated = WallAt(select.Int(6));
  return std::optional<ProcessingRecord>(std::move(record));
}

Result<std::vector<CaptureId>> CaptureIndex::Unprocessed() {
  std::lock_guard lock(read_mutex_);
  const std::string what = "listing unprocessed captures in " + path_;
  Statement select(reader_,
                   "SELECT c.id FROM captures c LEFT JOIN processing p ON p.capture_id = c.id"
                   " WHERE p.state IS NULL OR p.state = 1 ORDER BY c.taken_wall_ns, c.id");
  if (!select.prepared()) return DbError(reader_, select.prepare_rc(), what);
  std::vector<CaptureId> ids;
  int rc;
  while ((rc = select.Step()) == SQLITE_ROW)
    if (auto id = CaptureId::Parse(select.Text(0))) ids.push_back(*id);
  if (rc != SQLITE_DONE) return DbError(reader_, rc, what);
  return ids;
}

}  // namespace bsls::store
