// The capture-to-mesh pipeline: the real bslsd on its simulated
// framestore hands every acknowledged grab to a real bsls-processd and keeps
// what comes back beside the capture as a sealed record; the queue survives
// an absent service and a restart of the daemon.
#include <gtest/gtest.h>

#include <atomic>
#include <nlohmann/json.hpp>
#include <thread>

#include "bsls/calibration/calibration_file.h"
#include "bsls/common/sha256.h"
#include "bsls/io/surface_file.h"
#include "bsls/testing/build_paths.h"
#include "bsls/testing/calibration_sessions.h"
#include "bsls/v1/processing.grpc.pb.h"
#include "daemon_process.h"
#include "processd_process.h"

namespace bsls::testing {
namespace {

using std::chrono::milliseconds;
using std::chrono::seconds;

using processing::test::ProcessdProcess;

// A replica of bsls-processd in `dir` on loopback TCP (`tcp`: where).
std::unique_ptr<ProcessdProcess> StartReplica(const fs::path& dir, const std::string& name,
                                              const std::string& tcp = "127.0.0.1:0") {
  return std::make_unique<ProcessdProcess>(
      bsls::testing::ProcessdPath(), dir, name, 1,
      std::vector<std::string>{"--set", "scratch_dir=" + dir.string()}, std::chrono::seconds(120),
      tcp);
}

class Pipeline : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = MakeDaemonDir(::testing::UnitTest::GetInstance()->current_test_info()->name());
    using calibration::testing::SessionKind;
    for (auto [kind, name] : {std::pair{SessionKind::kLeftNoisy, "left.yaml"},
                              std::pair{SessionKind::kRightClean, "right.yaml"}})
      calibration::SaveCalibration(dir_ / name, calibration::testing::SessionCalibration(kind),
                                   "test");
  }
  // bslsd handing its grabs to `server`, retrying quickly.
  void StartDaemon(const std::string& server) {
    config_ = WriteDaemonConfig(
        dir_, "roles:\n  admin: [root]\nslides:\n  backend: simulated\nprocessing:\n  server: \"" +
                  server + "\"\n  calibration_left: " + (dir_ / "left.yaml").string() +
                  "\n  calibration_right: " + (dir_ / "right.yaml").string() +
                  "\n  retry_initial_ms: 100\n  retry_max_ms: 400\n");
    daemon_ = std::make_unique<DaemonProcess>(dir_, config_);
    ASSERT_TRUE(daemon_->ready()) << daemon_->Log();
  }
  // A grab under the left brick slide (both sides: each under its own).
  std::string Grab(v1::GrabSide side) {
    v1::SetSlideRequest slide;
    slide.set_slide(2);
    v1::SlideState state;
    EXPECT_TRUE(daemon_->Stub()->SetSlide(Deadline(milliseconds(10000)).get(), slide, &state).ok());
    v1::GrabRequest request;
    request.set_side(side);
    request.set_session_id("pipeline");
    v1::GrabResponse reply;
    const grpc::Status status =
        daemon_->Stub()->Grab(Deadline(milliseconds(30000)).get(), request, &reply);
    EXPECT_TRUE(status.ok()) << status.error_message();
    return reply.capture().capture_id();
  }
  v1::CaptureInfo Get(const std::string& id) {
    v1::GetCaptureRequest request;
    request.set_capture_id(id);
    v1::CaptureInfo info;
    EXPECT_TRUE(
        daemon_->Stub()->GetCapture(Deadline(milliseconds(10000)).get(), request, &info).ok());
    return info;
  }
  // Polls until the capture's processing is no longer pending.
  v1::CaptureInfo WaitProcessed(const std::string& id, seconds timeout = seconds(300)) {
    const auto until = std::chrono::steady_clock::now() + timeout;
    v1::CaptureInfo info = Get(id);
    while (info.processing().state() == v1::ProcessingStatus::STATE_PENDING &&
           std::chrono::steady_clock::now() < until) {
      std::this_thread::sleep_for(milliseconds(200));
      info = Get(id);
    }
    return info;
  }
  std::map<std::string, std::string> Results(const std::string& id, const std::string& name = "") {
    v1::GetCaptureResultRequest request;
    request.set_capture_id(id);
    request.set_name(name);
    auto context = Deadline(milliseconds(30000));
    auto reader = daemon_->Stub()->GetCaptureResult(context.get(), request);
    std::map<std::string, std::string> files;
    v1::Artifact chunk;
    while (reader->Read(&chunk)) files[chunk.name()] += chunk.data();
    last_status_ = reader->Finish();
    return files;
  }
  void TearDown() override {
    if (daemon_ && !daemon_->exited()) {
      EXPECT_EQ(daemon_->Terminate(), 0) << daemon_->Log();
    }
  }

  fs::path dir_;
  fs::path config_;
  std::unique_ptr<DaemonProcess> daemon_;
  grpc::Status last_status_;
};

TEST_F(Pipeline, AGrabOfBothSidesIsReconstructedAndSealedBesideTheCapture) {
  const auto processd = StartReplica(dir_, "p");
  ASSERT_TRUE(processd->ready()) << processd->Log();
  StartDaemon(processd->address());
  // Someone watching hears of the result.
  grpc::ClientContext watch;
  auto events = daemon_->Stub()->WatchEvents(&watch, {});
  const std::string id = Grab(v1::GRAB_SIDE_BOTH);
  ASSERT_FALSE(id.empty());
  bool heard = false;
  v1::Event event;
  while (!heard && events->Read(&event))
    heard = event.has_processing_finished() && event.processing_finished().capture_id() == id;
  watch.TryCancel();
  EXPECT_TRUE(heard);

  const v1::CaptureInfo info = WaitProcessed(id);
  ASSERT_EQ(info.processing().state(), v1::ProcessingStatus::STATE_DONE)
      << info.processing().last_error() << "\n"
      << daemon_->Log();
  EXPECT_EQ(info.processing().replica(), "p");
  const std::map<std::string, std::string> files = Results(id);
  ASSERT_TRUE(last_status_.ok()) << last_status_.error_message();
  for (const char* name :
       {"surface.ply", "left.ply", "right.ply", "report.json", "record.json", "left.junctions.json",
        "right.junctions.json", "calibration-left.yaml", "calibration-right.yaml"})
    EXPECT_TRUE(files.count(name)) << name;
  EXPECT_EQ(Sha256Hex(files.at("record.json")), info.processing().record_sha256());

  // The record ties the result to the frames, the calibrations and the software.
  const nlohmann::json record = nlohmann::json::parse(files.at("record.json"));
  EXPECT_EQ(record.at("capture_id"), id);
  EXPECT_EQ(record.at("call"), "ReconstructSession");
  ASSERT_EQ(record.at("frames").size(), 2u);
  EXPECT_EQ(record.at("frames")[0].at("sha256"), info.frames(0).sha256());
  EXPECT_EQ(record.at("calibrations").at("left"),
            "sha256:" + Sha256Hex(files.at("calibration-left.yaml")));
  for (const auto& [name, sha256] : record.at("files").items())
    EXPECT_EQ(Sha256Hex(files.at(name)), sha256.get<std::string>()) << name;
  EXPECT_FALSE(record.at("processing_software_version").get<std::string>().empty());
  EXPECT_FALSE(record.at("daemon_software_version").get<std::string>().empty());
  const geometry::SurfaceMesh mesh = io::DecodePly(files.at("surface.ply"), "surface.ply");
  EXPECT_GT(mesh.VertexCount(), 5000u);
  EXPECT_GT(mesh.faces.size(), 5000u);
  // One file on its own; an unknown name is NOT_FOUND.
  EXPECT_EQ(Results(id, "report.json").size(), 1u);
  Results(id, "nothing.bin");
  EXPECT_EQ(last_status_.error_code(), grpc::StatusCode::NOT_FOUND);

  // One side on its own: that side's surface with its calibration.
  const std::string left = Grab(v1::GRAB_SIDE_LEFT);
  const v1::CaptureInfo left_info = WaitProcessed(left);
  ASSERT_EQ(left_info.processing().state(), v1::ProcessingStatus::STATE_DONE)
      << left_info.processing().last_error();
  const auto left_files = Results(left);
  for (const char* name : {"junctions.json", "surface.ply", "overlay.png", "record.json"})
    EXPECT_TRUE(left_files.count(name)) << name;

  // Deleting the capture deletes its results.
  v1::DeleteCaptureRequest remove;
  remove.set_capture_id(id);
  v1::DeleteCaptureResponse removed;
  ASSERT_TRUE(
      daemon_->Stub()->DeleteCapture(Deadline(milliseconds(10000)).get(), remove, &removed).ok());
  for (const auto& entry : fs::directory_iterator(dir_ / "store" / "results"))
    EXPECT_NE(entry.path().filename().string().rfind(id, 0), 0u) << entry.path();
}

TEST_F(Pipeline, CapturesWaitThroughAnOutageAndARestartOfTheDaemon) {
  const std::string target = "127.0.0.1:" + std::to_string(FreeLoopbackPort());
  StartDaemon(target);  // nobody listens there yet
  const std::string first = Grab(v1::GRAB_SIDE_BOTH);
  const std::string second = Grab(v1::GRAB_SIDE_BOTH);
  // Tried and refused by the absent service, still pending, the reason shown.
  v1::CaptureInfo info = Get(first);
  for (int i = 0; i < 100 && info.processing().attempts() == 0; ++i) {
    std::this_thread::sleep_for(milliseconds(100));
    info = Get(first);
  }
  EXPECT_EQ(info.processing().state(), v1::ProcessingStatus::STATE_PENDING);
  EXPECT_GE(info.processing().attempts(), 1u);
  EXPECT_FALSE(info.processing().last_error().empty());

  // The daemon restarts: the queue is the store, nothing is lost.
  ASSERT_EQ(daemon_->Terminate(), 0) << daemon_->Log();
  daemon_ = std::make_unique<DaemonProcess>(dir_, config_);
  ASSERT_TRUE(daemon_->ready()) << daemon_->Log();
  EXPECT_EQ(Get(second).processing().state(), v1::ProcessingStatus::STATE_PENDING);

  // The service comes: both are processed, oldest first.
  const auto processd = StartReplica(dir_, "p", target);
  ASSERT_TRUE(processd->ready()) << processd->Log();
  for (const std::string& id : {first, second}) {
    const v1::CaptureInfo done = WaitProcessed(id);
    EXPECT_EQ(done.processing().state(), v1::ProcessingStatus::STATE_DONE)
        << done.processing().last_error() << "\n"
        << daemon_->Log();
  }
}

TEST_F(Pipeline, AReplicaKilledMidCallLosesNoCapture) {
  // Two replicas behind one round_robin address list.
  auto first = StartReplica(dir_, "r1");
  const auto second = StartReplica(dir_, "r2");
  ASSERT_TRUE(first->ready() && second->ready()) << first->Log() << second->Log();
  StartDaemon("ipv4:" + first->address() + "," + second->address());
  // Kill r1 the moment it works on a capture (watched from the start:
  // in a fast build the first captures are processed while later ones are
  // still being grabbed).
  std::atomic<bool> stop{false}, killed{false};
  std::thread killer([&] {
    auto r1 = v1::Processing::NewStub(
        grpc::CreateChannel(first->address(), grpc::InsecureChannelCredentials()));
    while (!stop) {
      v1::ServerInfo info;
      if (r1->GetServerInfo(Deadline(milliseconds(2000)).get(), {}, &info).ok() &&
          info.busy() > 0) {
        first->Kill();
        killed = true;
        return;
      }
      std::this_thread::sleep_for(milliseconds(2));
    }
  });
  std::vector<std::string> ids;
  for (int i = 0; i < 4; ++i) ids.push_back(Grab(v1::GRAB_SIDE_BOTH));
  for (const std::string& id : ids) {
    const v1::CaptureInfo done = WaitProcessed(id);
    EXPECT_EQ(done.processing().state(), v1::ProcessingStatus::STATE_DONE)
        << done.processing().last_error() << "\n"
        << daemon_->Log();
  }
  stop = true;
  killer.join();
  EXPECT_TRUE(killed) << "r1 never got work";
  // After the kill every capture still waiting went to the survivor.
  EXPECT_EQ(Get(ids.back()).processing().replica(), "r2");
}

}  // namespace
}  // namespace bsls::testing
