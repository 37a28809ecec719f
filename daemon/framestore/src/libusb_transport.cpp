// UsbTransport on libusb-1.0: the code that runs against a real device.
#include <libusb.h>

#include <atomic>
#include <mutex>
#include <thread>

#include "bsls/framestore/usb_transport.h"

namespace bsls::framestore {

namespace {

// libusb's error as a Status naming what was being done.
Status FromLibusb(int error, const std::string& what) {
  const std::string reason = what + ": " + libusb_strerror(static_cast<libusb_error>(error));
  switch (error) {
    case LIBUSB_ERROR_NO_DEVICE:
      return {ErrorCode::kUnavailable, "USB framestore unplugged (" + reason + ")"};
    case LIBUSB_ERROR_NOT_FOUND:
      return {ErrorCode::kUnavailable, reason};
    case LIBUSB_ERROR_TIMEOUT:
      return {ErrorCode::kDeadlineExceeded, reason};
    case LIBUSB_ERROR_PIPE:
    case LIBUSB_ERROR_OVERFLOW:
      return {ErrorCode::kDataLoss, reason};
    case LIBUSB_ERROR_ACCESS:
      return {ErrorCode::kPermissionDenied,
              reason + " (the udev rule 70-bsls.rules gives the bsls group the device)"};
    case LIBUSB_ERROR_BUSY:
      return {ErrorCode::kFailedPrecondition, reason + " (another program has the interface)"};
    case LIBUSB_ERROR_INVALID_PARAM:
      return {ErrorCode::kInvalidArgument, reason};
    default:
      return {ErrorCode::kUnavailable, reason};
  }
}

unsigned Ms(std::chrono::milliseconds timeout) {
  return static_cast<unsigned>(std::max<std::int64_t>(1, timeout.count()));
}

class LibusbTransport final : public UsbTransport {
 public:
  LibusbTransport(libusb_context* context, std::uint16_t vendor, std::uint16_t product)
      : context_(context), vendor_(vendor), product_(product) {
    if (libusb_has_capability(LIBUSB_CAP_HAS_HOTPLUG)) {
      const int rc = libusb_hotplug_register_callback(
          context_,
          static_cast<libusb_hotplug_event>(LIBUSB_HOTPLUG_EVENT_DEVICE_ARRIVED |
                                            LIBUSB_HOTPLUG_EVENT_DEVICE_LEFT),
          LIBUSB_HOTPLUG_NO_FLAGS, vendor_, product_, LIBUSB_HOTPLUG_MATCH_ANY, &OnHotplug, this,
          &hotplug_);
      if (rc == LIBUSB_SUCCESS) {
        events_ = std::thread([this] {
          while (!stopping_) {
            timeval tv{0, 200000};
            libusb_handle_events_timeout_completed(context_, &tv, nullptr);
          }
        });
      }
    }
  }
  ~LibusbTransport() override {
    stopping_ = true;
    if (events_.joinable()) {
      libusb_hotplug_deregister_callback(context_, hotplug_);  // wakes the event loop
      events_.join();
    }
    Close();
    libusb_exit(context_);
  }

  Status Open() override {
    if (handle_ != nullptr) return {};
    libusb_device_handle* handle = nullptr;
    libusb_device** list = nullptr;
    const ssize_t count = libusb_get_device_list(context_, &list);
    int rc = LIBUSB_ERROR_NOT_FOUND;
    for (ssize_t i = 0; i < count; ++i) {
      libusb_device_descriptor descriptor{};
      if (libusb_get_device_descriptor(list[i], &descriptor) != 0) continue;
      if (descriptor.idVendor != vendor_ || descriptor.idProduct != product_) continue;
      rc = libusb_open(list[i], &handle);
      if (rc == 0) {
        bus_ = libusb_get_bus_number(list[i]);
        address_ = libusb_get_device_address(list[i]);
      }
      break;
    }
    if (list) libusb_free_device_list(list, 1);
    if (rc != 0) return FromLibusb(rc, "opening " + Describe());
    libusb_set_auto_detach_kernel_driver(handle, 1);
    if (const int claim = libusb_claim_interface(handle, usb::kInterface); claim != 0) {
      libusb_close(handle);
      return FromLibusb(claim, "claiming interface 0 of " + Describe());
    }
    handle_ = handle;
    return {};
  }

  void Close() override {
    if (handle_ == nullptr) return;
    libusb_release_interface(handle_, usb::kInterface);
    libusb_close(handle_);
    handle_ = nullptr;
  }

  bool IsOpen() const override { return handle_ != nullptr; }

  Status ControlOut(std::uint8_t request, std::uint16_t value,
                    std::chrono::milliseconds timeout) override {
    if (!handle_) return NotOpen();
    const int rc = libusb_control_transfer(handle_, usb::kRequestOut, request, value,
                                           usb::kInterface, nullptr, 0, Ms(timeout));
    if (rc < 0) return FromLibusb(rc, "vendor request " + std::to_string(request));
    return {};
  }

  Result<std::vector<std::uint8_t>> ControlIn(std::uint8_t request, std::uint16_t value,
                                              std::uint16_t length,
                                              std::chrono::milliseconds timeout) override {
    if (!handle_) return NotOpen();
    std::vector<std::uint8_t> data(length);
    const int rc = libusb_control_transfer(handle_, usb::kRequestIn, request, value,
                                           usb::kInterface, data.data(), length, Ms(timeout));
    if (rc < 0) return FromLibusb(rc, "vendor request " + std::to_string(request));
    data.resize(static_cast<std::size_t>(rc));
    return data;
  }

  Result<std::size_t> BulkIn(std::uint8_t* buffer, std::size_t length,
                             std::chrono::milliseconds timeout) override {
    if (!handle_) return NotOpen();
    int transferred = 0;
    const int rc = libusb_bulk_transfer(handle_, usb::kBulkIn, buffer, static_cast<int>(length),
                                        &transferred, Ms(timeout));
    // A timeout may still have moved some bytes; they count.
    if (rc != 0 && !(rc == LIBUSB_ERROR_TIMEOUT && transferred > 0))
      return FromLibusb(rc, "bulk IN from " + Describe());
    return static_cast<std::size_t>(transferred);
  }

  Status ClearHalt() override {
    if (!handle_) return NotOpen();
    const int rc = libusb_clear_halt(handle_, usb::kBulkIn);
    if (rc != 0) return FromLibusb(rc, "clearing the halt of bulk IN");
    return {};
  }

  void SetHotplugCallback(std::function<void(bool)> callback) override {
    std::lock_guard lock(mutex_);
    callback_ = std::move(callback);
  }

  std::string Describe() const override {
    char text[64];
    std::snprintf(text, sizeof text, "USB %04x:%04x", vendor_, product_);
    std::string out = text;
    if (bus_ >= 0) out += " bus " + std::to_string(bus_) + " device " + std::to_string(address_);
    return out;
  }

 private:
  static int LIBUSB_CALL OnHotplug(libusb_context*, libusb_device*, libusb_hotplug_event event,
                                   void* self) {
    auto* transport = static_cast<LibusbTransport*>(self);
    std::function<void(bool)> callback;
    {
      std::lock_guard lock(transport->mutex_);
      callback = transport->callback_;
    }
    if (callback) callback(event == LIBUSB_HOTPLUG_EVENT_DEVICE_ARRIVED);
    return 0;  // stay registered
  }
  Status NotOpen() const {
    return {ErrorCode::kUnavailable, "USB framestore unplugged (" + Describe() + " is not open)"};
  }

  libusb_context* context_;
  std::uint16_t vendor_, product_;
  libusb_device_handle* handle_ = nullptr;
  int bus_ = -1, address_ = -1;
  libusb_hotplug_callback_handle hotplug_ = 0;
  std::thread events_;
  std::atomic<bool> stopping_{false};
  std::mutex mutex_;
  std::function<void(bool)> callback_;
};

}  // namespace

Result<std::unique_ptr<UsbTransport>> OpenLibusbTransport(std::uint16_t vendor,
                                                          std::uint16_t product) {
  libusb_context* context = nullptr;
  if (const int rc = libusb_init(&context); rc != 0)
    return FromLibusb(rc, "starting libusb (is /dev/bus/usb there?)");
  return std::unique_ptr<UsbTransport>(new LibusbTransport(context, vendor, product));
}

}  // namespace bsls::framestore
