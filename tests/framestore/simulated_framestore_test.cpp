// The simulated framestore (bslsd's default backend): frames of the simulated
// head that follow the camera, the slide in place and the gain, paced like a
// 25 Hz camera.
#include "bsls/framestore/simulated_framestore.h"

#include <gtest/gtest.h>

#include <atomic>
#include <cmath>
#include <numeric>

namespace bsls::framestore {
namespace {

double Mean(const GreyFrame& frame) {
  double sum = 0.0;
  for (int y = 0; y < frame.height; ++y)
    for (int x = 0; x < frame.width; ++x) sum += frame.at(x, y);
  return sum / (static_cast<double>(frame.width) * frame.height);
}

// Pixels (of a noiseless pair) that differ by more than 10 grey levels.
int Differing(const GreyFrame& a, const GreyFrame& b) {
  int count = 0;
  for (int y = 0; y < a.height; ++y)
    for (int x = 0; x < a.width; ++x) count += std::abs(a.at(x, y) - b.at(x, y)) > 10;
  return count;
}

SimulatedFramestoreParams Quiet(std::atomic<int>* slide) {
  SimulatedFramestoreParams params;
  params.noise_sigma = 0.0;
  params.paced = false;
  params.breathing_amplitude_mm = 0.0;
  params.breathing_phases = 1;
  if (slide) params.slide = [slide] { return slide->load(); };
  return params;
}

TEST(SimulatedFramestore, OffersTheRigsTwoCamerasAndAGainRange) {
  auto store = SimulatedFramestore::Open(Quiet(nullptr));
  ASSERT_TRUE(store.ok()) << store.status().ToString();
  const Capabilities& caps = (*store)->capabilities();
  EXPECT_EQ(caps.backend, "simulated");
  EXPECT_EQ(caps.cameras, (std::vector<Camera>{Camera::kLeft, Camera::kRight}));
  EXPECT_EQ(caps.width, 512);
  EXPECT_EQ(caps.height, 512);
  EXPECT_TRUE(caps.gain.Contains(caps.gain.nominal));
  EXPECT_EQ((*store)->gain(), caps.gain.nominal);
}

TEST(SimulatedFramestore, FramesFollowTheCameraTheSlideAndTheGain) {
  std::atomic<int> slide{2};
  auto opened = SimulatedFramestore::Open(Quiet(&slide));
  ASSERT_TRUE(opened.ok()) << opened.status().ToString();
  SimulatedFramestore& store = **opened;
  auto left = store.Grab();
  ASSERT_TRUE(left.ok()) << left.status().ToString();
  EXPECT_EQ(left->camera, Camera::kLeft);
  EXPECT_EQ(left->sequence, 1u);
  EXPECT_EQ(left->stride * left->height, static_cast<int>(left->pixels.size()));
  EXPECT_GT(Mean(*left), 10.0);

  ASSERT_TRUE(store.SelectCamera(Camera::kRight).ok());
  auto right = store.Grab();
  ASSERT_TRUE(right.ok());
  EXPECT_EQ(right->camera, Camera::kRight);
  EXPECT_GT(Differing(*left, *right), 10000);  // another view of the head

  ASSERT_TRUE(store.SelectCamera(Camera::kLeft).ok());
  slide = 1;  // the reference cross: one line instead of the bricks
  auto cross = store.Grab();
  ASSERT_TRUE(cross.ok());
  EXPECT_LT(Mean(*cross), Mean(*left));
  EXPECT_GT(Differing(*left, *cross), 5000);
  slide = 0;  // nothing in place: ambient light only
  auto dark = store.Grab();
  ASSERT_TRUE(dark.ok());
  EXPECT_LT(Mean(*dark), Mean(*cross));
  EXPECT_LT(Mean(*dark), 0.5 * Mean(*left));

  slide = 2;
  ASSERT_TRUE(store.SetGain(64).ok());
  auto half = store.Grab();
  ASSERT_TRUE(half.ok());
  EXPECT_EQ(half->gain, 64);
  EXPECT_NEAR(Mean(*half), 0.5 * Mean(*left), 0.05 * Mean(*left));
  EXPECT_EQ(half->sequence, 5u);
}

TEST(SimulatedFramestore, BadCameraAndGainAreRefusedNamingThem) {
  auto store = SimulatedFramestore::Open(Quiet(nullptr));
  ASSERT_TRUE(store.ok());
  Status status = (*store)->SelectCamera(Camera::kThird);
  EXPECT_EQ(status.code(), ErrorCode::kInvalidArgument);
  EXPECT_NE(status.message().find("third"), std::string::npos) << status.message();
  status = (*store)->SetGain(1000);
  EXPECT_EQ(status.code(), ErrorCode::kInvalidArgument);
  EXPECT_NE(status.message().find("gain 1000"), std::string::npos) << status.message();
  EXPECT_EQ((*store)->camera(), Camera::kLeft);  // nothing changed
}

TEST(SimulatedFramestore, PacedGrabsComeOnTheCamerasFrameClock) {
  SimulatedFramestoreParams params = Quiet(nullptr);
  params.paced = true;
  auto store = SimulatedFramestore::Open(params);
  ASSERT_TRUE(store.ok());
  auto a = (*store)->Grab();
  auto b = (*store)->Grab();
  ASSERT_TRUE(a.ok() && b.ok());
  // Consecutive grabs are whole frame periods (40 ms) apart.
  const double gap_ms =
      std::chrono::duration<double, std::milli>(b->timestamps.exposed - a->timestamps.exposed)
          .count();
  EXPECT_NEAR(std::fmod(gap_ms + 1.0, 40.0), 1.0, 0.01) << gap_ms;
  EXPECT_LE(a->timestamps.requested, a->timestamps.exposed);
  EXPECT_LE(a->timestamps.exposed, a->timestamps.delivered);

  GrabOptions options;
  options.deadline = std::chrono::steady_clock::now();  // before any next frame
  auto late = (*store)->Grab(options);
  EXPECT_EQ(late.status().code(), ErrorCode::kDeadlineExceeded);
}

TEST(SimulatedFramestore, NoiseIsFreshInEveryFrame) {
  SimulatedFramestoreParams params = Quiet(nullptr);
  params.noise_sigma = 3.0;
  auto store = SimulatedFramestore::Open(params);
  ASSERT_TRUE(store.ok());
  auto a = (*store)->Grab();
  auto b = (*store)->Grab();
  ASSERT_TRUE(a.ok() && b.ok());
  EXPECT_NE(a->pixels, b->pixels);
  double sum = 0.0, sum2 = 0.0;
  int n = 0;
  for (std::size_t i = 0; i < a->pixels.size(); ++i) {
    if (a->pixels[i] < 20 || a->pixels[i] > 235) continue;  // clipped
    const double d = static_cast<double>(a->pixels[i]) - b->pixels[i];
    sum += d;
    sum2 += d * d;
    ++n;
  }
  const double sigma_diff = std::sqrt(sum2 / n - (sum / n) * (sum / n));
  EXPECT_NEAR(sigma_diff, 3.0 * std::sqrt(2.0), 0.6);
}

TEST(SimulatedFramestore, InvalidParamsNameTheField) {
  SimulatedFramestoreParams params;
  params.frame_rate_hz = 0.0;
  auto store = SimulatedFramestore::Open(params);
  ASSERT_FALSE(store.ok());
  EXPECT_EQ(store.status().code(), ErrorCode::kInvalidArgument);
  EXPECT_NE(store.status().message().find("frame_rate_hz"), std::string::npos);
}

}  // namespace
}  // namespace bsls::framestore
