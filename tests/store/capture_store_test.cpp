// The capture store's behaviour on a healthy disk: byte-exact round trips
// with hashes, listing with filters and paging, deletion, retention by size
// and age, recovery of leftovers, corruption detected on open and on get, the
// free-space reserve, bad input, and concurrent clients.
#include "bsls/store/capture_store.h"

#include <gtest/gtest.h>

#include <atomic>
#include <condition_variable>
#include <fstream>
#include <thread>

#include "bsls/store/frame_file.h"
#include "bsls/store/sha256.h"
#include "store_test_util.h"

namespace bsls::store {
namespace {

using framestore::Camera;
using testing::OpenStore;
using testing::RandomFrame;
using testing::RandomRequest;
using testing::TempDir;
using testing::TestOptions;

void FlipByte(const std::string& path, std::uintmax_t offset_from_end) {
  std::fstream file(path, std::ios::in | std::ios::out | std::ios::binary);
  ASSERT_TRUE(file) << path;
  file.seekg(0, std::ios::end);
  const auto size = static_cast<std::streamoff>(file.tellg());
  const std::streamoff at = size - static_cast<std::streamoff>(offset_from_end);
  file.seekg(at);
  char byte = 0;
  file.read(&byte, 1);
  byte = static_cast<char>(byte ^ 0x01);
  file.seekp(at);
  file.write(&byte, 1);
}

TEST(CaptureStoreTest, PutGetRoundTripIsByteExactWithHashes) {
  TempDir dir;
  auto store = OpenStore(TestOptions(dir.path() + "/store"));
  ASSERT_TRUE(store);
  std::mt19937 rng(1);
  CaptureRequest request = RandomRequest(rng);
  // Padding must not reach the file or the hash: right frame with stride 80.
  request.frames[1] = RandomFrame(rng, Camera::kRight, 64, 48, 80);
  auto put = store->Put(request);
  ASSERT_TRUE(put.ok()) << put.status().ToString();
  EXPECT_TRUE(CaptureId::Parse(put->id.str()));
  ASSERT_EQ(put->frames.size(), 2u);
  EXPECT_EQ(put->frames[0].sha256, PixelSha256(request.frames[0]).value());
  EXPECT_EQ(put->frames[1].sha256, PixelSha256(request.frames[1]).value());

  auto got = store->Get(put->id.str());
  ASSERT_TRUE(got.ok()) << got.status().ToString();
  ASSERT_EQ(got->frames.size(), 2u);
  // Packed frame: the very same bytes.
  EXPECT_EQ(got->frames[0].pixels, request.frames[0].pixels);
  EXPECT_EQ(got->frames[0].stride, 64);
  // Padded frame: every pixel equal, padding dropped.
  const auto& padded = request.frames[1];
  const auto& back = got->frames[1];
  ASSERT_EQ(back.width, padded.width);
  ASSERT_EQ(back.height, padded.height);
  EXPECT_EQ(back.stride, back.width);
  int differing = 0;
  for (int y = 0; y < back.height; ++y) {
    for (int x = 0; x < back.width; ++x) differing += back.at(x, y) != padded.at(x, y);
  }
  EXPECT_EQ(differing, 0);
  EXPECT_EQ(PixelSha256(back).value(), got->info.frames[1].sha256);

  // Metadata survives exactly.
  const CaptureInfo& info = got->info;
  EXPECT_EQ(info.id, put->id);
  EXPECT_EQ(info.session_id, "s1");
  EXPECT_EQ(info.patient_reference, "p1");
  EXPECT_EQ(info.side, Side::kBoth);
  EXPECT_EQ(info.slide, 2);
  EXPECT_EQ(info.software_version, "bsls 0.1.0-test");
  EXPECT_EQ(info.requested_by.uid, 1000);
  EXPECT_EQ(info.requested_by.name, "operator");
  EXPECT_EQ(info.frames[0].camera, Camera::kLeft);
  EXPECT_EQ(info.frames[1].camera, Camera::kRight);
  EXPECT_EQ(info.frames[0].gain, request.frames[0].gain);
  EXPECT_EQ(info.frames[0].sequence, request.frames[0].sequence);
  EXPECT_EQ(info.frames[0].timestamps.requested, request.frames[0].timestamps.requested);
  EXPECT_EQ(info.frames[0].timestamps.exposed, request.frames[0].timestamps.exposed);
  EXPECT_EQ(info.frames[0].timestamps.delivered, request.frames[0].timestamps.delivered);
  EXPECT_EQ(info.frames[0].timestamps.wall, request.frames[0].timestamps.wall);
  EXPECT_EQ(got->frames[1].camera, Camera::kRight);
  EXPECT_EQ(got->frames[1].timestamps.exposed, padded.timestamps.exposed);
  EXPECT_EQ(info.total_bytes, info.frames[0].file_bytes + info.frames[1].file_bytes);

  // The file is a PGM whose pixel block hashes to the recorded digest.
  auto content = ReadFrameFile(*MakePosixFileSystem(),
                               dir.path() + "/store/frames/" + info.frames[0].file_name);
  ASSERT_TRUE(content.ok()) << content.status().ToString();
  EXPECT_EQ(BytesSha256(std::string_view(reinterpret_cast<const char*>(content->pixels.data()),
                                         content->pixels.size()))
                .value(),
            info.frames[0].sha256);
}

TEST(CaptureStoreTest, SurvivesReopenAndChecksIntegrity) {
  TempDir dir;
  std::mt19937 rng(2);
  std::vector<std::string> ids;
  {
    auto store = OpenStore(TestOptions(dir.path()));
    ASSERT_TRUE(store);
    for (int i = 0; i < 5; ++i) {
      auto put = store->Put(RandomRequest(rng));
      ASSERT_TRUE(put.ok()) << put.status().ToString();
      ids.push_back(put->id.str());
    }
    // A second opener of the same root is refused while the first is open.
    auto second = CaptureStore::Open(TestOptions(dir.path()));
    EXPECT_EQ(second.status().code(), ErrorCode::kFailedPrecondition);
  }
  auto store = OpenStore(TestOptions(dir.path()));
  ASSERT_TRUE(store);
  EXPECT_TRUE(store->recovery_report().ok());
  EXPECT_EQ(store->recovery_report().captures_checked, 5);
  EXPECT_TRUE(store->CheckIndexIntegrity().ok());
  for (const auto& id : ids) EXPECT_TRUE(store->Get(id).ok()) << id;
}

TEST(CaptureStoreTest, ListFiltersAndPages) {
  TempDir dir;
  auto store = OpenStore(TestOptions(dir.path()));
  ASSERT_TRUE(store);
  std::mt19937 rng(3);
  const auto t0 = std::chrono::system_clock::now() - std::chrono::hours(10);
  std::vector<std::string> ids;
  for (int i = 0; i < 12; ++i) {
    CaptureRequest request =
        RandomRequest(rng, i % 3 == 0 ? "session-a" : "session-b", i < 6 ? "p-1" : "p-2", 8, 8);
    for (auto& frame : request.frames) frame.timestamps.wall = t0 + std::chrono::minutes(i);
    auto put = store->Put(request);
    ASSERT_TRUE(put.ok()) << put.status().ToString();
    ids.push_back(put->id.str());
  }
  // Paging: 12 captures in pages of 5, in time order, each exactly once.
  CaptureFilter filter;
  filter.page_size = 5;
  std::vector<std::string> listed;
  int pages = 0;
  while (true) {
    auto page = store->List(filter);
    ASSERT_TRUE(page.ok()) << page.status().ToString();
    ++pages;
    for (const auto& info : page->captures) {
      listed.push_back(info.id.str());
      EXPECT_EQ(info.frames.size(), 2u);
    }
    if (page->next_page_token.empty()) break;
    filter.page_token = page->next_page_token;
  }
  EXPECT_EQ(pages, 3);
  EXPECT_EQ(listed, ids);

  CaptureFilter session;
  session.session_id = "session-a";
  auto by_session = store->List(session);
  ASSERT_TRUE(by_session.ok());
  EXPECT_EQ(by_session->captures.size(), 4u);

  CaptureFilter patient;
  patient.patient_reference = "p-2";
  patient.session_id = "session-b";
  auto by_patient = store->List(patient);
  ASSERT_TRUE(by_patient.ok());
  EXPECT_EQ(by_patient->captures.size(), 4u);  // i = 7, 8, 10, 11

  CaptureFilter range;
  range.taken_from = t0 + std::chrono::minutes(3);
  range.taken_before = t0 + std::chrono::minutes(7);
  auto by_time = store->List(range);
  ASSERT_TRUE(by_time.ok());
  ASSERT_EQ(by_time->captures.size(), 4u);
  EXPECT_EQ(by_time->captures.front().id.str(), ids[3]);

  CaptureFilter bad;
  bad.page_size = kMaxPageSize + 1;
  EXPECT_EQ(store->List(bad).status().code(), ErrorCode::kInvalidArgument);
  bad.page_size = 0;
  bad.page_token = "not-a-token";
  EXPECT_EQ(store->List(bad).status().code(), ErrorCode::kInvalidArgument);
  // A huge token is quoted in part: the message must fit a reply's metadata.
  bad.page_token = std::string(60000, 'x');
  const auto huge = store->List(bad);
  EXPECT_EQ(huge.status().code(), ErrorCode::kInvalidArgument);
  EXPECT_LT(huge.status().message().size(), 200u) << huge.status().message().substr(0, 200);
  EXPECT_NE(huge.status().message().find("60000 bytes"), std::string::npos);
}

TEST(CaptureStoreTest, DeleteRemovesRowAndFiles) {
  TempDir dir;
  auto store = OpenStore(TestOptions(dir.path()));
  ASSERT_TRUE(store);
  std::mt19937 rng(4);
  auto keep = store->Put(RandomRequest(rng));
  auto gone = store->Put(RandomRequest(rng));
  ASSERT_TRUE(keep.ok() && gone.ok());
  ASSERT_TRUE(store->Delete(gone->id.str()).ok());
  EXPECT_EQ(store->Get(gone->id.str()).status().code(), ErrorCode::kNotFound);
  EXPECT_EQ(store->Delete(gone->id.str()).code(), ErrorCode::kNotFound);
  for (const auto& frame : gone->frames) {
    EXPECT_FALSE(std::filesystem::exists(dir.path() + "/frames/" + frame.file_name));
  }
  EXPECT_TRUE(store->Get(keep->id.str()).ok());
  auto page = store->List({});
  ASSERT_TRUE(page.ok());
  EXPECT_EQ(page->captures.size(), 1u);
}

TEST(CaptureStoreTest, RetentionBySizeDeletesOldestFirst) {
  TempDir dir;
  CaptureStoreOptions options = TestOptions(dir.path());
  std::mt19937 rng(5);
  auto probe = RandomRequest(rng);
  const std::uint64_t one =
      FrameFileBytes(*CaptureId::Parse(std::string(32, '0')), Camera::kLeft, 64, 48) +
      FrameFileBytes(*CaptureId::Parse(std::string(32, '0')), Camera::kRight, 64, 48);
  options.retention.max_total_bytes = 3 * one;
  auto store = OpenStore(options);
  ASSERT_TRUE(store);
  const auto t0 = std::chrono::system_clock::now() - std::chrono::hours(1);
  std::vector<std::string> ids;
  for (int i = 0; i < 5; ++i) {
    auto request = RandomRequest(rng);
    for (auto& frame : request.frames) frame.timestamps.wall = t0 + std::chrono::seconds(i);
    auto put = store->Put(request);
    ASSERT_TRUE(put.ok());
    ASSERT_EQ(put->total_bytes, one);
    ids.push_back(put->id.str());
  }
  auto report = store->ApplyRetention(std::chrono::system_clock::now());
  ASSERT_TRUE(report.ok()) << report.status().ToString();
  ASSERT_EQ(report->deleted.size(), 2u);
  EXPECT_EQ(report->deleted[0].str(), ids[0]);
  EXPECT_EQ(report->deleted[1].str(), ids[1]);
  EXPECT_EQ(report->bytes_freed, 2 * one);
  EXPECT_EQ(store->Get(ids[0]).status().code(), ErrorCode::kNotFound);
  EXPECT_TRUE(store->Get(ids[2]).ok());
  // Within budget now: a second pass deletes nothing.
  report = store->ApplyRetention(std::chrono::system_clock::now());
  ASSERT_TRUE(report.ok());
  EXPECT_TRUE(report->deleted.empty());
}

TEST(CaptureStoreTest, RetentionByAge) {
  TempDir dir;
  CaptureStoreOptions options = TestOptions(dir.path());
  options.retention.max_age = std::chrono::hours(24 * 30);
  auto store = OpenStore(options);
  ASSERT_TRUE(store);
  std::mt19937 rng(6);
  const auto now = std::chrono::system_clock::now();
  std::vector<std::string> ids;
  for (int days : {90, 40, 10, 0}) {
    auto request = RandomRequest(rng);
    for (auto& frame : request.frames) frame.timestamps.wall = now - std::chrono::hours(24 * days);
    auto put = store->Put(request);
    ASSERT_TRUE(put.ok());
    ids.push_back(put->id.str());
  }
  auto report = store->ApplyRetention(now);
  ASSERT_TRUE(report.ok()) << report.status().ToString();
  ASSERT_EQ(report->deleted.size(), 2u);
  EXPECT_EQ(report->deleted[0].str(), ids[0]);
  EXPECT_EQ(report->deleted[1].str(), ids[1]);
  EXPECT_TRUE(store->Get(ids[2]).ok());
  EXPECT_TRUE(store->Get(ids[3]).ok());
}

// A POSIX filesystem whose reads of one file name block until released.
class BlockingReads final : public FileSystem {
 public:
  explicit BlockingReads(std::string blocked_name) : blocked_(std::move(blocked_name)) {}
  void Release() {
    std::lock_guard lock(mutex_);
    released_ = true;
    changed_.notify_all();
  }
  void WaitUntilBlocked() {
    std::unique_lock lock(mutex_);
    changed_.wait(lock, [&] { return blocking_; });
  }
  Result<int> Open(const std::string& path, int flags, mode_t mode) override {
    if (path.size() >= blocked_.size() &&
        path.compare(path.size() - blocked_.size(), blocked_.size(), blocked_) == 0) {
      std::unique_lock lock(mutex_);
      blocking_ = true;
      changed_.notify_all();
      changed_.wait(lock, [&] { return released_; });
    }
    return posix_->Open(path, flags, mode);
  }
  Result<std::size_t> Write(int fd, const void* data, std::size_t size) override {
    return posix_->Write(fd, data, size);
  }
  Result<std::size_t> Read(int fd, void* data, std::size_t size) override {
    return posix_->Read(fd, data, size);
  }
  Status Fsync(int fd) override { return posix_->Fsync(fd); }
  Status Close(int fd) override { return posix_->Close(fd); }
  Status Rename(const std::string& from, const std::string& to) override {
    return posix_->Rename(from, to);
  }
  Status Unlink(const std::string& path) override { return posix_->Unlink(path); }
  Status MakeDirectory(const std::string& path, mode_t mode) override {
    return posix_->MakeDirectory(path, mode);
  }
  Status FsyncDirectory(const std::string& path) override { return posix_->FsyncDirectory(path); }
  Result<SpaceInfo> Statvfs(const std::string& path) override { return posix_->Statvfs(path); }
  Result<std::vector<std::string>> ListDirectory(const std::string& path) override {
    return posix_->ListDirectory(path);
  }

 private:
  std::unique_ptr<FileSystem> posix_ = MakePosixFileSystem();
  std::string blocked_;
  std::mutex mutex_;
  std::condition_variable changed_;
  bool blocking_ = false;
  bool released_ = false;
};

TEST(CaptureStoreTest, RetentionNeverDeletesACaptureBeingRead) {
  TempDir dir;
  std::mt19937 rng(15);
  std::string oldest;
  std::string oldest_file;
  {
    auto store = OpenStore(TestOptions(dir.path()));
    ASSERT_TRUE(store);
    const auto long_ago = std::chrono::system_clock::now() - std::chrono::hours(24 * 400);
    for (int i = 0; i < 3; ++i) {
      auto request = RandomRequest(rng);
      for (auto& frame : request.frames) frame.timestamps.wall = long_ago + std::chrono::hours(i);
      auto put = store->Put(request);
      ASSERT_TRUE(put.ok());
      if (i == 0) {
        oldest = put->id.str();
        oldest_file = put->frames[0].file_name;
      }
    }
  }
  BlockingReads fs("/" + oldest_file);
  CaptureStoreOptions options = TestOptions(dir.path());
  options.file_system = &fs;
  options.verify_hashes_on_open = false;  // Open itself must not block on the file
  options.retention.max_age = std::chrono::hours(24);
  auto store = OpenStore(options);
  ASSERT_TRUE(store);
  Result<Capture> read = Status(ErrorCode::kInternal, "not read");
  std::thread reader([&] { read = store->Get(oldest); });
  fs.WaitUntilBlocked();
  auto report = store->ApplyRetention(std::chrono::system_clock::now());
  ASSERT_TRUE(report.ok()) << report.status().ToString();
  EXPECT_EQ(report->deleted.size(), 2u);
  EXPECT_EQ(report->skipped_busy, 1);
  fs.Release();
  reader.join();
  ASSERT_TRUE(read.ok()) << read.status().ToString();
  // Once the read is over, the next pass deletes it.
  report = store->ApplyRetention(std::chrono::system_clock::now());
  ASSERT_TRUE(report.ok());
  ASSERT_EQ(report->deleted.size(), 1u);
  EXPECT_EQ(report->deleted[0].str(), oldest);
}

TEST(CaptureStoreTest, RecoveryRemovesLeftoversAndKeepsForeignFiles) {
  TempDir dir;
  std::mt19937 rng(7);
  std::string kept;
  {
    auto store = OpenStore(TestOptions(dir.path()));
    ASSERT_TRUE(store);
    auto put = store->Put(RandomRequest(rng));
    ASSERT_TRUE(put.ok());
    kept = put->id.str();
  }
  const std::string frames = dir.path() + "/frames/";
  std::ofstream(frames + ".tmp-0123456789abcdef0123456789abcdef-left.pgm") << "half";
  std::ofstream(frames + "0123456789abcdef0123456789abcdef-right.pgm") << "P5\n1 1\n255\nx";
  std::ofstream(frames + "notes.txt") << "someone's file";
  auto store = OpenStore(TestOptions(dir.path()));
  ASSERT_TRUE(store);
  const RecoveryReport& report = store->recovery_report();
  EXPECT_TRUE(report.ok());
  EXPECT_EQ(report.temp_files_removed, 1);
  EXPECT_EQ(report.orphan_files_removed, 1);
  ASSERT_EQ(report.unknown_files.size(), 1u);
  EXPECT_EQ(report.unknown_files[0], "notes.txt");
  EXPECT_TRUE(std::filesystem::exists(frames + "notes.txt"));
  EXPECT_FALSE(std::filesystem::exists(frames + "0123456789abcdef0123456789abcdef-right.pgm"));
  EXPECT_TRUE(store->Get(kept).ok());
}

TEST(CaptureStoreTest, CorruptFileIsReportedOnOpenAndOnGet) {
  TempDir dir;
  std::mt19937 rng(8);
  CaptureInfo corrupt{*CaptureId::Parse(std::string(32, '0'))};
  CaptureInfo missing = corrupt;
  CaptureInfo intact = corrupt;
  {
    auto store = OpenStore(TestOptions(dir.path()));
    ASSERT_TRUE(store);
    corrupt = *store->Put(RandomRequest(rng));
    missing = *store->Put(RandomRequest(rng));
    intact = *store->Put(RandomRequest(rng));
    // Found on get while the store is open.
    FlipByte(dir.path() + "/frames/" + corrupt.frames[1].file_name, 100);
    auto got = store->Get(corrupt.id.str());
    EXPECT_EQ(got.status().code(), ErrorCode::kDataLoss);
    EXPECT_NE(got.status().message().find("SHA-256"), std::string::npos) << got.status().message();
    auto verify = store->VerifyAll();
    ASSERT_TRUE(verify.ok());
    EXPECT_EQ(verify->size(), 1u);
  }
  std::filesystem::remove(dir.path() + "/frames/" + missing.frames[0].file_name);
  auto store = OpenStore(TestOptions(dir.path()));
  ASSERT_TRUE(store);
  const RecoveryReport& report = store->recovery_report();
  ASSERT_EQ(report.problems.size(), 2u);
  std::set<std::string> bad;
  for (const auto& problem : report.problems) {
    bad.insert(problem.id);
    EXPECT_EQ(problem.status.code(), ErrorCode::kDataLoss) << problem.status.ToString();
  }
  EXPECT_TRUE(bad.count(corrupt.id.str()));
  EXPECT_TRUE(bad.count(missing.id.str()));
  // Reported, never dropped: both stay listed, Get says why they are unusable.
  auto page = store->List({});
  ASSERT_TRUE(page.ok());
  EXPECT_EQ(page->captures.size(), 3u);
  EXPECT_EQ(store->Get(missing.id.str()).status().code(), ErrorCode::kDataLoss);
  EXPECT_EQ(store->Get(corrupt.id.str()).status().code(), ErrorCode::kDataLoss);
  EXPECT_TRUE(store->Get(intact.id.str()).ok());
  // A flipped header byte (the comment mark) is caught as well.
  FlipByte(dir.path() + "/frames/" + intact.frames[0].file_name, intact.frames[0].file_bytes - 3);
  EXPECT_EQ(store->Get(intact.id.str()).status().code(), ErrorCode::kDataLoss);
}

TEST(CaptureStoreTest, FreeSpaceReserveRefusesBeforeWriting) {
  TempDir dir;
  CaptureStoreOptions options = TestOptions(dir.path());
  options.free_space_reserve_bytes = std::uint64_t{1} << 62;  // more than any disk
  auto store = OpenStore(options);
  ASSERT_TRUE(store);
  std::mt19937 rng(9);
  auto put = store->Put(RandomRequest(rng));
  ASSERT_EQ(put.status().code(), ErrorCode::kResourceExhausted);
  EXPECT_NE(put.status().message().find("reserve"), std::string::npos) << put.status().message();
  EXPECT_TRUE(std::filesystem::is_empty(dir.path() + "/frames"));
  auto page = store->List({});
  ASSERT_TRUE(page.ok());
  EXPECT_TRUE(page->captures.empty());
}

TEST(CaptureStoreTest, BadInputIsRefusedWithTheField) {
  TempDir dir;
  auto store = OpenStore(TestOptions(dir.path()));
  ASSERT_TRUE(store);
  std::mt19937 rng(10);
  auto expect_invalid = [&](CaptureRequest request, const std::string& mention) {
    auto put = store->Put(request);
    EXPECT_EQ(put.status().code(), ErrorCode::kInvalidArgument) << mention;
    EXPECT_NE(put.status().message().find(mention), std::string::npos) << put.status().message();
  };
  CaptureRequest request = RandomRequest(rng);
  request.frames.clear();
  expect_invalid(request, "frames");
  request = RandomRequest(rng);
  request.frames[1].camera = Camera::kLeft;
  expect_invalid(request, "second frame");
  request = RandomRequest(rng);
  request.frames[0].pixels.pop_back();
  expect_invalid(request, "pixel bytes");
  request = RandomRequest(rng);
  request.frames[0].stride = 10;
  expect_invalid(request, "stride");
  request = RandomRequest(rng);
  request.frames[0].camera = static_cast<Camera>(7);
  expect_invalid(request, "camera 7");
  request = RandomRequest(rng);
  request.patient_reference = std::string(kMaxTextField + 1, 'x');
  expect_invalid(request, "patient reference");
  request = RandomRequest(rng);
  request.side = static_cast<Side>(9);
  expect_invalid(request, "side 9");

  EXPECT_EQ(store->Get("../../etc/passwd").status().code(), ErrorCode::kInvalidArgument);
  EXPECT_EQ(store->Get(std::string(32, 'A')).status().code(), ErrorCode::kInvalidArgument);
  EXPECT_EQ(store->Get(std::string(32, 'a')).status().code(), ErrorCode::kNotFound);
  EXPECT_EQ(store->Delete("").code(), ErrorCode::kInvalidArgument);

  CaptureStoreOptions relative;
  relative.root = "relative/path";
  EXPECT_EQ(CaptureStore::Open(relative).status().code(), ErrorCode::kInvalidArgument);
}

TEST(CaptureStoreTest, ConcurrentPutsGetsListsAndDeletes) {
  TempDir dir;
  auto store = OpenStore(TestOptions(dir.path()));
  ASSERT_TRUE(store);
  constexpr int kThreads = 4;
  constexpr int kPutsPerThread = 15;
  std::atomic<int> failures{0};
  std::vector<std::thread> threads;
  std::vector<std::vector<std::string>> ids(kThreads);
  for (int t = 0; t < kThreads; ++t) {
    threads.emplace_back([&, t] {
      std::mt19937 rng(100 + t);
      for (int i = 0; i < kPutsPerThread; ++i) {
        auto put = store->Put(RandomRequest(rng, "session-" + std::to_string(t)));
        if (!put.ok()) {
          ++failures;
          continue;
        }
        ids[t].push_back(put->id.str());
        auto got = store->Get(put->id.str());
        if (!got.ok() || got->frames.size() != 2) ++failures;
        if (!store->List({}).ok()) ++failures;
        if (i % 5 == 4) {
          if (!store->Delete(ids[t].front()).ok()) ++failures;
          ids[t].erase(ids[t].begin());
        }
      }
    });
  }
  // A reader hammering whatever exists while the writers run.
  std::atomic<bool> done{false};
  std::thread reader([&] {
    while (!done) {
      auto page = store->List({});
      if (!page.ok()) {
        ++failures;
        continue;
      }
      for (const auto& info : page->captures) {
        auto got = store->Get(info.id.str());
        // Deleted meanwhile is fine; anything else is not.
        if (!got.ok() && got.status().code() != ErrorCode::kNotFound) ++failures;
      }
    }
  });
  for (auto& thread : threads) thread.join();
  done = true;
  reader.join();
  EXPECT_EQ(failures.load(), 0);
  std::set<std::string> all;
  for (const auto& list : ids) all.insert(list.begin(), list.end());
  EXPECT_EQ(all.size(), static_cast<std::size_t>(kThreads * (kPutsPerThread - 3)));
  auto verify = store->VerifyAll();
  ASSERT_TRUE(verify.ok());
  EXPECT_TRUE(verify->empty());
  EXPECT_TRUE(store->CheckIndexIntegrity().ok());
}

}  // namespace
}  // namespace bsls::store
