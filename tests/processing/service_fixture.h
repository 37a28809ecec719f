// What the processing-service tests share: the two sides' calibrations (the
// simulated sessions of bsls/testing/calibration_sessions.h), simulated
// face frames, and a service on an in-process channel. Built once per test
// program (the program is one CTest test, so once per run).
#ifndef BSLS_TESTS_PROCESSING_SERVICE_FIXTURE_H_
#define BSLS_TESTS_PROCESSING_SERVICE_FIXTURE_H_

#include <grpcpp/grpcpp.h>

#include <memory>
#include <string>

#include "bsls/calibration/calibration_file.h"
#include "bsls/contract/frame_message.h"
#include "bsls/processing/processing_client.h"
#include "bsls/processing/processing_service.h"
#include "bsls/simulator/renderer.h"
#include "bsls/simulator/scene.h"
#include "bsls/testing/calibration_sessions.h"

namespace bsls::processing::test {

using calibration::testing::SessionKind;

// The calibration file of one side's simulated session.
inline const std::string& CalibrationYaml(pattern::Side side) {
  static std::map<pattern::Side, std::string> files;
  if (auto it = files.find(side); it != files.end()) return it->second;
  const SessionKind kind =
      side == pattern::Side::kLeft ? SessionKind::kLeftNoisy : SessionKind::kRightClean;
  return files[side] =
             calibration::CalibrationToYaml(calibration::testing::SessionCalibration(kind), "test");
}

// A simulated frame of the face from `side` (noise 3, 512 x 512).
inline const cv::Mat& FaceFrame(pattern::Side side) {
  static std::map<pattern::Side, cv::Mat> frames;
  if (auto it = frames.find(side); it != frames.end()) return it->second;
  simulator::ThesisSceneOptions options;
  simulator::RenderParams params;
  params.noise_sigma = 3.0;
  params.seed = 4;
  return frames[side] =
             simulator::Render(simulator::ThesisScene(side, simulator::SurfaceKind::kFace, options),
                               params)
                 .image;
}

inline v1::Frame FrameMessage(const cv::Mat& grey) {
  v1::Frame frame;
  contract::ToFrameMessage(grey, &frame);
  return frame;
}

// A service on a gRPC server reached through an in-process channel.
class InProcessService {
 public:
  explicit InProcessService(ProcessingServiceOptions options = {}) {
    options.software_version = "test";
    if (options.replica.empty()) options.replica = "replica-under-test";
    service_ = std::make_unique<ProcessingService>(options);
    grpc::ServerBuilder builder;
    builder.SetMaxReceiveMessageSize(40 << 20);
    builder.SetMaxSendMessageSize(5 << 20);
    builder.RegisterService(service_.get());
    server_ = builder.BuildAndStart();
    grpc::ChannelArguments args;
    args.SetMaxReceiveMessageSize(8 << 20);
    args.SetMaxSendMessageSize(40 << 20);
    channel_ = server_->InProcessChannel(args);
    stub_ = v1::Processing::NewStub(channel_);
  }
  ~InProcessService() {
    service_->BeginDrain();
    server_->Shutdown(std::chrono::system_clock::now() + std::chrono::seconds(5));
  }

  ProcessingService& service() { return *service_; }
  v1::Processing::Stub& stub() { return *stub_; }
  std::shared_ptr<grpc::Channel> channel() { return channel_; }
  // A client with one attempt per call (retries are tested on their own).
  ProcessingClient Client(int attempts = 1) {
    ClientOptions options;
    options.target = "in-process";
    options.attempts = attempts;
    return ProcessingClient(channel_, options);
  }

 private:
  std::unique_ptr<ProcessingService> service_;
  std::unique_ptr<grpc::Server> server_;
  std::shared_ptr<grpc::Channel> channel_;
  std::unique_ptr<v1::Processing::Stub> stub_;
};

}  // namespace bsls::processing::test

#endif  // BSLS_TESTS_PROCESSING_SERVICE_FIXTURE_H_
