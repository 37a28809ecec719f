// The USB framestore backend (docs/usb-framestore.md) over a UsbTransport:
// LibusbTransport on hardware, UsbDeviceModel in the tests. Every wait is
// bounded; damaged frames are DATA_LOSS and the stream is resynchronised;
// an unplugged device is UNAVAILABLE, and after it comes back (hotplug, or
// the next grab finding it) the selected camera and gain are restored and
// grabs go on without restarting the daemon.
//
// Thread-safety: as the Framestore interface; the hotplug callback only sets
// a flag that the framestore's own thread acts on.
#ifndef BSLS_FRAMESTORE_USB_FRAMESTORE_H_
#define BSLS_FRAMESTORE_USB_FRAMESTORE_H_

#include <atomic>
#include <chrono>
#include <memory>

#include "bsls/framestore/framestore.h"
#include "bsls/framestore/usb_transport.h"

namespace bsls::framestore {

struct UsbFramestoreParams {
  std::chrono::milliseconds control_timeout{500};
  std::chrono::milliseconds frame_timeout{1000};  // GRAB to the frame's header
  std::chrono::milliseconds chunk_timeout{500};   // each payload transfer
  std::size_t chunk_bytes = 64 * 1024;            // bulk transfer size
  int stale_frames_max = 4;  // frames with a wrong tag dropped before giving up
};

class UsbFramestore final : public Framestore {
 public:
  // Opens the transport's device, reads GET_INFO and sets the first camera
  // and the nominal gain. kUnavailable when the device is not there.
  static Result<std::unique_ptr<UsbFramestore>> Open(std::unique_ptr<UsbTransport> transport,
                                                     const UsbFramestoreParams& params = {});
  ~UsbFramestore() override;

  const Capabilities& capabilities() const override { return capabilities_; }
  Status SelectCamera(Camera camera) override;
  Status SetGain(int gain) override;
  Camera camera() const override { return camera_; }
  int gain() const override { return gain_; }
  Result<GreyFrame> Grab(const GrabOptions& options = {}) override;

 private:
  UsbFramestore(std::unique_ptr<UsbTransport> transport, const UsbFramestoreParams& params);
  // Reads GET_INFO into capabilities_ (checking it against the old one on reopen).
  Status ReadInfo(bool reopening);
  // Makes sure the device is open and configured (after an unplug).
  Status EnsureOpen();
  // One vendor request without data; notes an unplug.
  Status Send(std::uint8_t request, std::uint16_t value);
  // Reads and drops whatever is left on bulk IN after an error.
  void Resynchronise();
  Status Transfer(Status status);  // notes unplugs

  std::unique_ptr<UsbTransport> transport_;
  UsbFramestoreParams params_;
  Capabilities capabilities_;
  Camera camera_ = Camera::kLeft;
  int gain_ = 0;
  std::uint64_t sequence_ = 0;
  std::uint16_t tag_ = 0;
  std::atomic<bool> replugged_{false};
  bool lost_ = false;
};

}  // namespace bsls::framestore

#endif  // BSLS_FRAMESTORE_USB_FRAMESTORE_H_
