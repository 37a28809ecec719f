// What the capture store keeps: a capture is one grab of one or both sides
// (1..3 frames, at most one per camera) plus who took it, for whom, how and
// when. CaptureRequest is what the daemon hands to CaptureStore::Put;
// CaptureInfo is the stored metadata (what List returns); Capture is the
// metadata with the frames (what Get returns).
//
// Times: `*_wall` values are std::chrono::system_clock (Unix time, UTC);
// frame timestamps requested/exposed/delivered are std::chrono::steady_clock
// values of the machine that grabbed them, comparable only within one boot.
// Stored with nanosecond resolution.
//
// Thread-safety: plain values.
#ifndef BSLS_STORE_CAPTURE_H_
#define BSLS_STORE_CAPTURE_H_

#include <sys/types.h>

#include <chrono>
#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "bsls/framestore/framestore.h"
#include "bsls/store/capture_id.h"

namespace bsls::store {

// Which side of the face a capture shows (thesis 2.6). Values are stored.
enum class Side : int {
  kLeft = 0,
  kRight = 1,
  kBoth = 2,  // both sides grabbed back to back: one frame per camera
};

// "left", "right", "both"; "side <n>" for values outside the enum.
std::string ToString(Side side);

// The caller on whose behalf a capture was taken (SO_PEERCRED uid and its
// user name, or the TLS peer's identity for remote callers with uid -1).
struct OperatorIdentity {
  std::int64_t uid = -1;  // -1: not a local user
  std::string name;
};

// Limits on request fields (bad input is refused with kInvalidArgument).
inline constexpr std::size_t kMaxTextField = 256;  // bytes of any text field
inline constexpr int kMaxFrameSide = 8192;         // pixels of a frame's width or height

// Everything Put needs: metadata of the grab and its frames.
struct CaptureRequest {
  std::string session_id;         // the daemon's session (operator workflow, thesis 2.5)
  std::string patient_reference;  // opaque reference into the clinic's records, never a name
  Side side = Side::kLeft;
  int slide = 0;                 // the slide in place: 1 reference, 2 left, 3 right; 0 none
  std::string software_version;  // of the daemon that grabbed the frames
  OperatorIdentity requested_by;
  // 1..kMaxCameras frames, distinct cameras; each pixels.size() == stride * height.
  std::vector<framestore::GreyFrame> frames;

  // True when the request can be stored; otherwise `error` (if given) names
  // the field and the reason.
  bool IsValid(std::string* error) const;
};

// The stored description of one frame of a capture.
struct StoredFrameInfo {
  framestore::Camera camera = framestore::Camera::kLeft;
  int gain = 0;
  std::uint64_t sequence = 0;  // the backend's grab counter
  int width = 0;
  int height = 0;
  framestore::FrameTimestamps timestamps;
  std::string sha256;     // hex SHA-256 of the pixels, see sha256.h
  std::string file_name;  // inside <root>/frames/
  std::uint64_t file_bytes = 0;
};

// The stored metadata of one capture.
struct CaptureInfo {
  CaptureId id;
  std::string session_id;
  std::string patient_reference;
  Side side = Side::kLeft;
  int slide = 0;
  std::string software_version;
  OperatorIdentity requested_by;
  std::chrono::system_clock::time_point taken_wall;   // earliest frame's timestamps.wall
  std::chrono::system_clock::time_point stored_wall;  // when Put acknowledged it
  std::uint64_t total_bytes = 0;                      // sum of the frame files' sizes
  std::vector<StoredFrameInfo> frames;                // in camera order
};

// Where a capture is in bslsd's processing queue. Values are
// stored. A capture without a record has not been tried yet.
enum class ProcessingState : int {
  kPending = 1,  // tried, will be tried again (attempts, last_error)
  kDone = 2,     // results stored beside the capture
  kFailed = 3,   // the service cannot process it; not tried again
};

// The processing record of one capture.
struct ProcessingRecord {
  ProcessingState state = ProcessingState::kPending;
  int attempts = 0;
  std::string last_error;
  std::string replica;                       // of the processing service that did it
  std::string software_version;              // of that service
  std::map<std::string, std::string> files;  // result file name -> hex SHA-256 (kDone)
  std::chrono::system_clock::time_point updated;
};

// A capture with its frames, as Get returns it: frames[i] matches
// info.frames[i]; each frame is packed (stride == width).
struct Capture {
  CaptureInfo info;
  std::vector<framestore::GreyFrame> frames;
};

}  // namespace bsls::store

#endif  // BSLS_STORE_CAPTURE_H_
