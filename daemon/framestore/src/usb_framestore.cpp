#include "bsls/framestore/usb_framestore.h"

#include <zlib.h>

#include <cstring>

namespace bsls::framestore {

namespace {

std::uint16_t Get16(const std::uint8_t* p) { return static_cast<std::uint16_t>(p[0] | p[1] << 8); }
std::uint32_t Get32(const std::uint8_t* p) {
  return static_cast<std::uint32_t>(p[0]) | static_cast<std::uint32_t>(p[1]) << 8 |
         static_cast<std::uint32_t>(p[2]) << 16 | static_cast<std::uint32_t>(p[3]) << 24;
}

using Clock = std::chrono::steady_clock;

// The shorter of `timeout` and what is left until `deadline`.
std::chrono::milliseconds Until(std::chrono::milliseconds timeout,
                                const std::optional<Clock::time_point>& deadline) {
  if (!deadline) return timeout;
  const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(*deadline - Clock::now());
  return std::max(std::chrono::milliseconds(1), std::min(timeout, left));
}

}  // namespace

UsbFramestore::UsbFramestore(std::unique_ptr<UsbTransport> transport,
                             const UsbFramestoreParams& params)
    : transport_(std::move(transport)), params_(params) {}

UsbFramestore::~UsbFramestore() {
  transport_->SetHotplugCallback({});
  transport_->Close();
}

Result<std::unique_ptr<UsbFramestore>> UsbFramestore::Open(std::unique_ptr<UsbTransport> transport,
                                                           const UsbFramestoreParams& params) {
  std::unique_ptr<UsbFramestore> store(new UsbFramestore(std::move(transport), params));
  if (Status s = store->transport_->Open(); !s.ok()) return s;
  if (Status s = store->ReadInfo(false); !s.ok()) return s;
  store->camera_ = store->capabilities_.cameras.front();
  store->gain_ = store->capabilities_.gain.nominal;
  if (Status s = store->SelectCamera(store->camera_); !s.ok()) return s;
  if (Status s = store->SetGain(store->gain_); !s.ok()) return s;
  UsbFramestore* self = store.get();
  store->transport_->SetHotplugCallback([self](bool arrived) {
    if (arrived) self->replugged_ = true;
  });
  return store;
}

Status UsbFramestore::ReadInfo(bool reopening) {
  Result<std::vector<std::uint8_t>> info =
      transport_->ControlIn(usb::kGetInfo, 0, usb::kInfoBytes, params_.control_timeout);
  if (!info.ok()) return info.status();
  if (info->size() < usb::kInfoBytes)
    return {ErrorCode::kDataLoss, "GET_INFO of " + transport_->Describe() + " returned " +
                                      std::to_string(info->size()) + " of 32 bytes"};
  const std::uint8_t* p = info->data();
  if (Get16(p) != 1)
    return {ErrorCode::kUnavailable, transport_->Describe() + " speaks protocol version " +
                                         std::to_string(Get16(p)) + "; bslsd knows version 1"};
  Capabilities caps;
  caps.backend = "usb";
  char firmware[17] = {};
  std::memcpy(firmware, p + 16, 16);
  caps.device = transport_->Describe() + ", firmware " + firmware;
  caps.width = Get16(p + 2);
  caps.height = Get16(p + 4);
  for (int c = 0; c < kMaxCameras; ++c)
    if (p[6] & (1u << c)) caps.cameras.push_back(static_cast<Camera>(c));
  caps.gain = {static_cast<std::int16_t>(Get16(p + 8)), static_cast<std::int16_t>(Get16(p + 10)),
               static_cast<std::int16_t>(Get16(p + 12)), "device gain code"};
  if (caps.cameras.empty() || caps.width <= 0 || caps.height <= 0 || caps.width > 8192 ||
      caps.height > 8192 || !caps.gain.Contains(caps.gain.nominal))
    return {ErrorCode::kDataLoss, "GET_INFO of " + transport_->Describe() +
                                      " describes no usable device (cameras, size or gain)"};
  if (reopening && (caps.width != capabilities_.width || caps.height != capabilities_.height ||
                    caps.cameras != capabilities_.cameras))
    return {ErrorCode::kFailedPrecondition,
            "the USB framestore that came back is not the one bslsd opened (size or cameras "
            "differ): restart bslsd to use it"};
  capabilities_ = std::move(caps);
  return {};
}

Status UsbFramestore::Transfer(Status status) {
  if (status.code() == ErrorCode::kUnavailable) {
    lost_ = true;
    transport_->Close();
  }
  return status;
}

Status UsbFramestore::EnsureOpen() {
  if (!lost_ && !replugged_ && transport_->IsOpen()) return {};
  // Back after an unplug (hotplug said so, or we try on every call).
  replugged_ = false;
  transport_->Close();
  if (Status s = transport_->Open(); !s.ok())
    return {ErrorCode::kUnavailable, "USB framestore unplugged: " + s.message()};
  if (Status s = ReadInfo(true); !s.ok()) return Transfer(s);
  // The firmware starts afresh: what the operator chose is sent again.
  if (Status s = Send(usb::kSelectCamera, static_cast<std::uint16_t>(camera_)); !s.ok()) return s;
  if (Status s = Send(usb::kSetGain, static_cast<std::uint16_t>(gain_)); !s.ok()) return s;
  lost_ = false;
  Resynchronise();
  return {};
}

Status UsbFramestore::Send(std::uint8_t request, std::uint16_t value) {
  return Transfer(transport_->ControlOut(request, value, params_.control_timeout));
}

Status UsbFramestore::SelectCamera(Camera camera) {
  if (!capabilities_.HasCamera(camera))
    return {ErrorCode::kInvalidArgument,
            "camera " + ToString(camera) + " is not connected to " + transport_->Describe()};
  if (Status s = EnsureOpen(); !s.ok()) return s;
  if (Status s = Send(usb::kSelectCamera, static_cast<std::uint16_t>(camera)); !s.ok()) return s;
  camera_ = camera;
  return {};
}

Status UsbFramestore::SetGain(int gain) {
  if (!capabilities_.gain.Contains(gain))
    return {ErrorCode::kInvalidArgument, "gain " + std::to_string(gain) + " is outside " +
                                             std::to_string(capabilities_.gain.min) + ".." +
                                             std::to_string(capabilities_.gain.max)};
  if (Status s = EnsureOpen(); !s.ok()) return s;
  if (Status s = Send(usb::kSetGain, static_cast<std::uint16_t>(gain)); !s.ok()) return s;
  gain_ = gain;
  return {};
}

void UsbFramestore::Resynchronise() {
  transport_->ClearHalt();
  std::vector<std::uint8_t> sink(params_.chunk_bytes);
  for (int i = 0; i < 1024; ++i) {
    Result<std::size_t> n =
        transport_->BulkIn(sink.data(), sink.size(), std::chrono::milliseconds(100));
    if (!n.ok() || *n == 0) break;
  }
}

Result<GreyFrame> UsbFramestore::Grab(const GrabOptions& options) {
  if (Status s = EnsureOpen(); !s.ok()) return s;
  GreyFrame frame;
  frame.timestamps.requested = Clock::now();
  const std::uint16_t tag = ++tag_;
  if (Status s = Send(usb::kGrab, tag); !s.ok()) return s;

  auto fail = [this](Status status) -> Status {
    if (status.code() == ErrorCode::kUnavailable) return Transfer(status);
    Resynchronise();
    return status;
  };
  // Reads exactly `n` bytes into `out`, each transfer bounded.
  auto read_exactly = [&](std::uint8_t* out, std::size_t n, std::chrono::milliseconds timeout,
                          const char* what) -> Status {
    std::size_t got = 0;
    while (got < n) {
      if (options.deadline && Clock::now() >= *options.deadline)
        return {ErrorCode::kDeadlineExceeded, std::string("USB framestore: the grab's deadline "
                                                          "passed while reading the ") +
                                                  what};
      Result<std::size_t> r = transport_->BulkIn(out + got, std::min(n - got, params_.chunk_bytes),
                                                 Until(timeout, options.deadline));
      if (!r.ok()) {
        if (r.status().code() == ErrorCode::kDeadlineExceeded && got > 0)
          return {ErrorCode::kDataLoss, std::string("USB framestore: the ") + what +
                                            " ended after " + std::to_string(got) + " of " +
                                            std::to_string(n) + " bytes"};
        return {r.status().code(),
                std::string("USB framestore, reading the ") + what + ": " + r.status().message()};
      }
      got += *r;
    }
    return {};
  };

  std::uint8_t header[usb::kHeaderBytes];
  for (int stale = 0;; ++stale) {
    if (Status s = read_exactly(header, sizeof header, params_.frame_timeout, "frame header");
        !s.ok())
      return fail(s);
    if (Get32(header) != usb::kMagic || Get16(header + 6) != usb::kHeaderBytes)
      return fail({ErrorCode::kDataLoss,
                   "USB framestore: a frame header without the BSLF magic "
                   "(the stream is out of step; resynchronised)"});
    if (crc32(0L, header, 44) != Get32(header + 44))
      return fail({ErrorCode::kDataLoss,
                   "USB framestore: the frame header's CRC-32 does not "
                   "match (damaged on the way; resynchronised)"});
    const std::uint32_t payload_bytes = Get32(header + 24);
    if (Get16(header + 8) == tag) break;
    // A frame of an earlier, abandoned grab: read it whole and drop it.
    if (stale >= params_.stale_frames_max || payload_bytes > (64u << 20))
      return fail({ErrorCode::kDataLoss, "USB framestore: too many frames with the wrong tag"});
    std::vector<std::uint8_t> drop(payload_bytes);
    if (Status s = read_exactly(drop.data(), drop.size(), params_.chunk_timeout, "stale frame");
        !s.ok())
      return fail(s);
  }
  frame.timestamps.exposed = Clock::now();  // the header came: the picture is complete
  frame.width = Get16(header + 16);
  frame.height = Get16(header + 18);
  frame.stride = Get16(header + 20);
  const std::uint32_t payload_bytes = Get32(header + 24);
  if (frame.width != capabilities_.width || frame.height != capabilities_.height ||
      frame.stride < frame.width ||
      payload_bytes != static_cast<std::uint32_t>(frame.stride) * frame.height)
    return fail({ErrorCode::kDataLoss,
                 "USB framestore: the frame header says " + std::to_string(frame.width) + " x " +
                     std::to_string(frame.height) + " (stride " + std::to_string(frame.stride) +
                     ", " + std::to_string(payload_bytes) + " bytes); the device is " +
                     std::to_string(capabilities_.width) + " x " +
                     std::to_string(capabilities_.height)});
  frame.pixels.resize(payload_bytes);
  if (Status s = read_exactly(frame.pixels.data(), payload_bytes, params_.chunk_timeout, "payload");
      !s.ok())
    return fail(s);
  if (crc32(0L, frame.pixels.data(), payload_bytes) != Get32(header + 40))
    return fail({ErrorCode::kDataLoss,
                 "USB framestore: the payload's CRC-32 does not match "
                 "(a frame damaged on the way was dropped)"});
  frame.camera = static_cast<Camera>(header[10]);
  frame.gain = static_cast<std::int16_t>(Get16(header + 12));
  frame.sequence = ++sequence_;
  frame.timestamps.delivered = Clock::now();
  frame.timestamps.wall = std::chrono::system_clock::now();
  return frame;
}

}  // namespace bsls::framestore
