// The processing queue in the capture store: which captures wait,
// attempts and failures, results stored durably and verified on reading,
// leftovers of interrupted stores removed on open, results deleted with
// their capture, and a store of the first schema migrated.
#include <gtest/gtest.h>
#include <sqlite3.h>

#include <filesystem>
#include <fstream>

#include "bsls/store/capture_store.h"
#include "store_test_util.h"

namespace bsls::store {
namespace {

namespace fs = std::filesystem;
using testing::OpenStore;
using testing::RandomRequest;
using testing::TempDir;
using testing::TestOptions;

std::vector<std::string> Ids(const Result<std::vector<CaptureId>>& ids) {
  std::vector<std::string> out;
  if (ids.ok())
    for (const CaptureId& id : *ids) out.push_back(id.str());
  return out;
}

TEST(ProcessingResults, EveryCaptureWaitsUntilDoneOrFailed) {
  TempDir dir;
  auto store = OpenStore(TestOptions(dir.path()));
  ASSERT_TRUE(store);
  std::mt19937 rng(7);
  auto a = store->Put(RandomRequest(rng));
  auto b = store->Put(RandomRequest(rng));
  auto c = store->Put(RandomRequest(rng));
  ASSERT_TRUE(a.ok() && b.ok() && c.ok());
  EXPECT_EQ(Ids(store->Unprocessed()),
            (std::vector<std::string>{a->id.str(), b->id.str(), c->id.str()}));
  auto never = store->Processing(a->id.str());
  ASSERT_TRUE(never.ok());
  EXPECT_FALSE(never->has_value());

  // Two failed attempts: still waiting, counted, the reason kept.
  ASSERT_TRUE(store->NoteProcessingAttempt(a->id.str(), "unreachable").ok());
  ASSERT_TRUE(store->NoteProcessingAttempt(a->id.str(), "busy").ok());
  auto tried = store->Processing(a->id.str());
  ASSERT_TRUE(tried.ok() && tried->has_value());
  EXPECT_EQ((*tried)->state, ProcessingState::kPending);
  EXPECT_EQ((*tried)->attempts, 2);
  EXPECT_EQ((*tried)->last_error, "busy");

  // Done and failed captures no longer wait.
  const std::map<std::string, std::string> files = {{"surface.ply", "ply bytes"},
                                                    {"record.json", "{}"}};
  ASSERT_TRUE(store->PutProcessingResult(a->id.str(), files, "r1", "0.1.0").ok());
  ASSERT_TRUE(store->PutProcessingFailure(b->id.str(), "no reference line").ok());
  EXPECT_EQ(Ids(store->Unprocessed()), std::vector<std::string>{c->id.str()});
  auto done = store->Processing(a->id.str());
  ASSERT_TRUE(done.ok() && done->has_value());
  EXPECT_EQ((*done)->state, ProcessingState::kDone);
  EXPECT_EQ((*done)->replica, "r1");
  EXPECT_EQ((*done)->files.size(), 2u);
  auto read = store->ReadProcessingFiles(a->id.str());
  ASSERT_TRUE(read.ok()) << read.status().ToString();
  EXPECT_EQ(*read, files);
  EXPECT_EQ(store->ReadProcessingFiles(b->id.str()).status().code(), ErrorCode::kNotFound);
  EXPECT_EQ(store->ReadProcessingFiles(a->id.str(), "other.bin").status().code(),
            ErrorCode::kNotFound);

  // It all survives a reopen.
  store.reset();
  store = OpenStore(TestOptions(dir.path()));
  ASSERT_TRUE(store);
  EXPECT_EQ(Ids(store->Unprocessed()), std::vector<std::string>{c->id.str()});
  EXPECT_TRUE(store->ReadProcessingFiles(a->id.str()).ok());
  EXPECT_EQ(store->recovery_report().result_files_removed, 0);
}

TEST(ProcessingResults, DamageIsFoundAndBadNamesAreRefused) {
  TempDir dir;
  auto store = OpenStore(TestOptions(dir.path()));
  ASSERT_TRUE(store);
  std::mt19937 rng(8);
  auto a = store->Put(RandomRequest(rng));
  ASSERT_TRUE(a.ok());
  for (const std::string& bad :
       std::vector<std::string>{"../escape", ".hidden", "a/b", std::string(65, 'x'), ""})
    EXPECT_EQ(store->PutProcessingResult(a->id.str(), {{bad, "x"}}, "r", "v").code(),
              ErrorCode::kInvalidArgument)
        << bad;
  EXPECT_EQ(store->PutProcessingResult("nope", {{"a.txt", "x"}}, "r", "v").code(),
            ErrorCode::kInvalidArgument);
  ASSERT_TRUE(
      store->PutProcessingResult(a->id.str(), {{"report.json", "{\"a\": 1}"}}, "r", "v").ok());
  const std::string path = dir.path() + "/results/" + a->id.str() + "-report.json";
  {
    std::ofstream out(path, std::ios::binary | std::ios::trunc);
    out << "{\"a\": 2}";
  }
  EXPECT_EQ(store->ReadProcessingFiles(a->id.str()).status().code(), ErrorCode::kDataLoss);
  fs::remove(path);
  EXPECT_EQ(store->ReadProcessingFiles(a->id.str()).status().code(), ErrorCode::kDataLoss);
}

TEST(ProcessingResults, LeftoversAreRemovedAndResultsGoWithTheirCapture) {
  TempDir dir;
  std::string kept_id, deleted_id;
  {
    auto store = OpenStore(TestOptions(dir.path()));
    ASSERT_TRUE(store);
    std::mt19937 rng(9);
    auto kept = store->Put(RandomRequest(rng));
    auto deleted = store->Put(RandomRequest(rng));
    ASSERT_TRUE(kept.ok() && deleted.ok());
    kept_id = kept->id.str();
    deleted_id = deleted->id.str();
    ASSERT_TRUE(store->PutProcessingResult(kept_id, {{"surface.ply", "k"}}, "r", "v").ok());
    ASSERT_TRUE(store->PutProcessingResult(deleted_id, {{"surface.ply", "d"}}, "r", "v").ok());
    ASSERT_TRUE(store->Delete(deleted_id).ok());
    EXPECT_FALSE(fs::exists(dir.path() + "/results/" + deleted_id + "-surface.ply"));
  }
  // A crash between the files and the record, and a half-written file.
  const std::string results = dir.path() + "/results/";
  std::ofstream(results + kept_id + "-extra.json") << "never recorded";
  std::ofstream(results + ".tmp-" + kept_id + "-x.ply") << "half";
  std::ofstream(results + deleted_id + "-surface.ply") << "orphan";
  auto store = OpenStore(TestOptions(dir.path()));
  ASSERT_TRUE(store);
  EXPECT_EQ(store->recovery_report().result_files_removed, 3);
  EXPECT_TRUE(fs::exists(results + kept_id + "-surface.ply"));
  EXPECT_FALSE(fs::exists(results + kept_id + "-extra.json"));
  EXPECT_TRUE(store->ReadProcessingFiles(kept_id).ok());
}

TEST(ProcessingResults, AStoreOfTheFirstSchemaIsMigrated) {
  TempDir dir;
  std::string id;
  {
    auto store = OpenStore(TestOptions(dir.path()));
    ASSERT_TRUE(store);
    std::mt19937 rng(10);
    auto a = store->Put(RandomRequest(rng));
    ASSERT_TRUE(a.ok());
    id = a->id.str();
  }
  // Back to schema 1, as an issue-4 daemon left it.
  sqlite3* db = nullptr;
  ASSERT_EQ(sqlite3_open((dir.path() + "/index.sqlite").c_str(), &db), SQLITE_OK);
  ASSERT_EQ(sqlite3_exec(db, "DROP TABLE processing; PRAGMA user_version = 1;", nullptr, nullptr,
                         nullptr),
            SQLITE_OK);
  sqlite3_close(db);
  auto store = OpenStore(TestOptions(dir.path()));
  ASSERT_TRUE(store);
  EXPECT_EQ(Ids(store->Unprocessed()), std::vector<std::string>{id});
  EXPECT_TRUE(store->PutProcessingFailure(id, "x").ok());
}

}  // namespace
}  // namespace bsls::store
