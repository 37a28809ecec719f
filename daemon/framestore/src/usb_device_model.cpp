#include "bsls/framestore/usb_device_model.h"

#include <zlib.h>

#include <cstring>
#include <thread>

namespace bsls::framestore {

namespace {

void Put16(std::vector<std::uint8_t>& out, std::size_t at, std::uint16_t v) {
  out[at] = static_cast<std::uint8_t>(v);
  out[at + 1] = static_cast<std::uint8_t>(v >> 8);
}
void Put32(std::vector<std::uint8_t>& out, std::size_t at, std::uint32_t v) {
  for (int i = 0; i < 4; ++i) out[at + i] = static_cast<std::uint8_t>(v >> (8 * i));
}
void Put64(std::vector<std::uint8_t>& out, std::size_t at, std::uint64_t v) {
  for (int i = 0; i < 8; ++i) out[at + i] = static_cast<std::uint8_t>(v >> (8 * i));
}

Status Unplugged() {
  return {ErrorCode::kUnavailable, "USB framestore unplugged (LIBUSB_ERROR_NO_DEVICE)"};
}

}  // namespace

UsbDeviceModel::UsbDeviceModel(VideoSource source, std::uint8_t camera_mask)
    : source_(std::move(source)), camera_mask_(camera_mask) {}

Status UsbDeviceModel::Open() {
  std::lock_guard lock(mutex_);
  if (!plugged_)
    return {ErrorCode::kUnavailable,
            "opening USB 1209:b515: no such device (LIBUSB_ERROR_NOT_FOUND)"};
  open_ = true;
  return {};
}

void UsbDeviceModel::Close() {
  std::lock_guard lock(mutex_);
  open_ = false;
}

bool UsbDeviceModel::IsOpen() const {
  std::lock_guard lock(mutex_);
  return open_;
}

Status UsbDeviceModel::ControlOut(std::uint8_t request, std::uint16_t value,
                                  std::chrono::milliseconds) {
  std::lock_guard lock(mutex_);
  if (!plugged_ || !open_) return Unplugged();
  switch (request) {
    case usb::kSelectCamera:
      if (value > 2 || !(camera_mask_ & (1u << value)))
        return {ErrorCode::kDataLoss, "vendor request 2: pipe error (LIBUSB_ERROR_PIPE)"};
      camera_ = value;
      return {};
    case usb::kSetGain:
      if (static_cast<int>(value) < kGainMin || static_cast<int>(value) > kGainMax)
        return {ErrorCode::kDataLoss, "vendor request 3: pipe error (LIBUSB_ERROR_PIPE)"};
      gain_ = value;
      return {};
    case usb::kGrab: {
      ++grabs_;
      if (faults_.silent) return {};
      if (faults_.stale_frame) {
        const std::vector<std::uint8_t> old =
            MakeFrame(static_cast<std::uint16_t>(value - 1), camera_);
        endpoint_.insert(endpoint_.end(), old.begin(), old.end());
        faults_.stale_frame = false;
      }
      std::vector<std::uint8_t> frame = MakeFrame(value, camera_);
      if (faults_.corrupt_payload) {
        frame[usb::kHeaderBytes + frame.size() / 2 - usb::kHeaderBytes / 2] ^= 0x10;
        faults_.corrupt_payload = false;
      }
      if (faults_.corrupt_header) {
        frame[18] ^= 0x01;  // the height
        faults_.corrupt_header = false;
      }
      if (faults_.short_frame) {
        frame.resize(frame.size() - 1000);
        faults_.short_frame = false;
      }
      if (faults_.stall) {
        halted_ = true;
        faults_.stall = false;
      }
      endpoint_.insert(endpoint_.end(), frame.begin(), frame.end());
      return {};
    }
    default:
      return {ErrorCode::kDataLoss,
              "vendor request " + std::to_string(request) + ": pipe error (LIBUSB_ERROR_PIPE)"};
  }
}

Result<std::vector<std::uint8_t>> UsbDeviceModel::ControlIn(std::uint8_t request, std::uint16_t,
                                                            std::uint16_t length,
                                                            std::chrono::milliseconds) {
  std::lock_guard lock(mutex_);
  if (!plugged_ || !open_) return Unplugged();
  std::vector<std::uint8_t> out;
  if (request == usb::kGetInfo) {
    out.assign(usb::kInfoBytes, 0);
    Put16(out, 0, 1);
    Put16(out, 2, isa::kFrameWidth);
    Put16(out, 4, isa::kFrameHeight);
    out[6] = camera_mask_;
    Put16(out, 8, static_cast<std::uint16_t>(kGainMin));
    Put16(out, 10, static_cast<std::uint16_t>(kGainMax));
    Put16(out, 12, static_cast<std::uint16_t>(kGainNominal));
    std::memcpy(out.data() + 16, "model-1.0", 9);
  } else if (request == usb::kGetStatus) {
    out.assign(4, 0);
  } else {
    return Status(ErrorCode::kDataLoss,
                  "vendor request " + std::to_string(request) + ": pipe error (LIBUSB_ERROR_PIPE)");
  }
  if (out.size() > length) out.resize(length);
  return out;
}

Result<std::size_t> UsbDeviceModel::BulkIn(std::uint8_t* buffer, std::size_t length,
                                           std::chrono::milliseconds timeout) {
  std::unique_lock lock(mutex_);
  if (!plugged_ || !open_) return Unplugged();
  if (halted_) return Status(ErrorCode::kDataLoss, "bulk IN: pipe error (LIBUSB_ERROR_PIPE)");
  if (endpoint_.empty()) {
    // Nothing to send: the host's transfer times out.
    lock.unlock();
    std::this_thread::sleep_for(std::min(timeout, std::chrono::milliseconds(2000)));
    return Status(ErrorCode::kDeadlineExceeded, "bulk IN: timed out (LIBUSB_ERROR_TIMEOUT)");
  }
  const std::size_t n = std::min(length, endpoint_.size());
  std::copy_n(endpoint_.begin(), n, buffer);
  endpoint_.erase(endpoint_.begin(), endpoint_.begin() + static_cast<std::ptrdiff_t>(n));
  return n;
}

Status UsbDeviceModel::ClearHalt() {
  std::lock_guard lock(mutex_);
  if (!plugged_ || !open_) return Unplugged();
  halted_ = false;
  return {};
}

void UsbDeviceModel::SetHotplugCallback(std::function<void(bool)> callback) {
  std::lock_guard lock(mutex_);
  hotplug_ = std::move(callback);
}

void UsbDeviceModel::Notify(bool arrived) {
  std::function<void(bool)> callback;
  {
    std::lock_guard lock(mutex_);
    callback = hotplug_;
  }
  if (callback) callback(arrived);
}

void UsbDeviceModel::Unplug() {
  {
    std::lock_guard lock(mutex_);
    plugged_ = false;
    open_ = false;
    endpoint_.clear();
    halted_ = false;
  }
  Notify(false);
}

void UsbDeviceModel::Replug() {
  {
    std::lock_guard lock(mutex_);
    plugged_ = true;
    camera_ = 0;  // the firmware starts afresh
    gain_ = kGainNominal;
  }
  Notify(true);
}

void UsbDeviceModel::SetFaults(const UsbDeviceFaults& faults) {
  std::lock_guard lock(mutex_);
  faults_ = faults;
}

int UsbDeviceModel::camera() const {
  std::lock_guard lock(mutex_);
  return camera_;
}
int UsbDeviceModel::gain() const {
  std::lock_guard lock(mutex_);
  return gain_;
}
int UsbDeviceModel::grabs() const {
  std::lock_guard lock(mutex_);
  return grabs_;
}

std::vector<std::uint8_t> UsbDeviceModel::MakeFrame(std::uint16_t tag, int camera) {
  const std::shared_ptr<const VideoFrame> picture = source_ ? source_(camera, sequence_) : nullptr;
  const int width = isa::kFrameWidth;
  const int height = isa::kFrameHeight;
  const int stride = width;
  std::vector<std::uint8_t> out(usb::kHeaderBytes + static_cast<std::size_t>(stride) * height, 0);
  // Pixels: the picture scaled by gain / nominal (no picture: black).
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x) {
      const int grey = picture ? picture->pixels[static_cast<std::size_t>(y) * width + x] : 0;
      out[usb::kHeaderBytes + static_cast<std::size_t>(y) * stride + x] =
          static_cast<std::uint8_t>(std::min(255, grey * gain_ / kGainNominal));
    }
  Put32(out, 0, usb::kMagic);
  Put16(out, 4, 1);
  Put16(out, 6, usb::kHeaderBytes);
  Put16(out, 8, tag);
  out[10] = static_cast<std::uint8_t>(camera);
  Put16(out, 12, static_cast<std::uint16_t>(gain_));
  Put16(out, 16, static_cast<std::uint16_t>(width));
  Put16(out, 18, static_cast<std::uint16_t>(height));
  Put16(out, 20, static_cast<std::uint16_t>(stride));
  Put32(out, 24, static_cast<std::uint32_t>(stride * height));
  Put32(out, 28, ++sequence_);
  Put64(out, 32, static_cast<std::uint64_t>(sequence_) * 40000);
  Put32(out, 40,
        static_cast<std::uint32_t>(crc32(0L, out.data() + usb::kHeaderBytes,
                                         static_cast<uInt>(out.size() - usb::kHeaderBytes))));
  Put32(out, 44, static_cast<std::uint32_t>(crc32(0L, out.data(), 44)));
  return out;
}

}  // namespace bsls::framestore
