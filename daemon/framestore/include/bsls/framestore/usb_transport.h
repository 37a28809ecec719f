// The lowest layer of the USB framestore (docs/usb-framestore.md): control and
// bulk transfers to one device and its hotplug. LibusbTransport is the real
// one (libusb-1.0); UsbDeviceModel (usb_device_model.h) answers as the
// firmware must, so UsbFramestore's real code runs in the tests.
//
// Thread-safety: transfers come from the framestore's one thread; the
// hotplug callback may come from another thread (libusb's event thread).
#ifndef BSLS_FRAMESTORE_USB_TRANSPORT_H_
#define BSLS_FRAMESTORE_USB_TRANSPORT_H_

#include <chrono>
#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "bsls/common/status.h"

namespace bsls::framestore {

namespace usb {
inline constexpr std::uint16_t kVendorId = 0x1209;
inline constexpr std::uint16_t kProductId = 0xB515;
inline constexpr int kInterface = 0;
inline constexpr std::uint8_t kBulkIn = 0x81;
inline constexpr std::uint8_t kRequestOut = 0x41;  // vendor, interface, host to device
inline constexpr std::uint8_t kRequestIn = 0xC1;   // vendor, interface, device to host
enum Request : std::uint8_t {
  kGetInfo = 0x01,
  kSelectCamera = 0x02,
  kSetGain = 0x03,
  kGrab = 0x04,
  kGetStatus = 0x05,
};
inline constexpr std::size_t kInfoBytes = 32;
inline constexpr std::size_t kHeaderBytes = 48;
inline constexpr std::uint32_t kMagic = 0x464C5342;  // "BSLF" little-endian
}  // namespace usb

class UsbTransport {
 public:
  virtual ~UsbTransport() = default;

  // Finds the device and claims its interface. kUnavailable when it is not
  // plugged in, kPermissionDenied when it may not be opened.
  virtual Status Open() = 0;
  // Releases the device (after an unplug: forgets it).
  virtual void Close() = 0;
  // True between a successful Open and Close.
  virtual bool IsOpen() const = 0;
  // A vendor request without data.
  virtual Status ControlOut(std::uint8_t request, std::uint16_t value,
                            std::chrono::milliseconds timeout) = 0;
  // A vendor request reading up to `length` bytes.
  virtual Result<std::vector<std::uint8_t>> ControlIn(std::uint8_t request, std::uint16_t value,
                                                      std::uint16_t length,
                                                      std::chrono::milliseconds timeout) = 0;
  // Reads up to `length` bytes from bulk IN; the count actually read.
  virtual Result<std::size_t> BulkIn(std::uint8_t* buffer, std::size_t length,
                                     std::chrono::milliseconds timeout) = 0;
  // Clears a halt (stall) of bulk IN.
  virtual Status ClearHalt() = 0;
  // Called with true when the device arrives and false when it leaves.
  virtual void SetHotplugCallback(std::function<void(bool arrived)> callback) = 0;
  // "USB 1209:b515 bus 1 device 4" for messages.
  virtual std::string Describe() const = 0;
};

// libusb-1.0's transport to the first device with `vendor`:`product`, with a
// hotplug event thread when the platform has hotplug. kUnavailable when
// libusb cannot start (no usbfs in a container, say).
Result<std::unique_ptr<UsbTransport>> OpenLibusbTransport(std::uint16_t vendor = usb::kVendorId,
                                                          std::uint16_t product = usb::kProductId);

}  // namespace bsls::framestore

#endif  // BSLS_FRAMESTORE_USB_TRANSPORT_H_
