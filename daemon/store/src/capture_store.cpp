#include "bsls/store/capture_store.h"

#include <fcntl.h>
#include <sys/file.h>
#include <unistd.h>

#include <algorithm>
#include <cassert>
#include <cctype>
#include <cerrno>
#include <cstring>
#include <map>
#include <numeric>
#include <set>

#include "bsls/store/frame_file.h"
#include "bsls/store/sha256.h"

namespace bsls::store {

namespace {

constexpr mode_t kDirectoryMode = 0750;
// Index growth a Put may cause (WAL frames of two small rows and their
// B-tree pages), counted against the free-space reserve.
constexpr std::uint64_t kIndexBytesPerPut = 64 << 10;

Status WithContext(const Status& status, const std::string& context) {
  return Status(status.code(), context + ": " + status.message());
}

// A failed Put's status: what failed, then that nothing was acknowledged.
Status NotAcknowledged(const Status& status, const std::string& context) {
  return Status(status.code(), context + ": " + status.message() + "; not acknowledged");
}

std::string ParentOf(const std::string& path) {
  const auto slash = path.find_last_of('/');
  if (slash == std::string::npos) return ".";
  if (slash == 0) return "/";
  return path.substr(0, slash);
}

// mkdir that treats an existing directory as success; true when it created one.
Result<bool> EnsureDirectory(FileSystem& fs, const std::string& path) {
  Status status = fs.MakeDirectory(path, kDirectoryMode);
  if (status.ok()) return true;
  if (status.code() == ErrorCode::kAlreadyExists) return false;
  return status;
}

Result<CaptureId> ParseId(std::string_view text) {
  auto id = CaptureId::Parse(text);
  if (!id) {
    std::string shown(text.substr(0, 64));
    return Status(ErrorCode::kInvalidArgument,
                  "capture id \"" + shown + "\" is not 32 lower-case hex digits");
  }
  return *id;
}

std::string MiB(std::uint64_t bytes) {
  return std::to_string(bytes >> 20) + "." + std::to_string(((bytes & 0xFFFFF) * 10) >> 20) +
         " MiB";
}

}  // namespace

bool CaptureStoreOptions::IsValid(std::string* error) const {
  auto fail = [error](std::string message) {
    if (error) *error = std::move(message);
    return false;
  };
  if (root.empty()) return fail("root: the store needs a directory");
  if (root.front() != '/') return fail("root \"" + root + "\" is not an absolute path");
  if (retention.max_age && retention.max_age->count() <= 0) {
    return fail("retention max_age must be positive");
  }
  return true;
}

Result<std::unique_ptr<CaptureStore>> CaptureStore::Open(const CaptureStoreOptions& options) {
  std::string error;
  if (!options.IsValid(&error)) {
    return Status(ErrorCode::kInvalidArgument, "capture store options: " + error);
  }
  CaptureStoreOptions opts = options;
  while (opts.root.size() > 1 && opts.root.back() == '/') opts.root.pop_back();
  std::unique_ptr<FileSystem> owned_fs;
  FileSystem* fs = opts.file_system;
  if (fs == nullptr) {
    owned_fs = MakePosixFileSystem();
    fs = owned_fs.get();
  }
  const std::string context = "opening capture store " + opts.root;

  // The directories, each made durable in its parent when newly created.
  auto root_created = EnsureDirectory(*fs, opts.root);
  if (!root_created.ok()) return WithContext(root_created.status(), context);
  if (*root_created) {
    if (Status s = fs->FsyncDirectory(ParentOf(opts.root)); !s.ok()) return WithContext(s, context);
  }
  bool created_any = false;
  for (const std::string& dir : {opts.root + "/frames", opts.root + "/results"}) {
    auto created = EnsureDirectory(*fs, dir);
    if (!created.ok()) return WithContext(created.status(), context);
    created_any = created_any || *created;
  }
  if (created_any) {
    if (Status s = fs->FsyncDirectory(opts.root); !s.ok()) return WithContext(s, context);
  }

  // One process per store: a second daemon would remove the first one's
  // in-flight files as leftovers.
  const std::string lock_path = opts.root + "/LOCK";
  const int lock_fd = ::open(lock_path.c_str(), O_RDWR | O_CREAT | O_CLOEXEC, 0640);
  if (lock_fd < 0) return WithContext(ErrnoStatus(errno, "open", lock_path), context);
  if (::flock(lock_fd, LOCK_EX | LOCK_NB) != 0) {
    const int error_number = errno;
    ::close(lock_fd);
    if (error_number == EWOULDBLOCK) {
      return Status(ErrorCode::kFailedPrecondition,
                    context + ": another process (or another CaptureStore) has it open");
    }
    return WithContext(ErrnoStatus(error_number, "flock", lock_path), context);
  }

  std::unique_ptr<CaptureStore> store(new CaptureStore(opts, std::move(owned_fs), *fs, lock_fd));
  auto index = CaptureIndex::Open(opts.root + "/index.sqlite", opts.sqlite_vfs);
  if (!index.ok()) return WithContext(index.status(), context);
  store->index_ = std::move(*index);
  if (Status status = store->Recover(); !status.ok()) return WithContext(status, context);
  return store;
}

CaptureStore::CaptureStore(const CaptureStoreOptions& options, std::unique_ptr<FileSystem> owned_fs,
                           FileSystem& fs, int lock_fd)
    : options_(options),
      owned_fs_(std::move(owned_fs)),
      fs_(fs),
      lock_fd_(lock_fd),
      frames_dir_(options.root + "/frames"),
      results_dir_(options.root + "/results") {}

CaptureStore::~CaptureStore() {
  index_.reset();     // closes SQLite (checkpoints the WAL) before the lock goes
  ::close(lock_fd_);  // releases the flock
}

Status CaptureStore::Recover() {
  if (Status status = index_->CheckIntegrity(); !status.ok()) return status;

  auto names = fs_.ListDirectory(frames_dir_);
  if (!names.ok()) return names.status();
  std::set<std::string> present(names->begin(), names->end());

  // Every acknowledged capture: its files exist and (by default) verify.
  std::set<std::string> indexed_files;
  const Status walked = ForEachCapture([&](const CaptureInfo& info) {
    ++recovery_.captures_checked;
    Status capture_status;
    for (const StoredFrameInfo& frame : info.frames) {
      indexed_files.insert(frame.file_name);
      if (!capture_status.ok()) continue;
      if (options_.verify_hashes_on_open) {
        capture_status = VerifyFrame(info, frame, nullptr);
      } else if (!present.count(frame.file_name)) {
        capture_status = Status(ErrorCode::kDataLoss, "frame file " + frames_dir_ + "/" +
                                                          frame.file_name + " is missing");
      }
    }
    if (info.frames.empty()) {
      capture_status = Status(ErrorCode::kDataLoss, "the index has no frames for it");
    }
    if (!capture_status.ok()) {
      recovery_.problems.push_back(
          CaptureProblem{info.id.str(), WithContext(capture_status, "capture " + info.id.str())});
    }
  });
  if (!walked.ok()) return walked;

  // Leftovers of puts that were never acknowledged.
  bool removed_any = false;
  for (const std::string& name : *names) {
    const bool temp = name.rfind(kTempFilePrefix, 0) == 0;
    const bool orphan = !temp && ParseFrameFileName(name) && !indexed_files.count(name);
    if (!temp && !orphan) {
      if (!indexed_files.count(name)) recovery_.unknown_files.push_back(name);
      continue;
    }
    if (Status status = fs_.Unlink(frames_dir_ + "/" + name); !status.ok()) {
      return WithContext(status, "removing the leftover " + name);
    }
    removed_any = true;
    ++(temp ? recovery_.temp_files_removed : recovery_.orphan_files_removed);
  }
  if (removed_any) {
    if (Status status = fs_.FsyncDirectory(frames_dir_); !status.ok()) return status;
  }
  return RecoverResults();
}

// Result files of a capture whose record never said done (a crash between
// the files and the record), or of deleted captures, and temporary files.
Status CaptureStore::RecoverResults() {
  auto names = fs_.ListDirectory(results_dir_);
  if (!names.ok()) return names.status();
  std::map<std::string, std::set<std::string>> kept;  // capture id -> file names of its record
  bool removed_any = false;
  for (const std::string& name : *names) {
    bool keep = false;
    const auto dash = name.find('-');
    if (name.rfind(kTempFilePrefix, 0) != 0 && dash != std::string::npos) {
      const std::string id_text = name.substr(0, dash);
      if (!kept.count(id_text)) {
        kept[id_text];
        if (auto id = CaptureId::Parse(id_text)) {
          auto record = index_->FindProcessing(*id);
          if (!record.ok()) return record.status();
          if (*record && (*record)->state == ProcessingState::kDone)
            for (const auto& [file, sha256] : (*record)->files) kept[id_text].insert(file);
        }
      }
      keep = kept[id_text].count(name.substr(dash + 1)) > 0;
    }
    if (keep) continue;
    if (Status status = fs_.Unlink(results_dir_ + "/" + name); !status.ok())
      return WithContext(status, "removing the leftover result " + name);
    removed_any = true;
    ++recovery_.result_files_removed;
  }
  if (removed_any) return fs_.FsyncDirectory(results_dir_);
  return {};
}

Status CaptureStore::VerifyFrame(const CaptureInfo& info, const StoredFrameInfo& frame,
                                 framestore::GreyFrame* out) {
  const std::string path = frames_dir_ + "/" + frame.file_name;
  auto content = ReadFrameFile(fs_, path);
  if (!content.ok()) {
    if (content.status().code() == ErrorCode::kNotFound) {
      return Status(ErrorCode::kDataLoss, "frame file " + path + " is missing");
    }
    return content.status();
  }
  if (content->width != frame.width || content->height != frame.height) {
    return Status(ErrorCode::kDataLoss, path + " is " + std::to_string(content->width) + "x" +
                                            std::to_string(content->height) +
                                            ", the index recorded " + std::to_string(frame.width) +
                                            "x" + std::to_string(frame.height));
  }
  const Result<std::string> hashed = BytesSha256(std::string_view(
      reinterpret_cast<const char*>(content->pixels.data()), content->pixels.size()));
  if (!hashed.ok()) return WithContext(hashed.status(), path);
  const std::string& digest = *hashed;
  if (digest != frame.sha256) {
    return Status(ErrorCode::kDataLoss, path + " has SHA-256 " + digest + ", the index recorded " +
                                            frame.sha256 + " when capture " + info.id.str() +
                                            " was stored");
  }
  if (out != nullptr) {
    out->width = content->width;
    out->height = content->height;
    out->stride = content->width;
    out->pixels = std::move(content->pixels);
    out->camera = frame.camera;
    out->gain = frame.gain;
    out->sequence = frame.sequence;
    out->timestamps = frame.timestamps;
  }
  return {};
}

Result<StoreUsage> CaptureStore::Usage() {
  Result<IndexTotals> totals = index_->Totals();
  if (!totals.ok()) return totals.status();
  auto space = fs_.Statvfs(options_.root);
  if (!space.ok()) return WithContext(space.status(), "reading the free space of " + options_.root);
  StoreUsage usage;
  usage.captures = totals->captures;
  usage.total_bytes = totals->total_bytes;
  usage.free_bytes = space->available_bytes > options_.free_space_reserve_bytes
                         ? space->available_bytes - options_.free_space_reserve_bytes
                         : 0;
  return usage;
}

Status CaptureStore::CheckFreeSpace(const CaptureId& id, std::uint64_t bytes) {
  auto space = fs_.Statvfs(options_.root);
  if (!space.ok()) {
    return WithContext(space.status(),
                       "checking free space for capture " + id.str() + " (nothing was written)");
  }
  const std::uint64_t needed = bytes + kIndexBytesPerPut + options_.free_space_reserve_bytes;
  if (space->available_bytes < needed) {
    return Status(ErrorCode::kResourceExhausted,
                  "capture store " + options_.root + " has " + MiB(space->available_bytes) +
                      " free; capture " + id.str() + " needs " + MiB(bytes + kIndexBytesPerPut) +
                      " plus the reserve of " + MiB(options_.free_space_reserve_bytes) +
                      ": delete captures or apply retention; nothing was written");
  }
  return {};
}

Result<CaptureInfo> CaptureStore::Put(const CaptureRequest& request) {
  std::string error;
  if (!request.IsValid(&error)) {
    return Status(ErrorCode::kInvalidArgument, "capture request: " + error);
  }
  const auto now = std::chrono::system_clock::now();
  const CaptureId id = ids_.Next(now);
  const std::string context = "storing capture " + id.str();

  CaptureInfo info{id};
  info.session_id = request.session_id;
  info.patient_reference = request.patient_reference;
  info.side = request.side;
  info.slide = request.slide;
  info.software_version = request.software_version;
  info.requested_by = request.requested_by;
  info.stored_wall = now;

  // Frames in camera order; hashes and sizes before anything touches the disk.
  std::vector<const framestore::GreyFrame*> frames;
  for (const auto& frame : request.frames) frames.push_back(&frame);
  std::sort(frames.begin(), frames.end(), [](auto* a, auto* b) { return a->camera < b->camera; });
  info.taken_wall = frames.front()->timestamps.wall;
  for (const framestore::GreyFrame* frame : frames) {
    StoredFrameInfo stored;
    stored.camera = frame->camera;
    stored.gain = frame->gain;
    stored.sequence = frame->sequence;
    stored.width = frame->width;
    stored.height = frame->height;
    stored.timestamps = frame->timestamps;
    Result<std::string> sha256 = PixelSha256(*frame);
    if (!sha256.ok()) return WithContext(sha256.status(), context);
    stored.sha256 = std::move(sha256).value();
    stored.file_name = FrameFileName(id, frame->camera);
    stored.file_bytes = FrameFileBytes(id, frame->camera, frame->width, frame->height);
    info.total_bytes += stored.file_bytes;
    info.taken_wall = std::min(info.taken_wall, frame->timestamps.wall);
    info.frames.push_back(std::move(stored));
  }

  if (Status status = CheckFreeSpace(id, info.total_bytes); !status.ok()) return status;

  {
    std::lock_guard lock(mutex_);
    in_flight_.insert(id.str());
  }
  struct InFlight {
    CaptureStore* store;
    std::string id;
    ~InFlight() {
      std::lock_guard lock(store->mutex_);
      store->in_flight_.erase(id);
    }
  } in_flight{this, id.str()};

  // 1. Each frame file: temporary name, write, fsync, rename (frame_file.h).
  std::vector<std::string> published;
  auto remove_published = [&] {
    for (const std::string& name : published) fs_.Unlink(frames_dir_ + "/" + name);
  };
  for (std::size_t i = 0; i < frames.size(); ++i) {
    auto written = WriteFrameFile(fs_, frames_dir_, info.frames[i].file_name, id, *frames[i]);
    if (!written.ok()) {
      remove_published();
      return NotAcknowledged(written.status(),
                             context + ", " + framestore::ToString(frames[i]->camera) + " frame");
    }
    assert(*written == info.frames[i].file_bytes);
    published.push_back(info.frames[i].file_name);
  }
  // 2. The renames themselves: the directory entries must be durable before
  //    an index row may point at them.
  if (Status status = fs_.FsyncDirectory(frames_dir_); !status.ok()) {
    remove_published();
    return NotAcknowledged(status, context + ", fsync of the frames directory");
  }
  // 3. The index rows, committed with the WAL synced. If the commit fails the
  //    files stay: SQLite may still replay the commit from its WAL at the next
  //    open and then its rows need them; if it does not, recovery removes them.
  if (Status status = index_->Insert(info); !status.ok()) {
    return NotAcknowledged(status, context);
  }
  return info;
}

Result<Capture> CaptureStore::Get(std::string_view text) {
  auto id = ParseId(text);
  if (!id.ok()) return id.status();
  const std::string key = id->str();
  {
    std::lock_guard lock(mutex_);
    if (deleting_.count(key)) {
      return Status(ErrorCode::kNotFound, "capture " + key + " is being deleted");
    }
    ++readers_[key];
  }
  struct Reader {
    CaptureStore* store;
    std::string id;
    ~Reader() {
      std::lock_guard lock(store->mutex_);
      if (--store->readers_[id] == 0) store->readers_.erase(id);
      store->readers_done_.notify_all();
    }
  } reader{this, key};

  auto info = index_->Find(*id);
  if (!info.ok()) return info.status();
  Capture capture{*info, {}};
  for (const StoredFrameInfo& frame : info->frames) {
    framestore::GreyFrame grey;
    if (Status status = VerifyFrame(*info, frame, &grey); !status.ok()) {
      return WithContext(status, "reading capture " + key);
    }
    capture.frames.push_back(std::move(grey));
  }
  return capture;
}

Result<CapturePage> CaptureStore::List(const CaptureFilter& filter) { return index_->List(filter); }

Status CaptureStore::RemoveCapture(const CaptureInfo& info) {
  auto record = index_->FindProcessing(info.id);
  if (!record.ok()) return record.status();
  // Row first: a crash after this commit leaves files without a row, which
  // recovery removes; the other order could leave a row without its files.
  if (Status status = index_->Remove(info.id); !status.ok()) return status;
  for (const StoredFrameInfo& frame : info.frames) {
    // A failure here leaves an unindexed file that the next Open removes.
    fs_.Unlink(frames_dir_ + "/" + frame.file_name);
  }
  fs_.FsyncDirectory(frames_dir_);
  if (*record) {
    for (const auto& [name, sha256] : (*record)->files)
      fs_.Unlink(results_dir_ + "/" + info.id.str() + "-" + name);
    fs_.FsyncDirectory(results_dir_);
  }
  return {};
}

Result<std::vector<CaptureId>> CaptureStore::Unprocessed() { return index_->Unprocessed(); }

Result<std::optional<ProcessingRecord>> CaptureStore::Processing(std::string_view text) {
  auto id = ParseId(text);
  if (!id.ok()) return id.status();
  return index_->FindProcessing(*id);
}

Status CaptureStore::NoteProcessingAttempt(std::string_view text, const std::string& error) {
  auto id = ParseId(text);
  if (!id.ok()) return id.status();
  auto old = index_->FindProcessing(*id);
  if (!old.ok()) return old.status();
  ProcessingRecord record;
  record.attempts = (*old ? (*old)->attempts : 0) + 1;
  record.last_error = error;
  record.updated = std::chrono::system_clock::now();
  return index_->PutProcessing(*id, record);
}

Status CaptureStore::PutProcessingFailure(std::string_view text, const std::string& error) {
  auto id = ParseId(text);
  if (!id.ok()) return id.status();
  auto old = index_->FindProcessing(*id);
  if (!old.ok()) return old.status();
  ProcessingRecord record;
  record.state = ProcessingState::kFailed;
  record.attempts = (*old ? (*old)->attempts : 0) + 1;
  record.last_error = error;
  record.updated = std::chrono::system_clock::now();
  return index_->PutProcessing(*id, record);
}

namespace {

bool IsResultFileName(std::string_view name) {
  if (name.empty() || name.size() > 64 || name.front() == '.') return false;
  return std::all_of(name.begin(), name.end(), [](char c) {
    return std::isalnum(static_cast<unsigned char>(c)) || c == '.' || c == '_' || c == '-';
  });
}

}  // namespace

Status CaptureStore::PutProcessingResult(std::string_view text,
                                         const std::map<std::string, std::string>& files,
                                         const ProcessingProvenance& provenance) {
  auto id = ParseId(text);
  if (!id.ok()) return id.status();
  const std::string context = "storing the results of capture " + id->str();
  ProcessingRecord record;
  record.state = ProcessingState::kDone;
  record.replica = provenance.replica;
  record.software_version = provenance.processing_software_version;
  record.updated = std::chrono::system_clock::now();
  std::uint64_t bytes = 0;
  for (const auto& [name, content] : files) {
    if (!IsResultFileName(name) || name == kRecordFileName)
      return Status(ErrorCode::kInvalidArgument,
                    context + ": \"" + name.substr(0, 64) + "\" is not a result file name");
    bytes += content.size();
  }
  Result<CaptureInfo> capture = index_->Find(*id);
  if (!capture.ok()) return WithContext(capture.status(), context);
  bytes += 64 * 1024;  // the record, at most
  if (Status status = CheckFreeSpace(*id, bytes); !status.ok()) return WithContext(status, context);
  {
    std::lock_guard lock(mutex_);
    if (deleting_.count(id->str()))
      return Status(ErrorCode::kNotFound, context + ": the capture is being deleted");
  }
  // Files first (each durable under its final name), then the record that
  // makes them part of the capture: a crash in between leaves files that
  // recovery removes and a capture that is processed again.
  for (const auto& [name, content] : files) {
    const std::string file = id->str() + "-" + name;
    if (Status status = WriteFileDurably(fs_, results_dir_, file, {content}, kFileMode);
        !status.ok())
      return WithContext(status, context);
    Result<std::string> sha256 = BytesSha256(content);
    if (!sha256.ok()) return WithContext(sha256.status(), context);
    record.files[name] = std::move(sha256).value();
  }
  // The sealed record, last: it lists every file above by its hash.
  const std::string sealed = ProvenanceRecord(*capture, provenance, record.files);
  if (Status status = WriteFileDurably(fs_, results_dir_, id->str() + "-" + kRecordFileName,
                                       {sealed}, kFileMode);
      !status.ok())
    return WithContext(status, context);
  Result<std::string> sealed_sha256 = BytesSha256(sealed);
  if (!sealed_sha256.ok()) return WithContext(sealed_sha256.status(), context);
  record.files[kRecordFileName] = std::move(sealed_sha256).value();
  if (Status status = fs_.FsyncDirectory(results_dir_); !status.ok())
    return WithContext(status, context);
  if (Status status = index_->PutProcessing(*id, record); !status.ok())
    return WithContext(status, context);
  return {};
}

Result<std::map<std::string, std::string>> CaptureStore::ReadProcessingFiles(
    std::string_view text, const std::string& only) {
  auto id = ParseId(text);
  if (!id.ok()) return id.status();
  auto record = index_->FindProcessing(*id);
  if (!record.ok()) return record.status();
  if (!*record || (*record)->state != ProcessingState::kDone)
    return Status(ErrorCode::kNotFound, "capture " + id->str() + " has no stored results (yet)");
  std::map<std::string, std::string> out;
  for (const auto& [name, sha256] : (*record)->files) {
    if (!only.empty() && name != only) continue;
    const std::string path = results_dir_ + "/" + id->str() + "-" + name;
    auto content = ReadWholeFile(fs_, path, std::uint64_t{1} << 32);
    if (!content.ok()) {
      if (content.status().code() == ErrorCode::kNotFound)
        return Status(ErrorCode::kDataLoss, "result file " + path + " is missing");
      return content.status();
    }
    const Result<std::string> hashed = BytesSha256(*content);
    if (!hashed.ok()) return WithContext(hashed.status(), path);
    if (*hashed != sha256)
      return Status(ErrorCode::kDataLoss, "result file " + path + " does not match its SHA-256");
    out[name] = std::move(*content);
  }
  if (!only.empty() && out.empty())
    return Status(ErrorCode::kNotFound,
                  "capture " + id->str() + " has no result \"" + only.substr(0, 64) + "\"");
  return out;
}

Status CaptureStore::Delete(std::string_view text) {
  auto id = ParseId(text);
  if (!id.ok()) return id.status();
  const std::string key = id->str();
  auto info = index_->Find(*id);
  if (!info.ok()) return info.status();
  {
    std::unique_lock lock(mutex_);
    if (!deleting_.insert(key).second) {
      return Status(ErrorCode::kNotFound, "capture " + key + " is being deleted");
    }
    readers_done_.wait(lock, [&] { return readers_.count(key) == 0; });
  }
  Status status = RemoveCapture(*info);
  {
    std::lock_guard lock(mutex_);
    deleting_.erase(key);
  }
  if (!status.ok()) return WithContext(status, "deleting capture " + key);
  return {};
}

Result<RetentionReport> CaptureStore::ApplyRetention(std::chrono::system_clock::time_point now) {
  RetentionReport report;
  const RetentionPolicy& policy = options_.retention;
  if (!policy.max_age && !policy.max_total_bytes) return report;
  auto candidates = index_->OldestFirst();
  if (!candidates.ok()) return WithContext(candidates.status(), "applying retention");
  std::uint64_t total = 0;
  for (const auto& candidate : *candidates) total += candidate.total_bytes;
  for (const RetentionCandidate& candidate : *candidates) {
    const bool too_old = policy.max_age && candidate.taken_wall < now - *policy.max_age;
    const bool over_budget = policy.max_total_bytes && total > *policy.max_total_bytes;
    if (!too_old && !over_budget) break;  // oldest first: the rest are younger
    const std::string key = candidate.id.str();
    {
      std::lock_guard lock(mutex_);
      if (readers_.count(key) || in_flight_.count(key) || deleting_.count(key)) {
        ++report.skipped_busy;
        continue;
      }
      deleting_.insert(key);
    }
    Status status;
    auto info = index_->Find(candidate.id);
    if (info.ok()) {
      status = RemoveCapture(*info);
    } else if (info.status().code() != ErrorCode::kNotFound) {
      status = info.status();
    }
    {
      std::lock_guard lock(mutex_);
      deleting_.erase(key);
    }
    if (!status.ok()) {
      return WithContext(status, "applying retention after deleting " +
                                     std::to_string(report.deleted.size()) + " captures");
    }
    if (info.ok()) {
      report.deleted.push_back(candidate.id);
      report.bytes_freed += candidate.total_bytes;
    }
    total -= candidate.total_bytes;
  }
  return report;
}

Result<std::vector<CaptureProblem>> CaptureStore::VerifyAll() {
  std::vector<CaptureProblem> problems;
  const Status walked = ForEachCapture([&](const CaptureInfo& info) {
    for (const StoredFrameInfo& frame : info.frames) {
      if (Status status = VerifyFrame(info, frame, nullptr); !status.ok()) {
        // A capture deleted since the page was read is not a problem.
        if (!index_->Find(info.id).ok()) break;
        problems.push_back(
            CaptureProblem{info.id.str(), WithContext(status, "capture " + info.id.str())});
        break;
      }
    }
  });
  if (!walked.ok()) return walked;
  return problems;
}

Status CaptureStore::ForEachCapture(const std::function<void(const CaptureInfo&)>& visit) {
  CaptureFilter all;
  all.page_size = kMaxPageSize;
  while (true) {
    auto page = index_->List(all);
    if (!page.ok()) return page.status();
    for (const CaptureInfo& info : page->captures) visit(info);
    if (page->next_page_token.empty()) return {};
    all.page_token = page->next_page_token;
  }
}

Status CaptureStore::CheckIndexIntegrity() { return index_->CheckIntegrity(); }

}  // namespace bsls::store
