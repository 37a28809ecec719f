// The USB framestore's firmware as docs/usb-framestore.md specifies it, at
// the transport level: control requests, the bulk-IN frame stream with header
// and CRCs, hotplug. Fed with pictures per camera (a VideoSource, as the ISA
// card emulator), it is what UsbFramestore's real code runs against in the
// tests, with faults to inject: unplug/replug, corrupted payload or header,
// short transfers, a stalled endpoint, a device that stops answering, and a
// stale frame left in the endpoint.
#ifndef BSLS_FRAMESTORE_USB_DEVICE_MODEL_H_
#define BSLS_FRAMESTORE_USB_DEVICE_MODEL_H_

#include <deque>
#include <mutex>

#include "bsls/framestore/isa_card_emulator.h"
#include "bsls/framestore/usb_transport.h"

namespace bsls::framestore {

// What the next grab (or the device from now on) does wrong.
struct UsbDeviceFaults {
  bool corrupt_payload = false;  // next frame: one payload byte flipped after the CRC
  bool corrupt_header = false;   // next frame: one header byte flipped after its CRC
  bool short_frame = false;      // next frame: the last 1000 payload bytes never come
  bool stall = false;            // next frame: bulk IN stalls until ClearHalt
  bool silent = false;           // from now on: GRAB is accepted, nothing is ever sent
  bool stale_frame = false;      // next grab: an old frame (wrong tag) comes first
};

class UsbDeviceModel final : public UsbTransport {
 public:
  // A device with `cameras` (mask bits 0..2) showing `source`'s pictures.
  UsbDeviceModel(VideoSource source, std::uint8_t camera_mask = 0b011);

  Status Open() override;
  void Close() override;
  bool IsOpen() const override;
  Status ControlOut(std::uint8_t request, std::uint16_t value,
                    std::chrono::milliseconds timeout) override;
  Result<std::vector<std::uint8_t>> ControlIn(std::uint8_t request, std::uint16_t value,
                                              std::uint16_t length,
                                              std::chrono::milliseconds timeout) override;
  Result<std::size_t> BulkIn(std::uint8_t* buffer, std::size_t length,
                             std::chrono::milliseconds timeout) override;
  Status ClearHalt() override;
  void SetHotplugCallback(std::function<void(bool arrived)> callback) override;
  std::string Describe() const override { return "USB framestore model 1209:b515"; }

  // The cable: pulled (every transfer fails NO_DEVICE, the host is told) or put back.
  void Unplug();
  void Replug();
  void SetFaults(const UsbDeviceFaults& faults);
  // What the host last set, as the device sees it.
  int camera() const;
  int gain() const;
  int grabs() const;  // GRAB requests accepted

  static constexpr int kGainMin = 0;
  static constexpr int kGainMax = 1023;
  static constexpr int kGainNominal = 256;

 private:
  std::vector<std::uint8_t> MakeFrame(std::uint16_t tag, int camera);  // mutex_ held
  void Notify(bool arrived);

  VideoSource source_;
  std::uint8_t camera_mask_;
  mutable std::mutex mutex_;
  bool plugged_ = true;
  bool open_ = false;
  bool halted_ = false;
  int camera_ = 0;
  int gain_ = kGainNominal;
  std::uint32_t sequence_ = 0;
  int grabs_ = 0;
  std::deque<std::uint8_t> endpoint_;  // bytes waiting on bulk IN
  UsbDeviceFaults faults_;
  std::function<void(bool)> hotplug_;
};

}  // namespace bsls::framestore

#endif  // BSLS_FRAMESTORE_USB_DEVICE_MODEL_H_
