// Inputs of ReconstructSession for the tests that run bsls-processd replicas
// as processes (failover, malformed requests): both sides' calibrations and
// simulated face frames, made once per process.
//
// The calibrations come from a lighter simulated session than
// bsls/testing/calibration_sessions.h (9 views per side instead of 13, one
// ray per pixel instead of 3 x 3): these tests run under AddressSanitizer
// too, where the full sessions alone take minutes to render. The faces are
// rendered as in service_fixture.h (noise 3, 512 x 512).
#ifndef BSLS_TESTS_PROCESSING_REPLICA_INPUTS_H_
#define BSLS_TESTS_PROCESSING_REPLICA_INPUTS_H_

#include <filesystem>
#include <mutex>
#include <string>
#include <thread>

#include "bsls/calibration/calibration_file.h"
#include "bsls/calibration/manifest.h"
#include "bsls/calibration/side_calibration.h"
#include "bsls/contract/frame_message.h"
#include "bsls/processing/processing_client.h"
#include "bsls/simulator/calibration_session.h"
#include "bsls/simulator/renderer.h"
#include "bsls/simulator/scene.h"
#include "processd_process.h"

namespace bsls::processing::test {

struct SessionInputs {
  std::string left_calibration;  // calibration files (YAML)
  std::string right_calibration;
  cv::Mat left_face;  // 8-bit grey
  cv::Mat right_face;
};

// The calibration file of a light simulated session of `side`.
inline std::string LightCalibrationYaml(pattern::Side side) {
  simulator::CalibrationSessionParams params;
  params.camera_z_mm = {0, 50, 100};
  params.screen_z_mm = {0, 60, 120};
  params.reference_z_mm = {0, 60, 120};
  params.render.supersampling = 1;
  params.render.noise_sigma = 1.0;
  params.render.seed = 11;
  const fs::path folder = MakeTempFolder("bsls_light_session_");
  const fs::path manifest = simulator::WriteCalibrationSession(
      simulator::SimulateCalibrationSession(side, params), folder);
  const calibration::SideCalibration result =
      calibration::CalibrateSide(calibration::LoadManifest(manifest));
  std::error_code ec;
  fs::remove_all(folder, ec);
  return calibration::CalibrationToYaml(result, "test");
}

// The simulated face seen from `side` (noise 3, seed 4, 512 x 512).
inline cv::Mat RenderFace(pattern::Side side) {
  simulator::RenderParams params;
  params.noise_sigma = 3.0;
  params.seed = 4;
  return simulator::Render(simulator::ThesisScene(side, simulator::SurfaceKind::kFace, {}), params)
      .image;
}

// Both sides' calibrations and faces, made once per process (the two sides
// in parallel).
inline const SessionInputs& LightSessionInputs() {
  static std::once_flag once;
  static SessionInputs inputs;
  std::call_once(once, [] {
    std::thread right([] {
      inputs.right_calibration = LightCalibrationYaml(pattern::Side::kRight);
      inputs.right_face = RenderFace(pattern::Side::kRight);
    });
    inputs.left_calibration = LightCalibrationYaml(pattern::Side::kLeft);
    inputs.left_face = RenderFace(pattern::Side::kLeft);
    right.join();
  });
  return inputs;
}

// A ReconstructSession request of both faces with their calibrations inline
// (as the C++ client always sends them).
inline v1::ReconstructSessionRequest SessionRequestOf(const SessionInputs& inputs) {
  v1::ReconstructSessionRequest request;
  contract::ToFrameMessage(inputs.left_face, request.mutable_left());
  contract::ToFrameMessage(inputs.right_face, request.mutable_right());
  *request.mutable_left_calibration() = ProcessingClient::Inline(inputs.left_calibration);
  *request.mutable_right_calibration() = ProcessingClient::Inline(inputs.right_calibration);
  return request;
}

}  // namespace bsls::processing::test

#endif  // BSLS_TESTS_PROCESSING_REPLICA_INPUTS_H_
