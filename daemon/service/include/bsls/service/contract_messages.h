// The daemon's one conversion between its own types (cameras, frames,
// stored captures, times) and the contract's messages
// (bsls/v1/capture.proto). The capture service, the processing queue and
// bslsd's device events all convert here.
#ifndef BSLS_SERVICE_CONTRACT_MESSAGES_H_
#define BSLS_SERVICE_CONTRACT_MESSAGES_H_

#include <google/protobuf/timestamp.pb.h>

#include <chrono>
#include <optional>
#include <string>

#include "bsls/framestore/framestore.h"
#include "bsls/store/capture_store.h"
#include "bsls/v1/capture.pb.h"

namespace bsls::service {

// The camera a message names; nullopt for CAMERA_UNSPECIFIED or a value
// the contract does not define.
std::optional<framestore::Camera> FromProto(v1::Camera camera);
// The contract's name of a camera.
v1::Camera ToProto(framestore::Camera camera);
// The contract's name of a grab's side.
v1::GrabSide ToProto(store::Side side);
// A wall-clock time as a protobuf Timestamp, and back.
google::protobuf::Timestamp ToProto(std::chrono::system_clock::time_point t);
std::chrono::system_clock::time_point FromProto(const google::protobuf::Timestamp& t);

// A grabbed frame's size, camera, gain, sequence, times and `sha256`; its
// pixels too when `with_pixels`.
void FillFrame(const framestore::GreyFrame& frame, bool with_pixels, const std::string& sha256,
               v1::Frame* out);
// A stored frame's description (no pixels: SetPixels adds them).
void FillStoredFrame(const store::StoredFrameInfo& info, v1::Frame* out);
// The frame's pixel bytes, as stored (stride bytes a row).
void SetPixels(const framestore::GreyFrame& frame, v1::Frame* out);
// A stored capture's description, its frames' included (no pixels).
void FillInfo(const store::CaptureInfo& info, v1::CaptureInfo* out);

}  // namespace bsls::service

#endif  // BSLS_SERVICE_CONTRACT_MESSAGES_H_
