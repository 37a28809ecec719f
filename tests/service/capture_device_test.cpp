// bslsd's capture thread over the USB framestore's real code and the model
// of its firmware: a device that is unplugged or stops answering gives
// UNAVAILABLE or DEADLINE_EXCEEDED within the caller's deadline (never a
// hang), is reported lost once and found again once, and grabs go on after it
// comes back; the thread keeps ticking (the watchdog) throughout.
#include "bsls/service/capture_device.h"

#include <gtest/gtest.h>

#include <atomic>
#include <condition_variable>
#include <memory>
#include <mutex>
#include <thread>

#include "bsls/framestore/usb_device_model.h"
#include "bsls/framestore/usb_framestore.h"
#include "bsls/slides/emulated_slide_changer.h"

namespace bsls::service {
namespace {

using std::chrono::milliseconds;

std::shared_ptr<const framestore::VideoFrame> Grey(int input) {
  auto picture = std::make_shared<framestore::VideoFrame>();
  picture->pixels.assign(static_cast<std::size_t>(picture->width) * picture->height,
                         static_cast<std::uint8_t>(60 + 40 * input));
  return picture;
}

struct Events {
  std::mutex mutex;
  std::vector<std::string> lost, found;
  std::atomic<int> ticks{0};
};

class CaptureDeviceOverUsb : public ::testing::Test {
 protected:
  void SetUp() override {
    auto model = std::make_unique<framestore::UsbDeviceModel>(
        [](int input, std::int64_t) { return input <= 1 ? Grey(input) : nullptr; });
    model_ = model.get();
    framestore::UsbFramestoreParams params;
    params.frame_timeout = milliseconds(300);
    params.chunk_timeout = milliseconds(200);
    auto store = framestore::UsbFramestore::Open(std::move(model), params);
    ASSERT_TRUE(store.ok()) << store.status().ToString();
    DeviceCallbacks callbacks;
    callbacks.tick = [this] { ++events_.ticks; };
    callbacks.lost = [this](const std::string& reason) {
      std::lock_guard lock(events_.mutex);
      events_.lost.push_back(reason);
    };
    callbacks.found = [this](const std::string& device) {
      std::lock_guard lock(events_.mutex);
      events_.found.push_back(device);
    };
    device_ = std::make_unique<CaptureDevice>(std::move(store).value(), std::move(callbacks));
  }

  Clock::time_point In(milliseconds ms) { return Clock::now() + ms; }

  framestore::UsbDeviceModel* model_ = nullptr;
  Events events_;
  std::unique_ptr<CaptureDevice> device_;
};

TEST_F(CaptureDeviceOverUsb, UnpluggedIsUnavailableLostOnceAndFoundAgain) {
  ASSERT_TRUE(device_->Grab(GrabSides::kBoth, In(milliseconds(5000))).ok());
  model_->Unplug();
  for (int i = 0; i < 3; ++i) {
    auto grab = device_->Grab(GrabSides::kLeft, In(milliseconds(5000)));
    ASSERT_FALSE(grab.ok());
    EXPECT_EQ(grab.status().code(), ErrorCode::kUnavailable) << grab.status().ToString();
  }
  DeviceSnapshot snapshot = device_->Snapshot();
  EXPECT_FALSE(snapshot.available);
  EXPECT_NE(snapshot.availability_reason.find("unplugged"), std::string::npos)
      << snapshot.availability_reason;
  model_->Replug();
  auto grab = device_->Grab(GrabSides::kBoth, In(milliseconds(5000)));
  ASSERT_TRUE(grab.ok()) << grab.status().ToString();
  ASSERT_EQ(grab->size(), 2u);
  EXPECT_EQ((*grab)[1].at(10, 10), 100);  // the right camera's picture, not the left's
  EXPECT_TRUE(device_->Snapshot().available);
  std::lock_guard lock(events_.mutex);
  EXPECT_EQ(events_.lost.size(), 1u);  // once per loss, not once per failed grab
  EXPECT_EQ(events_.found.size(), 1u);
}

TEST_F(CaptureDeviceOverUsb, ASilentDeviceEndsInDeadlineExceededAndTheThreadGoesOn) {
  model_->SetFaults({.silent = true});
  // The caller's deadline is shorter than the device's own timeout: it wins.
  auto start = Clock::now();
  auto grab = device_->Grab(GrabSides::kLeft, In(milliseconds(100)));
  EXPECT_EQ(grab.status().code(), ErrorCode::kDeadlineExceeded) << grab.status().ToString();
  EXPECT_LT(Clock::now() - start, milliseconds(100 + 500));
  // With a long deadline the device's own timeout ends it.
  start = Clock::now();
  grab = device_->Grab(GrabSides::kLeft, In(milliseconds(10000)));
  EXPECT_EQ(grab.status().code(), ErrorCode::kDeadlineExceeded) << grab.status().ToString();
  EXPECT_LT(Clock::now() - start, milliseconds(300 + 2000));
  EXPECT_FALSE(device_->Snapshot().available);
  const int ticks = events_.ticks;
  model_->SetFaults({});
  grab = device_->Grab(GrabSides::kRight, In(milliseconds(5000)));
  ASSERT_TRUE(grab.ok()) << grab.status().ToString();
  EXPECT_TRUE(device_->Snapshot().available);
  // The loop goes on passing (idle passes come every 500 ms at the latest).
  const auto until = Clock::now() + milliseconds(3000);
  while (events_.ticks <= ticks && Clock::now() < until)
    std::this_thread::sleep_for(milliseconds(10));
  EXPECT_GT(events_.ticks, ticks);
}

// The slides a grab takes (contracts section 1): with a brick slide in
// place both sides are grabbed each under its own slide (2, then 3, which
// stays in) and the capture records slide 0; under the cross both cameras
// see the cross; one side, or no slide controller, keeps the slide there.
TEST_F(CaptureDeviceOverUsb, AGrabOfBothSidesPutsEachSidesSlideInPlace) {
  slides::SlideControllerConfig config;
  config.pulse = milliseconds(12);
  config.settle = milliseconds(20);
  config.change_timeout = milliseconds(1000);
  config.emulated_travel = milliseconds(30);
  auto opened =
      slides::SlideController::Open(std::make_unique<slides::EmulatedSlideChanger>(config), config);
  ASSERT_TRUE(opened.ok()) << opened.status().ToString();
  slides::SlideController& slides = **opened;

  ASSERT_TRUE(slides.ChangeTo(2, In(milliseconds(5000))).ok());
  auto both = device_->GrabWithSlides(GrabSides::kBoth, &slides, In(milliseconds(10000)));
  ASSERT_TRUE(both.ok()) << both.status().ToString();
  ASSERT_EQ(both->frames.size(), 2u);
  EXPECT_EQ(both->frames[0].camera, framestore::Camera::kLeft);
  EXPECT_EQ(both->frames[0].at(5, 5), 60);
  EXPECT_EQ(both->frames[1].camera, framestore::Camera::kRight);
  EXPECT_EQ(both->frames[1].at(5, 5), 100);
  EXPECT_EQ(both->slide, 0);
  EXPECT_EQ(slides.State().slide, 3);

  auto one = device_->GrabWithSlides(GrabSides::kLeft, &slides, In(milliseconds(5000)));
  ASSERT_TRUE(one.ok()) << one.status().ToString();
  EXPECT_EQ(one->frames.size(), 1u);
  EXPECT_EQ(one->slide, 3);  // one side keeps the slide in place

  ASSERT_TRUE(slides.ChangeTo(1, In(milliseconds(5000))).ok());
  auto cross = device_->GrabWithSlides(GrabSides::kBoth, &slides, In(milliseconds(5000)));
  ASSERT_TRUE(cross.ok()) << cross.status().ToString();
  EXPECT_EQ(cross->frames.size(), 2u);
  EXPECT_EQ(cross->slide, 1);
  EXPECT_EQ(slides.State().slide, 1);

  auto bare = device_->GrabWithSlides(GrabSides::kBoth, nullptr, In(milliseconds(5000)));
  ASSERT_TRUE(bare.ok()) << bare.status().ToString();
  EXPECT_EQ(bare->frames.size(), 2u);
  EXPECT_EQ(bare->slide, 0);
}

// A preview as a stream uses it: woken by the capture thread after each
// frame, it takes the newest.
class PreviewReader {
 public:
  explicit PreviewReader(CaptureDevice& device)
      : preview_(device.OpenPreview([this] {
          {
            std::lock_guard lock(mutex_);
            ++wakes_;
          }
          woken_.notify_all();
        })) {}
  // The next frame newer than the last one taken, waiting up to `timeout`.
  std::shared_ptr<const framestore::GreyFrame> Next(milliseconds timeout) {
    const auto until = Clock::now() + timeout;
    for (;;) {
      std::uint64_t dropped = 0;
      if (auto frame = preview_->Take(&dropped)) return frame;
      std::unique_lock lock(mutex_);
      const int seen = wakes_;
      if (!woken_.wait_until(lock, until, [&] { return wakes_ != seen; })) return nullptr;
    }
  }

 private:
  std::mutex mutex_;
  std::condition_variable woken_;
  int wakes_ = 0;
  std::unique_ptr<CaptureDevice::Preview> preview_;  // last: its callback uses the members above
};

TEST_F(CaptureDeviceOverUsb, PreviewsRideOutADamagedFrame) {
  PreviewReader preview(*device_);
  ASSERT_NE(preview.Next(milliseconds(5000)), nullptr);
  model_->SetFaults({.corrupt_payload = true});
  // The damaged frame is never published; the next good one is.
  for (int i = 0; i < 3; ++i) {
    auto frame = preview.Next(milliseconds(5000));
    ASSERT_NE(frame, nullptr);
    EXPECT_EQ(frame->at(5, 5), 60);
  }
  EXPECT_TRUE(device_->Snapshot().available);  // damage is not a lost device
}

}  // namespace
}  // namespace bsls::service
