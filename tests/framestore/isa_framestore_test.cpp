// The ISA framestore driver's real code against the register-level card
// emulator: thesis protocol, pixel round trip, camera/gain lines, and every
// fault ending in a clear error within bounded time.
#include "bsls/framestore/isa_framestore.h"

#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <cstdlib>
#include <opencv2/core.hpp>

#include "bsls/simulator/renderer.h"
#include "bsls/simulator/scene.h"
#include "emulated_card.h"

namespace bsls::framestore {
namespace {

using namespace std::chrono_literals;
using Clock = std::chrono::steady_clock;
using testing::Cameras;
using testing::FastParams;
using testing::MakePicture;
using testing::OpenEmulatedCard;

// The ADC keeps 192 codes (64..255) of 256 grey levels: one code is 4/3 grey
// level, so the thesis's stretch returns g within 2/3, i.e. within 1 after
// rounding. Exactly: g = 4k+2 comes back as 4k+3, every other g exactly.
constexpr int kRoundTripTolerance = 1;

// Errors must arrive this long at most after the timeout that causes them
// (polling granularity plus a loaded 2-core CI machine).
constexpr auto kErrorSlack = 1500ms;

std::shared_ptr<const VideoFrame> FromMat(const cv::Mat& image) {
  EXPECT_EQ(image.type(), CV_8UC1);
  return MakePicture([&image](int x, int y) { return image.at<std::uint8_t>(y, x); });
}

// The simulator's face seen by the left and right cameras (rendered once).
const Cameras& FaceCameras() {
  static const Cameras cameras = [] {
    simulator::RenderParams params;
    params.supersampling = 1;
    Cameras result;
    for (pattern::Side side : {pattern::Side::kLeft, pattern::Side::kRight}) {
      const simulator::Scene scene = simulator::ThesisScene(side, simulator::SurfaceKind::kFace);
      result.inputs[side == pattern::Side::kLeft ? 0 : 1] =
          FromMat(simulator::Render(scene, params).image);
    }
    return result;
  }();
  return cameras;
}

std::uint8_t Expected(std::uint8_t grey, int gain = isa::kUnityGainCode) {
  return ExtendBlackLevel(AdcCode(grey, gain));
}

testing::EmulatedCard OpenOrDie(const Cameras& cameras,
                                const IsaFramestoreParams& params = FastParams()) {
  testing::EmulatedCard card = OpenEmulatedCard(cameras, params);
  EXPECT_TRUE(card.open_status.ok()) << card.open_status.ToString();
  return card;
}

bool Contains(const std::string& text, const std::string& part) {
  return text.find(part) != std::string::npos;
}

TEST(ExtendBlackLevelTest, Thesis311Formula) {
  EXPECT_EQ(ExtendBlackLevel(64), 0);
  EXPECT_EQ(ExtendBlackLevel(0), 0);  // sync level clamps to black
  EXPECT_EQ(ExtendBlackLevel(63), 0);
  EXPECT_EQ(ExtendBlackLevel(255), 255);  // 191 * 1.333 = 254.6
  EXPECT_EQ(ExtendBlackLevel(67), 4);     // 3 * 4/3
  EXPECT_EQ(ExtendBlackLevel(65), 1);     // 1.33
  EXPECT_EQ(ExtendBlackLevel(66), 3);     // 2.67
  for (int code = 64; code < 256; ++code) {
    // The thesis's factor 1.333 and 4/3 agree on every code.
    const int thesis = static_cast<int>(std::lround((code - 64) * 1.333));
    EXPECT_EQ(ExtendBlackLevel(static_cast<std::uint8_t>(code)), std::min(255, thesis));
  }
}

TEST(ExtendBlackLevelTest, InvertsTheAdcWithinOneGreyLevel) {
  for (int g = 0; g < 256; ++g) {
    const int back = Expected(static_cast<std::uint8_t>(g));
    EXPECT_LE(std::abs(back - g), kRoundTripTolerance) << "grey " << g;
    EXPECT_EQ(back, g % 4 == 2 ? g + 1 : g) << "grey " << g;
  }
}

TEST(IsaFramestoreTest, OpenReportsCapabilities) {
  testing::EmulatedCard card = OpenOrDie(FaceCameras());
  ASSERT_TRUE(card.framestore);
  const Capabilities& caps = card.framestore->capabilities();
  EXPECT_EQ(caps.backend, "isa");
  EXPECT_TRUE(Contains(caps.device, "0x300")) << caps.device;
  EXPECT_EQ(caps.cameras, (std::vector<Camera>{Camera::kLeft, Camera::kRight}));
  EXPECT_EQ(caps.width, 512);
  EXPECT_EQ(caps.height, 512);
  EXPECT_EQ(caps.gain.min, 0);
  EXPECT_EQ(caps.gain.max, 255);
  EXPECT_EQ(caps.gain.nominal, 128);
  EXPECT_EQ(card.framestore->camera(), Camera::kLeft);
  EXPECT_EQ(card.framestore->gain(), 128);
  // Thesis 3.8: the 8255 holds 0x93; the register holds input 0, unity gain.
  EXPECT_EQ(card.card->lines().mode_word, 0x93);
  EXPECT_EQ(card.card->lines().video_input, 0);
  EXPECT_EQ(card.card->lines().gain_code, 128);
  EXPECT_EQ(card.card->lines().state, isa::PldState::kIdle);
}

TEST(IsaFramestoreTest, GrabReturnsTheFedFaceWithinQuantisation) {
  const Cameras& cameras = FaceCameras();
  testing::EmulatedCard card = OpenOrDie(cameras);
  ASSERT_TRUE(card.framestore);
  const EmulatorCounters before = card.card->counters();
  Result<GreyFrame> frame = card.framestore->Grab();
  ASSERT_TRUE(frame.ok()) << frame.status().ToString();
  EXPECT_EQ(frame->width, 512);
  EXPECT_EQ(frame->height, 512);
  EXPECT_EQ(frame->stride, 512);
  ASSERT_EQ(frame->pixels.size(), 512u * 512u);
  EXPECT_EQ(frame->camera, Camera::kLeft);
  EXPECT_EQ(frame->gain, 128);
  EXPECT_EQ(frame->sequence, 1u);

  const VideoFrame& fed = *cameras.inputs[0];
  int exact = 0, lit = 0;
  for (int y = 0; y < 512; ++y) {
    for (int x = 0; x < 512; ++x) {
      const std::uint8_t g = fed.pixels[y * 512 + x];
      ASSERT_EQ(frame->at(x, y), Expected(g)) << "x " << x << " y " << y;
      ASSERT_LE(std::abs(frame->at(x, y) - g), kRoundTripTolerance);
      exact += frame->at(x, y) == g;
      lit += g > 20;
    }
  }
  EXPECT_GT(lit, 512 * 512 / 10) << "the face render should light a good part of the frame";
  EXPECT_GT(exact, 512 * 512 * 7 / 10);  // 3 of 4 grey levels come back exactly

  const EmulatorCounters after = card.card->counters();
  EXPECT_EQ(after.downloads_completed - before.downloads_completed, 1);
  EXPECT_EQ(after.pairs_missed - before.pairs_missed, 0);
  EXPECT_EQ(after.pairs_presented - before.pairs_presented, isa::kPairsPerFrame);
}

TEST(IsaFramestoreTest, FieldsAreInterleavedOddRowsFirst) {
  // Even rows (odd field, video lines 1, 3, ...) and odd rows differ in level
  // and carry their row number, so any swap or shift shows.
  Cameras cameras;
  cameras.inputs[0] = MakePicture([](int x, int y) {
    return static_cast<std::uint8_t>(y % 2 == 0 ? (y / 2 + x) % 100 : 150 + (y / 2 + x) % 100);
  });
  testing::EmulatedCard card = OpenOrDie(cameras);
  ASSERT_TRUE(card.framestore);
  Result<GreyFrame> frame = card.framestore->Grab();
  ASSERT_TRUE(frame.ok()) << frame.status().ToString();
  for (int y = 0; y < 512; ++y) {
    for (int x = 0; x < 512; ++x) {
      ASSERT_EQ(frame->at(x, y), Expected(cameras.inputs[0]->pixels[y * 512 + x]))
          << "x " << x << " y " << y;
    }
  }
}

TEST(IsaFramestoreTest, CameraSelectAndGainReachTheCardLines) {
  const Cameras& cameras = FaceCameras();
  testing::EmulatedCard card = OpenOrDie(cameras);
  ASSERT_TRUE(card.framestore);
  ASSERT_TRUE(card.framestore->SelectCamera(Camera::kRight).ok());
  ASSERT_TRUE(card.framestore->SetGain(96).ok());
  EXPECT_EQ(card.card->lines().video_input, 1);
  EXPECT_EQ(card.card->lines().gain_code, 96);
  EXPECT_EQ(card.framestore->camera(), Camera::kRight);
  EXPECT_EQ(card.framestore->gain(), 96);

  Result<GreyFrame> frame = card.framestore->Grab();
  ASSERT_TRUE(frame.ok()) << frame.status().ToString();
  EXPECT_EQ(frame->camera, Camera::kRight);
  EXPECT_EQ(frame->gain, 96);
  const VideoFrame& right = *cameras.inputs[1];
  for (int i = 0; i < 512 * 512; ++i) {
    ASSERT_EQ(frame->pixels[i], Expected(right.pixels[i], 96)) << "pixel " << i;
  }
  ASSERT_TRUE(card.framestore->SelectCamera(Camera::kLeft).ok());
  EXPECT_EQ(card.card->lines().video_input, 0);
  EXPECT_EQ(card.card->lines().gain_code, 96);  // the gain is kept
}

TEST(IsaFramestoreTest, ConsecutiveGrabsCountAndKeepTimeOrder) {
  testing::EmulatedCard card = OpenOrDie(FaceCameras());
  ASSERT_TRUE(card.framestore);
  Result<GreyFrame> first = card.framestore->Grab();
  Result<GreyFrame> second = card.framestore->Grab();
  ASSERT_TRUE(first.ok() && second.ok());
  EXPECT_EQ(first->sequence, 1u);
  EXPECT_EQ(second->sequence, 2u);
  for (const GreyFrame* f : {&first.value(), &second.value()}) {
    EXPECT_LE(f->timestamps.requested, f->timestamps.exposed);
    EXPECT_LE(f->timestamps.exposed, f->timestamps.delivered);
  }
  EXPECT_LE(first->timestamps.delivered, second->timestamps.requested);
  EXPECT_EQ(first->pixels, second->pixels);
}

TEST(IsaFramestoreTest, RealTimeEmulatorClockGrabs) {
  SteadyEmulatorClock clock;
  IsaCardEmulatorParams card_params;
  card_params.clock = &clock;
  testing::EmulatedCard card = OpenEmulatedCard(FaceCameras(), FastParams(), {}, card_params);
  ASSERT_TRUE(card.open_status.ok()) << card.open_status.ToString();
  Result<GreyFrame> frame = card.framestore->Grab();
  ASSERT_TRUE(frame.ok()) << frame.status().ToString();
  EXPECT_EQ(frame->at(256, 256), Expected(FaceCameras().inputs[0]->pixels[256 * 512 + 256]));
}

// ---- rejected input ----------------------------------------------------------

TEST(IsaFramestoreTest, UnknownCameraIsRejected) {
  testing::EmulatedCard card = OpenOrDie(FaceCameras());
  ASSERT_TRUE(card.framestore);
  Status status = card.framestore->SelectCamera(Camera::kThird);
  EXPECT_EQ(status.code(), ErrorCode::kInvalidArgument);
  EXPECT_TRUE(Contains(status.message(), "camera third is not connected")) << status.message();
  EXPECT_TRUE(Contains(status.message(), "left, right")) << status.message();
  status = card.framestore->SelectCamera(static_cast<Camera>(7));
  EXPECT_EQ(status.code(), ErrorCode::kInvalidArgument);
  EXPECT_TRUE(Contains(status.message(), "camera 7")) << status.message();
  EXPECT_EQ(card.card->lines().video_input, 0);  // nothing reached the card
}

TEST(IsaFramestoreTest, GainOutOfRangeIsRejected) {
  testing::EmulatedCard card = OpenOrDie(FaceCameras());
  ASSERT_TRUE(card.framestore);
  for (int gain : {-1, 256, 100000}) {
    const Status status = card.framestore->SetGain(gain);
    EXPECT_EQ(status.code(), ErrorCode::kInvalidArgument);
    EXPECT_TRUE(Contains(status.message(), "gain " + std::to_string(gain) + " is outside 0..255"))
        << status.message();
  }
  EXPECT_EQ(card.card->lines().gain_code, 128);
  EXPECT_EQ(card.framestore->gain(), 128);
}

TEST(IsaFramestoreTest, BadBaseAddressesAreRejected) {
  struct Case {
    std::uint32_t base;
    const char* reason;
  };
  for (const Case& c : {Case{0x301, "not a multiple of 4"}, Case{0x060, "system-board range"},
                        Case{0x400, "above 0x3FC"}}) {
    IsaFramestoreParams params = FastParams();
    params.base = c.base;
    testing::EmulatedCard card = OpenEmulatedCard(FaceCameras(), params);
    EXPECT_EQ(card.open_status.code(), ErrorCode::kInvalidArgument);
    EXPECT_TRUE(Contains(card.open_status.message(), c.reason)) << card.open_status.message();
  }
}

TEST(IsaFramestoreTest, WrongBaseFindsNoCard) {
  IsaFramestoreParams params = FastParams();
  params.base = 0x310;                     // the emulated card's switches say 0x300
  const Cameras& cameras = FaceCameras();  // rendered outside the timed part
  const auto start = Clock::now();
  testing::EmulatedCard card = OpenEmulatedCard(cameras, params);
  EXPECT_LT(Clock::now() - start, kErrorSlack);
  EXPECT_EQ(card.open_status.code(), ErrorCode::kUnavailable);
  EXPECT_TRUE(Contains(card.open_status.message(), "no card answers at base 0x310"))
      << card.open_status.message();
  EXPECT_TRUE(Contains(card.open_status.message(), "port 0x313")) << card.open_status.message();
}

TEST(IsaFramestoreTest, InvalidParamsNameTheField) {
  IsaFramestoreParams params = FastParams();
  params.initial_camera = Camera::kThird;
  testing::EmulatedCard card = OpenEmulatedCard(FaceCameras(), params);
  EXPECT_EQ(card.open_status.code(), ErrorCode::kInvalidArgument);
  EXPECT_TRUE(Contains(card.open_status.message(), "initial_camera")) << card.open_status.message();
  params = FastParams();
  params.pair_timeout = 0ms;
  card = OpenEmulatedCard(FaceCameras(), params);
  EXPECT_TRUE(Contains(card.open_status.message(), "pair_timeout")) << card.open_status.message();
  params = FastParams();
  params.cameras = {Camera::kLeft, Camera::kLeft};
  card = OpenEmulatedCard(FaceCameras(), params);
  EXPECT_TRUE(Contains(card.open_status.message(), "twice")) << card.open_status.message();
}

// ---- faults: every wait ends in a clear error, in bounded time ---------------

TEST(IsaFramestoreTest, AbsentCardIsUnavailable) {
  EmulatorFaults faults;
  faults.absent = true;
  testing::EmulatedCard card = OpenEmulatedCard(FaceCameras(), FastParams(), faults);
  EXPECT_EQ(card.open_status.code(), ErrorCode::kUnavailable);
  EXPECT_TRUE(Contains(card.open_status.message(), "reads 0xFF after writing 0x93"));
}

TEST(IsaFramestoreTest, WrongControlWordReadbackIsUnavailable) {
  EmulatorFaults faults;
  faults.control_readback = 0x9B;
  testing::EmulatedCard card = OpenEmulatedCard(FaceCameras(), FastParams(), faults);
  EXPECT_EQ(card.open_status.code(), ErrorCode::kUnavailable);
  EXPECT_TRUE(Contains(card.open_status.message(), "reads back 0x9B after writing 0x93"))
      << card.open_status.message();
  // Without the read-back check (an NMOS 8255) the card opens.
  IsaFramestoreParams params = FastParams();
  params.verify_control_word = false;
  card = OpenEmulatedCard(FaceCameras(), params, faults);
  EXPECT_TRUE(card.open_status.ok()) << card.open_status.ToString();
}

TEST(IsaFramestoreTest, CardThatStopsBeforeTheFirstPulseTimesOut) {
  testing::EmulatedCard card = OpenOrDie(FaceCameras());
  ASSERT_TRUE(card.framestore);
  EmulatorFaults faults;
  faults.stall_after_pairs = 0;
  card.card->SetFaults(faults);
  const auto start = Clock::now();
  Result<GreyFrame> frame = card.framestore->Grab();
  EXPECT_LT(Clock::now() - start, FastParams().pair_timeout + kErrorSlack);
  ASSERT_FALSE(frame.ok());
  EXPECT_EQ(frame.status().code(), ErrorCode::kDeadlineExceeded);
  const std::string& message = frame.status().message();
  EXPECT_TRUE(Contains(message, "stopped answering")) << message;
  EXPECT_TRUE(Contains(message, "OE (port 0x302 bit 0) stayed high")) << message;
  EXPECT_TRUE(Contains(message, "pair 0 of 131072")) << message;
}

TEST(IsaFramestoreTest, CardThatStopsMidDownloadTimesOutAndRecovers) {
  testing::EmulatedCard card = OpenOrDie(FaceCameras());
  ASSERT_TRUE(card.framestore);
  EmulatorFaults faults;
  faults.stall_after_pairs = 70000;
  card.card->SetFaults(faults);
  Result<GreyFrame> frame = card.framestore->Grab();
  ASSERT_FALSE(frame.ok());
  EXPECT_EQ(frame.status().code(), ErrorCode::kDeadlineExceeded);
  EXPECT_TRUE(Contains(frame.status().message(), "pair 70000 of 131072 (field line 136"))
      << frame.status().message();
  // The card comes back: the next grab resynchronises and succeeds.
  card.card->SetFaults({});
  frame = card.framestore->Grab();
  ASSERT_TRUE(frame.ok()) << frame.status().ToString();
  EXPECT_EQ(frame->at(100, 300), Expected(FaceCameras().inputs[0]->pixels[300 * 512 + 100]));
}

TEST(IsaFramestoreTest, S3StuckAtOneFailsOpenWithinBound) {
  IsaFramestoreParams params = FastParams();
  params.idle_timeout = 200ms;
  EmulatorFaults faults;
  faults.s3_stuck_at = true;
  const Cameras& cameras = FaceCameras();  // rendered outside the timed part
  const auto start = Clock::now();
  testing::EmulatedCard card = OpenEmulatedCard(cameras, params, faults);
  EXPECT_LT(Clock::now() - start, params.idle_timeout + params.resync_quiet + kErrorSlack);
  EXPECT_EQ(card.open_status.code(), ErrorCode::kFailedPrecondition);
  EXPECT_TRUE(Contains(card.open_status.message(), "card not idle: S3 (port 0x302 bit 1)"))
      << card.open_status.message();
}

TEST(IsaFramestoreTest, S3StuckAtZeroFailsTheDigitiseWithinBound) {
  testing::EmulatedCard card = OpenOrDie(FaceCameras());
  ASSERT_TRUE(card.framestore);
  EmulatorFaults faults;
  faults.s3_stuck_at = false;
  card.card->SetFaults(faults);
  const auto start = Clock::now();
  Result<GreyFrame> frame = card.framestore->Grab();
  EXPECT_LT(Clock::now() - start, FastParams().digitise_timeout + 100ms + kErrorSlack);
  ASSERT_FALSE(frame.ok());
  EXPECT_EQ(frame.status().code(), ErrorCode::kDeadlineExceeded);
  const std::string& message = frame.status().message();
  EXPECT_TRUE(Contains(message, "digitise did not complete within 150 ms")) << message;
  EXPECT_TRUE(Contains(message, "S3 (port 0x302 bit 1) stayed 0 after SAMPLE (port 0x302 bit 4)"))
      << message;
  EXPECT_TRUE(Contains(message, "Video sync is present")) << message;
}

TEST(IsaFramestoreTest, NoVideoSaysWhichCamera) {
  Cameras cameras = FaceCameras();  // nothing on input 2
  IsaFramestoreParams params = FastParams();
  params.cameras = {Camera::kLeft, Camera::kRight, Camera::kThird};
  testing::EmulatedCard card = OpenOrDie(cameras, params);
  ASSERT_TRUE(card.framestore);
  ASSERT_TRUE(card.framestore->SelectCamera(Camera::kThird).ok());
  Result<GreyFrame> frame = card.framestore->Grab();
  ASSERT_FALSE(frame.ok());
  EXPECT_EQ(frame.status().code(), ErrorCode::kDeadlineExceeded);
  EXPECT_TRUE(Contains(frame.status().message(), "no video sync on camera third (input 2)"))
      << frame.status().message();
  // Back on a camera with video, grabbing works again.
  ASSERT_TRUE(card.framestore->SelectCamera(Camera::kLeft).ok());
  frame = card.framestore->Grab();
  EXPECT_TRUE(frame.ok()) << frame.status().ToString();
}

TEST(IsaFramestoreTest, CallerDeadlineIsHonoured) {
  testing::EmulatedCard card = OpenOrDie(FaceCameras());
  ASSERT_TRUE(card.framestore);
  Result<GreyFrame> frame = card.framestore->Grab({.deadline = Clock::now() - 1ms});
  EXPECT_EQ(frame.status().code(), ErrorCode::kDeadlineExceeded);
  EXPECT_TRUE(Contains(frame.status().message(), "before the grab")) << frame.status().message();

  EmulatorFaults faults;
  faults.stall_after_pairs = 10;
  card.card->SetFaults(faults);
  const auto start = Clock::now();
  frame = card.framestore->Grab({.deadline = Clock::now() + 5ms});
  EXPECT_LT(Clock::now() - start, kErrorSlack);
  EXPECT_EQ(frame.status().code(), ErrorCode::kDeadlineExceeded);
  EXPECT_TRUE(Contains(frame.status().message(), "caller's deadline")) << frame.status().message();
}

// A host preempted in the middle of a download: the card streams on without
// handshake (thesis 3.11), so pairs are lost; the driver must say so.
class PreemptedPortIo final : public PortIo {
 public:
  PreemptedPortIo(std::unique_ptr<IsaCardEmulator> card, ManualEmulatorClock* clock)
      : card_(std::move(card)), clock_(clock) {}
  std::uint8_t Inb(std::uint32_t port) override {
    if (port == isa::kDefaultBase + isa::kApin && ++apin_reads_ == preempt_at_) {
      clock_->Advance(card_->now() + 2ms - clock_->Now());  // 2 ms away: ~155 pairs pass
    }
    return card_->Inb(port);
  }
  void Outb(std::uint32_t port, std::uint8_t value) override { card_->Outb(port, value); }
  PortRange range() const override { return card_->range(); }
  Status status() const override { return card_->status(); }
  std::string Describe() const override { return "preempted emulator"; }
  void PreemptAtApinRead(std::int64_t n) {
    apin_reads_ = 0;
    preempt_at_ = n;
  }

 private:
  std::unique_ptr<IsaCardEmulator> card_;
  ManualEmulatorClock* clock_;
  std::int64_t apin_reads_ = 0, preempt_at_ = -1;
};

TEST(IsaFramestoreTest, MissedPulsesAreDataLossNotATornFrame) {
  ManualEmulatorClock clock;
  IsaCardEmulatorParams card_params;
  card_params.clock = &clock;
  auto io = std::make_unique<PreemptedPortIo>(
      std::make_unique<IsaCardEmulator>(card_params, FaceCameras().Source()), &clock);
  PreemptedPortIo* preempted = io.get();
  auto opened = IsaFramestore::Open(std::move(io), FastParams());
  ASSERT_TRUE(opened.ok()) << opened.status().ToString();
  preempted->PreemptAtApinRead(5000);
  Result<GreyFrame> frame = (*opened)->Grab();
  ASSERT_FALSE(frame.ok());
  EXPECT_EQ(frame.status().code(), ErrorCode::kDataLoss);
  EXPECT_TRUE(Contains(frame.status().message(), "missed OE pulses")) << frame.status().message();
  // A retry without preemption works.
  frame = (*opened)->Grab();
  EXPECT_TRUE(frame.ok()) << frame.status().ToString();
}

}  // namespace
}  // namespace bsls::framestore
