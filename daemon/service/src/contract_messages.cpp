#include "bsls/service/contract_messages.h"

#include <google/protobuf/util/time_util.h>

namespace bsls::service {

using framestore::Camera;
using google::protobuf::util::TimeUtil;

std::optional<Camera> FromProto(v1::Camera camera) {
  switch (camera) {
    case v1::CAMERA_LEFT:
      return Camera::kLeft;
    case v1::CAMERA_RIGHT:
      return Camera::kRight;
    case v1::CAMERA_THIRD:
      return Camera::kThird;
    default:
      return std::nullopt;
  }
}

v1::Camera ToProto(Camera camera) {
  switch (camera) {
    case Camera::kLeft:
      return v1::CAMERA_LEFT;
    case Camera::kRight:
      return v1::CAMERA_RIGHT;
    case Camera::kThird:
      return v1::CAMERA_THIRD;
  }
  return v1::CAMERA_UNSPECIFIED;
}

v1::GrabSide ToProto(store::Side side) {
  switch (side) {
    case store::Side::kLeft:
      return v1::GRAB_SIDE_LEFT;
    case store::Side::kRight:
      return v1::GRAB_SIDE_RIGHT;
    case store::Side::kBoth:
      return v1::GRAB_SIDE_BOTH;
  }
  return v1::GRAB_SIDE_UNSPECIFIED;
}

namespace {

std::int64_t MonotonicNs(std::chrono::steady_clock::time_point t) {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(t.time_since_epoch()).count();
}

}  // namespace

google::protobuf::Timestamp ToProto(std::chrono::system_clock::time_point t) {
  return TimeUtil::NanosecondsToTimestamp(
      std::chrono::duration_cast<std::chrono::nanoseconds>(t.time_since_epoch()).count());
}

std::chrono::system_clock::time_point FromProto(const google::protobuf::Timestamp& t) {
  return std::chrono::system_clock::time_point(
      std::chrono::duration_cast<std::chrono::system_clock::duration>(
          std::chrono::nanoseconds(TimeUtil::TimestampToNanoseconds(t))));
}

// The frame's metadata; pixels only when `with_pixels`.
void FillFrame(const framestore::GreyFrame& frame, bool with_pixels, const std::string& sha256,
               v1::Frame* out) {
  out->set_camera(ToProto(frame.camera));
  out->set_width(static_cast<std::uint32_t>(frame.width));
  out->set_height(static_cast<std::uint32_t>(frame.height));
  out->set_stride(static_cast<std::uint32_t>(frame.stride));
  if (with_pixels) SetPixels(frame, out);
  out->set_gain(frame.gain);
  out->set_sequence(frame.sequence);
  *out->mutable_delivered() = ToProto(frame.timestamps.wall);
  out->set_requested_monotonic_ns(MonotonicNs(frame.timestamps.requested));
  out->set_exposed_monotonic_ns(MonotonicNs(frame.timestamps.exposed));
  out->set_delivered_monotonic_ns(MonotonicNs(frame.timestamps.delivered));
  out->set_sha256(sha256);
}

void FillStoredFrame(const store::StoredFrameInfo& info, v1::Frame* out) {
  out->set_camera(ToProto(info.camera));
  out->set_width(static_cast<std::uint32_t>(info.width));
  out->set_height(static_cast<std::uint32_t>(info.height));
  out->set_stride(static_cast<std::uint32_t>(info.width));
  out->set_gain(info.gain);
  out->set_sequence(info.sequence);
  *out->mutable_delivered() = ToProto(info.timestamps.wall);
  out->set_requested_monotonic_ns(MonotonicNs(info.timestamps.requested));
  out->set_exposed_monotonic_ns(MonotonicNs(info.timestamps.exposed));
  out->set_delivered_monotonic_ns(MonotonicNs(info.timestamps.delivered));
  out->set_sha256(info.sha256);
}

void FillInfo(const store::CaptureInfo& info, v1::CaptureInfo* out) {
  out->set_capture_id(info.id.str());
  out->set_session_id(info.session_id);
  out->set_patient_reference(info.patient_reference);
  out->set_side(ToProto(info.side));
  out->set_slide(info.slide);
  out->set_software_version(info.software_version);
  out->set_requested_by_uid(info.requested_by.uid);
  out->set_requested_by(info.requested_by.name);
  *out->mutable_taken() = ToProto(info.taken_wall);
  *out->mutable_stored() = ToProto(info.stored_wall);
  out->set_total_bytes(info.total_bytes);
  for (const store::StoredFrameInfo& frame : info.frames) FillStoredFrame(frame, out->add_frames());
}

void SetPixels(const framestore::GreyFrame& frame, v1::Frame* out) {
  out->set_pixels(frame.pixels.data(), frame.pixels.size());
}

}  // namespace bsls::service
