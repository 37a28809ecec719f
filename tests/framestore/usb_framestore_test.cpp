// The USB framestore's real code (UsbFramestore) against the model of its
// firmware (docs/usb-framestore.md): frames arrive exactly, camera and gain
// reach the device, damaged and stale frames are caught and the stream
// resynchronised, a silent device times out, an unplugged one is UNAVAILABLE
// and comes back with the operator's settings; and libusb itself, with no
// device present, fails cleanly.
#include "bsls/framestore/usb_framestore.h"

#include <gtest/gtest.h>

#include "bsls/framestore/usb_device_model.h"

namespace bsls::framestore {
namespace {

using std::chrono::milliseconds;

// Camera c shows grey (x + y + 50 c) mod 256 (distinct per camera and pixel).
std::shared_ptr<const VideoFrame> Picture(int camera) {
  auto picture = std::make_shared<VideoFrame>();
  picture->pixels.resize(static_cast<std::size_t>(picture->width) * picture->height);
  for (int y = 0; y < picture->height; ++y)
    for (int x = 0; x < picture->width; ++x)
      picture->pixels[static_cast<std::size_t>(y) * picture->width + x] =
          static_cast<std::uint8_t>((x + y + 50 * camera) % 200);
  return picture;
}

struct Rig {
  UsbDeviceModel* device = nullptr;
  std::unique_ptr<UsbFramestore> store;
};

UsbFramestoreParams Fast() {
  UsbFramestoreParams params;
  params.frame_timeout = milliseconds(200);
  params.chunk_timeout = milliseconds(100);
  return params;
}

Rig Open() {
  auto device = std::make_unique<UsbDeviceModel>(
      [](int input, std::int64_t) { return input <= 1 ? Picture(input) : nullptr; });
  Rig rig;
  rig.device = device.get();
  auto opened = UsbFramestore::Open(std::move(device), Fast());
  EXPECT_TRUE(opened.ok()) << opened.status().ToString();
  if (opened.ok()) rig.store = std::move(opened).value();
  return rig;
}

bool SameAsPicture(const GreyFrame& frame, int camera, int gain = UsbDeviceModel::kGainNominal) {
  const auto picture = Picture(camera);
  for (int y = 0; y < frame.height; ++y)
    for (int x = 0; x < frame.width; ++x) {
      const int expected = std::min(
          255, picture->pixels[y * picture->width + x] * gain / UsbDeviceModel::kGainNominal);
      if (frame.at(x, y) != expected) return false;
    }
  return true;
}

TEST(UsbFramestore, OpenReadsWhatTheDeviceIs) {
  Rig rig = Open();
  ASSERT_TRUE(rig.store);
  const Capabilities& caps = rig.store->capabilities();
  EXPECT_EQ(caps.backend, "usb");
  EXPECT_NE(caps.device.find("model-1.0"), std::string::npos) << caps.device;
  EXPECT_EQ(caps.cameras, (std::vector<Camera>{Camera::kLeft, Camera::kRight}));
  EXPECT_EQ(caps.width, 512);
  EXPECT_EQ(caps.gain.nominal, UsbDeviceModel::kGainNominal);
}

TEST(UsbFramestore, GrabsReturnTheDevicesPicturesExactly) {
  Rig rig = Open();
  ASSERT_TRUE(rig.store);
  auto left = rig.store->Grab();
  ASSERT_TRUE(left.ok()) << left.status().ToString();
  EXPECT_EQ(left->camera, Camera::kLeft);
  EXPECT_TRUE(SameAsPicture(*left, 0));
  ASSERT_TRUE(rig.store->SelectCamera(Camera::kRight).ok());
  ASSERT_TRUE(rig.store->SetGain(128).ok());
  EXPECT_EQ(rig.device->camera(), 1);
  EXPECT_EQ(rig.device->gain(), 128);
  auto right = rig.store->Grab();
  ASSERT_TRUE(right.ok());
  EXPECT_EQ(right->camera, Camera::kRight);
  EXPECT_EQ(right->gain, 128);
  EXPECT_TRUE(SameAsPicture(*right, 1, 128));
  EXPECT_EQ(right->sequence, 2u);
  EXPECT_LE(right->timestamps.requested, right->timestamps.exposed);
  EXPECT_LE(right->timestamps.exposed, right->timestamps.delivered);
}

TEST(UsbFramestore, BadCameraAndGainAreRefusedBeforeTheDevice) {
  Rig rig = Open();
  ASSERT_TRUE(rig.store);
  Status status = rig.store->SelectCamera(Camera::kThird);
  EXPECT_EQ(status.code(), ErrorCode::kInvalidArgument);
  EXPECT_NE(status.message().find("third"), std::string::npos);
  status = rig.store->SetGain(5000);
  EXPECT_EQ(status.code(), ErrorCode::kInvalidArgument);
  EXPECT_NE(status.message().find("gain 5000"), std::string::npos);
  EXPECT_EQ(rig.device->camera(), 0);
}

TEST(UsbFramestore, DamagedFramesAreDataLossAndTheNextGrabIsClean) {
  Rig rig = Open();
  ASSERT_TRUE(rig.store);
  for (const UsbDeviceFaults& fault :
       {UsbDeviceFaults{.corrupt_payload = true}, UsbDeviceFaults{.corrupt_header = true},
        UsbDeviceFaults{.short_frame = true}, UsbDeviceFaults{.stall = true}}) {
    rig.device->SetFaults(fault);
    auto bad = rig.store->Grab();
    ASSERT_FALSE(bad.ok());
    EXPECT_EQ(bad.status().code(), ErrorCode::kDataLoss) << bad.status().ToString();
    auto good = rig.store->Grab();
    ASSERT_TRUE(good.ok()) << good.status().ToString();
    EXPECT_TRUE(SameAsPicture(*good, 0));
  }
}

TEST(UsbFramestore, AStaleFrameIsDroppedAndTheRightOneReturned) {
  Rig rig = Open();
  ASSERT_TRUE(rig.store);
  rig.device->SetFaults({.stale_frame = true});
  auto frame = rig.store->Grab();
  ASSERT_TRUE(frame.ok()) << frame.status().ToString();
  EXPECT_TRUE(SameAsPicture(*frame, 0));
}

TEST(UsbFramestore, ASilentDeviceTimesOutWithinBound) {
  Rig rig = Open();
  ASSERT_TRUE(rig.store);
  rig.device->SetFaults({.silent = true});
  const auto start = std::chrono::steady_clock::now();
  auto frame = rig.store->Grab();
  const auto took = std::chrono::steady_clock::now() - start;
  EXPECT_EQ(frame.status().code(), ErrorCode::kDeadlineExceeded) << frame.status().ToString();
  EXPECT_LT(took, milliseconds(200 + 1500));  // frame timeout + the resynchronising drain
  // The caller's deadline comes first when it is sooner.
  GrabOptions options;
  options.deadline = std::chrono::steady_clock::now() + milliseconds(30);
  const auto start2 = std::chrono::steady_clock::now();
  frame = rig.store->Grab(options);
  EXPECT_EQ(frame.status().code(), ErrorCode::kDeadlineExceeded);
  EXPECT_LT(std::chrono::steady_clock::now() - start2, milliseconds(30 + 1500));
  rig.device->SetFaults({});
  EXPECT_TRUE(rig.store->Grab().ok());
}

TEST(UsbFramestore, UnplugIsUnavailableAndReplugRestoresCameraAndGain) {
  Rig rig = Open();
  ASSERT_TRUE(rig.store);
  ASSERT_TRUE(rig.store->SelectCamera(Camera::kRight).ok());
  ASSERT_TRUE(rig.store->SetGain(300).ok());
  rig.device->Unplug();
  auto frame = rig.store->Grab();
  EXPECT_EQ(frame.status().code(), ErrorCode::kUnavailable);
  EXPECT_NE(frame.status().message().find("unplugged"), std::string::npos)
      << frame.status().ToString();
  frame = rig.store->Grab();  // still gone: still a clear error, no hang
  EXPECT_EQ(frame.status().code(), ErrorCode::kUnavailable);
  rig.device->Replug();  // the firmware starts at camera 0, nominal gain
  frame = rig.store->Grab();
  ASSERT_TRUE(frame.ok()) << frame.status().ToString();
  EXPECT_EQ(rig.device->camera(), 1);
  EXPECT_EQ(rig.device->gain(), 300);
  EXPECT_EQ(frame->camera, Camera::kRight);
  EXPECT_TRUE(SameAsPicture(*frame, 1, 300));
}

TEST(UsbFramestore, OpenWithoutTheDeviceIsUnavailable) {
  auto device = std::make_unique<UsbDeviceModel>(nullptr);
  device->Unplug();
  auto store = UsbFramestore::Open(std::move(device), Fast());
  ASSERT_FALSE(store.ok());
  EXPECT_EQ(store.status().code(), ErrorCode::kUnavailable);
}

TEST(LibusbTransport, NoDevicePresentIsACleanError) {
  auto transport = OpenLibusbTransport();
  if (!transport.ok()) {
    // No usbfs here (a container): libusb itself cannot start, and says so.
    EXPECT_EQ(transport.status().code(), ErrorCode::kUnavailable) << transport.status().ToString();
    return;
  }
  const Status status = (*transport)->Open();
  EXPECT_FALSE(status.ok());
  EXPECT_TRUE(status.code() == ErrorCode::kUnavailable ||
              status.code() == ErrorCode::kPermissionDenied)
      << status.ToString();
  EXPECT_NE(status.message().find("1209:b515"), std::string::npos) << status.message();
  EXPECT_FALSE((*transport)->IsOpen());
}

}  // namespace
}  // namespace bsls::framestore
