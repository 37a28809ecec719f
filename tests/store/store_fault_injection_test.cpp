// Failures injected at every step of storing a grab, through the real store
// code path: each filesystem call of a Put (open, every write, fsync, close,
// rename, directory fsync, statvfs) and each write and sync of the SQLite
// index (WAL frames, commit sync) is failed in turn, with EIO and ENOSPC, and
// short writes are injected. Each time: the Put fails with a clear status,
// nothing unacknowledged becomes visible, the store keeps working, and a
// reopened store finds every acknowledged capture intact and the index
// passing its integrity check.
#include <gtest/gtest.h>

#include <cstdio>
#include <set>

#include "bsls/store/capture_store.h"
#include "bsls/store/faulty_file_system.h"
#include "bsls/store/faulty_sqlite_vfs.h"
#include "store_test_util.h"

namespace bsls::store {
namespace {

using testing::RandomRequest;
using testing::TempDir;
using testing::TestOptions;

// The kinds of call a successful Put makes.
constexpr FsOp kPutOps[] = {FsOp::kStatvfs,        FsOp::kOpen,    FsOp::kWrite,
                            FsOp::kFsync,          FsOp::kClose,   FsOp::kRename,
                            FsOp::kFsyncDirectory, FsOp::kDbWrite, FsOp::kDbSync};

class StoreFaultTest : public ::testing::Test {
 protected:
  StoreFaultTest() : posix_(MakePosixFileSystem()), faulty_(*posix_), vfs_(faulty_) {}

  CaptureStoreOptions Options() {
    CaptureStoreOptions options = TestOptions(dir_.path());
    options.file_system = &faulty_;
    options.sqlite_vfs = vfs_.name();
    return options;
  }

  // Reopens the store without faults and checks that exactly `acknowledged`
  // are present and intact, and nothing else.
  void ExpectReopenedStoreHolds(const std::set<std::string>& acknowledged,
                                const std::string& step) {
    faulty_.Disarm();
    auto reopened = CaptureStore::Open(Options());
    ASSERT_TRUE(reopened.ok()) << step << ": " << reopened.status().ToString();
    CaptureStore& store = **reopened;
    EXPECT_TRUE(store.recovery_report().ok()) << step;
    for (const auto& problem : store.recovery_report().problems) {
      ADD_FAILURE() << step << ": " << problem.status.ToString();
    }
    EXPECT_TRUE(store.CheckIndexIntegrity().ok()) << step;
    CaptureFilter all;
    all.page_size = kMaxPageSize;
    auto page = store.List(all);
    ASSERT_TRUE(page.ok()) << step;
    std::set<std::string> listed;
    for (const auto& info : page->captures) listed.insert(info.id.str());
    EXPECT_EQ(listed, acknowledged) << step;
    for (const auto& id : acknowledged) {
      auto got = store.Get(id);
      EXPECT_TRUE(got.ok()) << step << ": " << got.status().ToString();
    }
  }

  TempDir dir_;
  std::unique_ptr<FileSystem> posix_;
  FaultyFileSystem faulty_;
  FaultySqliteVfs vfs_;
};

TEST_F(StoreFaultTest, EveryStepOfAPutFailsCleanly) {
  std::mt19937 rng(11);
  std::set<std::string> acknowledged;
  // How many calls of each kind one Put makes (same sizes every time).
  std::array<int, kFsOpCount> calls{};
  {
    auto store = CaptureStore::Open(Options());
    ASSERT_TRUE(store.ok()) << store.status().ToString();
    auto warmup = (*store)->Put(RandomRequest(rng));  // first commit creates B-tree pages
    ASSERT_TRUE(warmup.ok());
    acknowledged.insert(warmup->id.str());
    faulty_.ResetCounts();
    auto put = (*store)->Put(RandomRequest(rng));
    ASSERT_TRUE(put.ok()) << put.status().ToString();
    acknowledged.insert(put->id.str());
    for (FsOp op : kPutOps) calls[static_cast<int>(op)] = faulty_.count(op);
  }
  std::string counted;
  for (FsOp op : kPutOps) {
    counted += " " + std::string(ToString(op)) + "=" + std::to_string(calls[static_cast<int>(op)]);
  }
  std::printf("[ faults   ] calls of one put:%s\n", counted.c_str());
  for (FsOp op : kPutOps) {
    ASSERT_GT(calls[static_cast<int>(op)], 0) << "a Put makes no " << ToString(op) << " call";
  }
  EXPECT_EQ(calls[static_cast<int>(FsOp::kFsync)], 2);           // one per frame file
  EXPECT_EQ(calls[static_cast<int>(FsOp::kRename)], 2);          // one per frame file
  EXPECT_EQ(calls[static_cast<int>(FsOp::kFsyncDirectory)], 1);  // one for both renames
  EXPECT_GE(calls[static_cast<int>(FsOp::kDbSync)], 1);          // the WAL at commit

  int steps = 0;
  for (FsOp op : kPutOps) {
    for (Fault fault : {Fault::kEio, Fault::kEnospc}) {
      for (int nth = 1; nth <= calls[static_cast<int>(op)]; ++nth) {
        const std::string step = std::string(ToString(op)) + " #" + std::to_string(nth) +
                                 (fault == Fault::kEio ? " EIO" : " ENOSPC");
        SCOPED_TRACE(step);
        ++steps;
        {
          auto store = CaptureStore::Open(Options());
          ASSERT_TRUE(store.ok()) << store.status().ToString();
          const int fired_before = faulty_.faults_fired();
          faulty_.FailNth(op, nth, fault);
          auto put = (*store)->Put(RandomRequest(rng));
          faulty_.Disarm();
          ASSERT_EQ(faulty_.faults_fired(), fired_before + 1) << "the fault never fired";
          ASSERT_FALSE(put.ok()) << "a Put acknowledged despite the fault";
          const ErrorCode code = put.status().code();
          EXPECT_TRUE(code == ErrorCode::kUnavailable || code == ErrorCode::kResourceExhausted)
              << put.status().ToString();
          // ENOSPC is a full disk wherever the store sees errno; SQLite's
          // xSync reports every fsync failure as SQLITE_IOERR_FSYNC.
          if (fault == Fault::kEnospc && op != FsOp::kDbSync) {
            EXPECT_EQ(code, ErrorCode::kResourceExhausted) << put.status().ToString();
          }
          const std::string& message = put.status().message();
          EXPECT_TRUE(message.find("not acknowledged") != std::string::npos ||
                      message.find("nothing was written") != std::string::npos)
              << message;
          // The failed capture is invisible and the store still works.
          auto page = (*store)->List({});
          ASSERT_TRUE(page.ok());
          EXPECT_EQ(page->captures.size(), acknowledged.size());
          auto after = (*store)->Put(RandomRequest(rng));
          ASSERT_TRUE(after.ok()) << "the store no longer works: " << after.status().ToString();
          acknowledged.insert(after->id.str());
          EXPECT_TRUE((*store)->Get(after->id.str()).ok());
        }
        ExpectReopenedStoreHolds(acknowledged, step);
        if (HasFatalFailure()) return;
      }
    }
  }
  std::printf("[ faults   ] %d injected failures, each followed by a reopen\n", steps);
  EXPECT_GT(steps, 20);
}

TEST_F(StoreFaultTest, ShortWritesAreCompleted) {
  auto store = CaptureStore::Open(Options());
  ASSERT_TRUE(store.ok());
  std::mt19937 rng(12);
  std::set<std::string> acknowledged;
  for (int nth = 1; nth <= 4; ++nth) {
    faulty_.FailNth(FsOp::kWrite, nth, Fault::kShortWrite);
    auto put = (*store)->Put(RandomRequest(rng));
    ASSERT_TRUE(put.ok()) << put.status().ToString();
    acknowledged.insert(put->id.str());
    auto got = (*store)->Get(put->id.str());
    ASSERT_TRUE(got.ok()) << got.status().ToString();
  }
  EXPECT_EQ(faulty_.faults_fired(), 4);
  // Every write short: the loop still completes each file.
  faulty_.FailAll(FsOp::kWrite, Fault::kShortWrite);
  auto put = (*store)->Put(RandomRequest(rng));
  faulty_.Disarm();
  ASSERT_TRUE(put.ok()) << put.status().ToString();
  acknowledged.insert(put->id.str());
  store->reset();
  ExpectReopenedStoreHolds(acknowledged, "short writes");
}

TEST_F(StoreFaultTest, FullDiskIsRefusedBeforeAnythingIsWritten) {
  auto store = CaptureStore::Open(Options());
  ASSERT_TRUE(store.ok());
  std::mt19937 rng(13);
  auto kept = (*store)->Put(RandomRequest(rng));
  ASSERT_TRUE(kept.ok());
  faulty_.SetAvailableBytes(1000);
  faulty_.ResetCounts();
  auto put = (*store)->Put(RandomRequest(rng));
  EXPECT_EQ(put.status().code(), ErrorCode::kResourceExhausted) << put.status().ToString();
  EXPECT_NE(put.status().message().find("nothing was written"), std::string::npos);
  EXPECT_EQ(faulty_.count(FsOp::kOpen), 0);
  EXPECT_EQ(faulty_.count(FsOp::kWrite), 0);
  EXPECT_EQ(faulty_.count(FsOp::kDbWrite), 0);
  faulty_.SetAvailableBytes(std::nullopt);
  EXPECT_TRUE((*store)->Get(kept->id.str()).ok());
  EXPECT_TRUE((*store)->Put(RandomRequest(rng)).ok());
}

TEST_F(StoreFaultTest, FailedDeleteCommitKeepsTheCapture) {
  auto store = CaptureStore::Open(Options());
  ASSERT_TRUE(store.ok());
  std::mt19937 rng(14);
  auto put = (*store)->Put(RandomRequest(rng));
  ASSERT_TRUE(put.ok());
  faulty_.FailNth(FsOp::kDbSync, 1, Fault::kEio);
  Status status = (*store)->Delete(put->id.str());
  faulty_.Disarm();
  EXPECT_FALSE(status.ok());
  EXPECT_TRUE((*store)->Get(put->id.str()).ok()) << "a failed delete lost the capture";
  // An unlink failing after the commit leaves a stray file, not a broken capture.
  faulty_.FailNth(FsOp::kUnlink, 1, Fault::kEio);
  EXPECT_TRUE((*store)->Delete(put->id.str()).ok());
  faulty_.Disarm();
  store->reset();
  faulty_.ResetCounts();
  auto reopened = CaptureStore::Open(Options());
  ASSERT_TRUE(reopened.ok());
  EXPECT_TRUE((*reopened)->recovery_report().ok());
  EXPECT_EQ((*reopened)->recovery_report().orphan_files_removed, 1);
}

}  // namespace
}  // namespace bsls::store
