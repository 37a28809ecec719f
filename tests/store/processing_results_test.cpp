// The processing queue in the capture store: which captures wait,
// attempts and failures, results stored durably and verified on reading,
// leftovers of interrupted stores removed on open, results deleted with
// their capture, and a store of the first schema migrated.
#include <gtest/gtest.h>
#include <sqlite3.h>

#include <filesystem>
#include <fstream>
#include <memory>
#include <nlohmann/json.hpp>
#include <optional>

#include "bsls/store/capture_store.h"
#include "store_test_util.h"

namespace bsls::store {
namespace {

namespace fs = std::filesystem;
using testing::OpenStore;
using testing::RandomRequest;
using testing::TempDir;
using testing::TestOptions;

// Provenance of a replica "r" at version "v".
ProcessingProvenance By(const std::string& replica = "r", const std::string& version = "v") {
  ProcessingProvenance p;
  p.call = "ProcessFrame";
  p.replica = replica;
  p.processing_software_version = version;
  p.daemon_software_version = "d";
  return p;
}

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
                                                    {"report.json", "{}"}};
  ASSERT_TRUE(store->PutProcessingResult(a->id.str(), files, By("r1", "0.1.0")).ok());
  ASSERT_TRUE(store->PutProcessingFailure(b->id.str(), "no reference line").ok());
  EXPECT_EQ(Ids(store->Unprocessed()), std::vector<std::string>{c->id.str()});
  auto done = store->Processing(a->id.str());
  ASSERT_TRUE(done.ok() && done->has_value());
  EXPECT_EQ((*done)->state, ProcessingState::kDone);
  EXPECT_EQ((*done)->replica, "r1");
  EXPECT_EQ((*done)->files.size(), 3u);  // and the record
  auto read = store->ReadProcessingFiles(a->id.str());
  ASSERT_TRUE(read.ok()) << read.status().ToString();
  EXPECT_EQ(read->size(), 3u);
  for (const auto& [name, bytes] : files) EXPECT_EQ(read->at(name), bytes) << name;
  EXPECT_EQ(read->count(std::string(kRecordFileName)), 1u);
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

// The store seals the results with record.json, written from its own copy
// of the capture's metadata: the frames by hash, every file by hash, and
// where the results came from.
// A store in a folder of its own with one random capture.
class OneCapture : public ::testing::Test {
 protected:
  void SetUp() override {
    store = OpenStore(TestOptions(dir.path()));
    ASSERT_TRUE(store);
    std::mt19937 rng(8);
    auto put = store->Put(RandomRequest(rng));
    ASSERT_TRUE(put.ok()) << put.status().ToString();
    a = std::move(put).value();
  }
  TempDir dir;
  std::unique_ptr<CaptureStore> store;
  std::optional<CaptureInfo> a;
};

TEST_F(OneCapture, TheRecordSealsTheFilesWithTheCapturesOwnMetadata) {
  ProcessingProvenance p = By("replica-1", "1.2.3");
  p.call = "ReconstructSession";
  p.calibrations["left"] = "sha256:abc";
  p.results.push_back({{"replica", "replica-1"}});
  ASSERT_TRUE(store->PutProcessingResult(a->id.str(), {{"surface.ply", "ply"}}, p).ok());
  auto files = store->ReadProcessingFiles(a->id.str());
  ASSERT_TRUE(files.ok()) << files.status().ToString();
  const nlohmann::json record = nlohmann::json::parse(files->at(kRecordFileName));
  EXPECT_EQ(record.at("format"), "bsls-processing-record");
  EXPECT_EQ(record.at("capture_id"), a->id.str());
  EXPECT_EQ(record.at("session_id"), a->session_id);
  EXPECT_EQ(record.at("side"), ToString(a->side));
  ASSERT_EQ(record.at("frames").size(), a->frames.size());
  for (std::size_t i = 0; i < a->frames.size(); ++i)
    EXPECT_EQ(record.at("frames")[i].at("sha256"), a->frames[i].sha256);
  auto done = store->Processing(a->id.str());
  ASSERT_TRUE(done.ok() && done->has_value());
  EXPECT_EQ(record.at("files").at("surface.ply"), (*done)->files.at("surface.ply"));
  EXPECT_EQ(record.at("files").count(kRecordFileName), 0u);  // it cannot list itself
  EXPECT_EQ(record.at("call"), "ReconstructSession");
  EXPECT_EQ(record.at("calibrations").at("left"), "sha256:abc");
  EXPECT_EQ(record.at("results")[0].at("replica"), "replica-1");
  EXPECT_EQ(record.at("replica"), "replica-1");
  EXPECT_EQ(record.at("processing_software_version"), "1.2.3");
  EXPECT_EQ(record.at("daemon_software_version"), "d");
}

TEST_F(OneCapture, DamageIsFoundAndBadNamesAreRefused) {
  for (const std::string& bad : std::vector<std::string>{"../escape", ".hidden", "a/b",
                                                         std::string(65, 'x'), "", kRecordFileName})
    EXPECT_EQ(store->PutProcessingResult(a->id.str(), {{bad, "x"}}, By()).code(),
              ErrorCode::kInvalidArgument)
        << bad;
  EXPECT_EQ(store->PutProcessingResult("nope", {{"a.txt", "x"}}, By()).code(),
            ErrorCode::kInvalidArgument);
  ASSERT_TRUE(store->PutProcessingResult(a->id.str(), {{"report.json", "{\"a\": 1}"}}, By()).ok());
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
    ASSERT_TRUE(store->PutProcessingResult(kept_id, {{"surface.ply", "k"}}, By()).ok());
    ASSERT_TRUE(store->PutProcessingResult(deleted_id, {{"surface.ply", "d"}}, By()).ok());
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
