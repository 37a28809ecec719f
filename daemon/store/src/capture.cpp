#include "bsls/store/capture.h"

#include <set>

namespace bsls::store {

std::string ToString(Side side) {
  switch (side) {
    case Side::kLeft:
      return "left";
    case Side::kRight:
      return "right";
    case Side::kBoth:
      return "both";
  }
  return "side " + std::to_string(static_cast<int>(side));
}

namespace {

bool TextOk(std::string_view name, const std::string& value, std::string* error) {
  if (value.size() > kMaxTextField) {
    if (error) {
      *error = std::string(name) + " is " + std::to_string(value.size()) + " bytes long, at most " +
               std::to_string(kMaxTextField) + " are allowed";
    }
    return false;
  }
  if (value.find('\0') != std::string::npos) {
    if (error) *error = std::string(name) + " contains a NUL byte";
    return false;
  }
  return true;
}

bool Fail(std::string* error, std::string message) {
  if (error) *error = std::move(message);
  return false;
}

}  // namespace

bool CaptureRequest::IsValid(std::string* error) const {
  if (!TextOk("session id", session_id, error) ||
      !TextOk("patient reference", patient_reference, error) ||
      !TextOk("software version", software_version, error) ||
      !TextOk("operator name", requested_by.name, error)) {
    return false;
  }
  const int side_value = static_cast<int>(side);
  if (side_value < 0 || side_value > static_cast<int>(Side::kBoth)) {
    return Fail(error, "side " + std::to_string(side_value) + " is not left, right or both");
  }
  if (slide < 0) return Fail(error, "slide " + std::to_string(slide) + " is negative");
  if (frames.empty() || frames.size() > static_cast<std::size_t>(framestore::kMaxCameras)) {
    return Fail(error, "a capture has 1.." + std::to_string(framestore::kMaxCameras) +
                           " frames, this one has " + std::to_string(frames.size()));
  }
  std::set<int> cameras;
  for (std::size_t i = 0; i < frames.size(); ++i) {
    const framestore::GreyFrame& frame = frames[i];
    const std::string which = "frame " + std::to_string(i);
    const int camera = static_cast<int>(frame.camera);
    if (camera < 0 || camera >= framestore::kMaxCameras) {
      return Fail(error, which + ": camera " + std::to_string(camera) + " is unknown");
    }
    if (!cameras.insert(camera).second) {
      return Fail(error, which + ": a second frame of the " + framestore::ToString(frame.camera) +
                             " camera");
    }
    if (frame.width < 1 || frame.height < 1 || frame.width > kMaxFrameSide ||
        frame.height > kMaxFrameSide) {
      return Fail(error, which + ": size " + std::to_string(frame.width) + "x" +
                             std::to_string(frame.height) + " is outside 1.." +
                             std::to_string(kMaxFrameSide));
    }
    if (frame.stride < frame.width) {
      return Fail(error, which + ": stride " + std::to_string(frame.stride) +
                             " is less than the width " + std::to_string(frame.width));
    }
    const std::size_t expected = static_cast<std::size_t>(frame.stride) * frame.height;
    if (frame.pixels.size() != expected) {
      return Fail(error, which + ": " + std::to_string(frame.pixels.size()) +
                             " pixel bytes, stride x height is " + std::to_string(expected));
    }
  }
  return true;
}

}  // namespace bsls::store
