#include "bsls/framestore/simulated_framestore.h"

#include <cmath>
#include <exception>
#include <numbers>
#include <opencv2/core.hpp>
#include <thread>

#include "bsls/simulator/renderer.h"
#include "bsls/simulator/scene.h"

namespace bsls::framestore {

namespace {

Status Invalid(std::string message) { return {ErrorCode::kInvalidArgument, std::move(message)}; }

pattern::Side SideOf(Camera camera) {
  return camera == Camera::kRight ? pattern::Side::kRight : pattern::Side::kLeft;
}

// The head moved by `dz` mm along z: the same picture as the rig moved by -dz.
geometry::PinholeModel Shifted(const geometry::PinholeModel& model, double dz) {
  geometry::Pose pose = model.pose();
  pose.translation += pose.rotation * Eigen::Vector3d(0.0, 0.0, dz);
  return {model.intrinsics(), pose};
}

}  // namespace

bool SimulatedFramestoreParams::IsValid(std::string* error) const {
  auto fail = [error](std::string message) {
    if (error) *error = std::move(message);
    return false;
  };
  if (!(frame_rate_hz > 0.0 && frame_rate_hz <= 1000.0))
    return fail("frame_rate_hz " + std::to_string(frame_rate_hz) + " is outside (0, 1000]");
  if (!(breathing_amplitude_mm >= 0.0 && breathing_amplitude_mm <= 20.0))
    return fail("breathing_amplitude_mm must be in [0, 20]");
  if (!(breathing_period_s > 0.0)) return fail("breathing_period_s must be > 0");
  if (breathing_phases < 1 || breathing_phases > 64)
    return fail("breathing_phases " + std::to_string(breathing_phases) + " is outside [1, 64]");
  if (!(noise_sigma >= 0.0 && noise_sigma <= 50.0)) return fail("noise_sigma must be in [0, 50]");
  return true;
}

// One rendered view: grey levels before noise at nominal gain (CV_32FC1).
struct SimulatedFramestore::View {
  cv::Mat noiseless;
};

SimulatedFramestore::SimulatedFramestore(const SimulatedFramestoreParams& params)
    : params_(params), epoch_(std::chrono::steady_clock::now()) {
  capabilities_.backend = "simulated";
  capabilities_.device = "simulated head in the thesis rig (simulator)";
  capabilities_.cameras = {Camera::kLeft, Camera::kRight};
  capabilities_.gain = {kSimulatedGainMin, kSimulatedGainMax, kSimulatedGainNominal,
                        "gain code, gain = code / 128"};
  capabilities_.width = simulator::RigParams{}.width;
  capabilities_.height = simulator::RigParams{}.height;
}

SimulatedFramestore::~SimulatedFramestore() = default;

Result<std::unique_ptr<SimulatedFramestore>> SimulatedFramestore::Open(
    const SimulatedFramestoreParams& params) {
  std::string error;
  if (!params.IsValid(&error)) return Invalid("simulated framestore: " + error);
  std::unique_ptr<SimulatedFramestore> store(new SimulatedFramestore(params));
  // Render the left camera's first view now: a missing face model is an
  // error of Open, not of the first grab.
  try {
    store->ViewFor(Camera::kLeft, params.slide ? params.slide() : 2, 0);
  } catch (const std::exception& e) {
    return Status(ErrorCode::kUnavailable, std::string("simulated framestore: ") + e.what());
  }
  return store;
}

Status SimulatedFramestore::SelectCamera(Camera camera) {
  if (!capabilities_.HasCamera(camera))
    return Invalid("camera " + ToString(camera) + " is not one of the simulated rig's cameras");
  camera_ = camera;
  return {};
}

Status SimulatedFramestore::SetGain(int gain) {
  if (!capabilities_.gain.Contains(gain))
    return Invalid("gain " + std::to_string(gain) + " is outside " +
                   std::to_string(capabilities_.gain.min) + ".." +
                   std::to_string(capabilities_.gain.max));
  gain_ = gain;
  return {};
}

const SimulatedFramestore::View& SimulatedFramestore::ViewFor(Camera camera, int slide, int phase) {
  const auto key = std::make_tuple(static_cast<int>(camera), slide, phase);
  if (auto it = views_.find(key); it != views_.end()) return *it->second;
  const pattern::Side side = SideOf(camera);
  simulator::Scene scene = simulator::ThesisScene(side, simulator::SurfaceKind::kFace);
  const double dz = params_.breathing_amplitude_mm *
                    std::sin(2.0 * std::numbers::pi * phase / params_.breathing_phases);
  scene.camera = Shifted(scene.camera, dz);
  scene.projector = Shifted(scene.projector, dz);
  simulator::RenderParams render;
  render.noise_sigma = 0.0;
  render.supersampling = 1;  // live frames: speed over the last tenth of a pixel
  if (slide >= 1 && slide <= 3) {
    // One projector serves both sides (thesis Figure 1.1): the other side's
    // brick slide is simply projected; the scene's side only names the
    // labels of the ground truth, which a framestore does not need.
    scene.slide = static_cast<pattern::Slide>(slide);
    if (scene.slide == pattern::Slide::kLeftBrick) scene.side = pattern::Side::kLeft;
    if (scene.slide == pattern::Slide::kRightBrick) scene.side = pattern::Side::kRight;
  } else {
    render.projector_power = 0.0;  // no slide in place: the projector shows nothing
  }
  auto view = std::make_unique<View>();
  view->noiseless = simulator::Renderer(std::move(scene), render).RenderNoiseless();
  return *(views_[key] = std::move(view));
}

Result<GreyFrame> SimulatedFramestore::Grab(const GrabOptions& options) {
  using Clock = std::chrono::steady_clock;
  const Clock::time_point requested = Clock::now();
  // A camera delivers whole frames on its own clock: the next frame time.
  const auto period = std::chrono::duration_cast<Clock::duration>(
      std::chrono::duration<double>(1.0 / params_.frame_rate_hz));
  Clock::time_point exposed = requested;
  if (params_.paced) {
    const auto frames_since_epoch = (requested - epoch_) / period + 1;
    exposed = epoch_ + frames_since_epoch * period;
    if (options.deadline && exposed > *options.deadline)
      return Status(ErrorCode::kDeadlineExceeded,
                    "simulated framestore: the next frame comes after the grab's deadline");
    std::this_thread::sleep_until(exposed);
  }
  const double t = std::chrono::duration<double>(exposed - epoch_).count();
  // A still head needs one view per camera and slide.
  const int phases = params_.breathing_amplitude_mm > 0.0 ? params_.breathing_phases : 1;
  const int phase = static_cast<int>(std::floor(t / params_.breathing_period_s * phases)) % phases;
  const int slide = params_.slide ? params_.slide() : (camera_ == Camera::kRight ? 3 : 2);
  const View* view = nullptr;
  try {
    view = &ViewFor(camera_, slide, phase);
  } catch (const std::exception& e) {
    return Status(ErrorCode::kInternal, std::string("simulated framestore: ") + e.what());
  }

  GreyFrame frame;
  frame.width = view->noiseless.cols;
  frame.height = view->noiseless.rows;
  frame.stride = frame.width;
  frame.pixels.resize(static_cast<std::size_t>(frame.stride) * frame.height);
  frame.camera = camera_;
  frame.gain = gain_;
  frame.sequence = ++sequence_;
  cv::Mat noisy = view->noiseless * (static_cast<double>(gain_) / kSimulatedGainNominal);
  if (params_.noise_sigma > 0.0) {
    cv::Mat noise(noisy.size(), CV_32FC1);
    cv::RNG rng(params_.seed * 0x9E3779B97F4A7C15ull + frame.sequence);
    rng.fill(noise, cv::RNG::NORMAL, 0.0, params_.noise_sigma);
    noisy += noise;
  }
  cv::Mat out(frame.height, frame.width, CV_8UC1, frame.pixels.data(), frame.stride);
  noisy.convertTo(out, CV_8UC1);  // rounds and saturates to 0..255
  frame.timestamps.requested = requested;
  frame.timestamps.exposed = exposed;
  frame.timestamps.delivered = Clock::now();
  frame.timestamps.wall = std::chrono::system_clock::now();
  return frame;
}

}  // namespace bsls::framestore
