// The one interface behind which every framestore backend sits (thesis
// chapter 3: a frame grabber fed by the left and right cameras through a
// video multiplexer, thesis 8.2: room for a third camera). The daemon picks a
// backend in its factory from the configuration; the gRPC layer talks only to
// this interface and maps Status codes onto gRPC status codes.
//
// Frames are 8-bit grey, ROW MAJOR, top row first, left pixel first; pixel
// (x, y) is pixels[y * stride + x]. Row y of the frame is video line y of
// the interlaced camera picture, 0-based (thesis Appendix C.1.3).
//
// Thread-safety: a Framestore is NOT thread-safe; the daemon owns each one
// from a single capture thread. capabilities() never changes after opening.
#ifndef BSLS_FRAMESTORE_FRAMESTORE_H_
#define BSLS_FRAMESTORE_FRAMESTORE_H_

#include <chrono>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "bsls/common/status.h"

namespace bsls::framestore {

// The camera (video input) a frame comes from. Values are stable: they are
// the video multiplexer's input numbers and go on the wire and into the store.
enum class Camera : int {
  kLeft = 0,   // the camera looking at the face's left side (thesis 2.6)
  kRight = 1,  // the camera looking at the right side
  kThird = 2,  // a third camera for the whole head (thesis 8.2); optional
};
inline constexpr int kMaxCameras = 3;

// "left", "right" or "third"; "camera <n>" for values outside the enum.
std::string ToString(Camera camera);
// Parses the names of ToString; nullopt for anything else.
std::optional<Camera> ParseCamera(std::string_view text);

// The gain steps a backend accepts: integers min..max, `nominal` the one that
// leaves the video as the camera gives it. `unit` says what one step is.
struct GainRange {
  int min = 0;
  int max = 0;
  int nominal = 0;
  std::string unit;  // e.g. "DAC code, gain = code / 128"

  // True when `gain` is one of the accepted steps.
  bool Contains(int gain) const { return gain >= min && gain <= max; }
};

// What a backend can do; fixed once it is open.
struct Capabilities {
  std::string backend;          // short kind name: "isa", "usb", "simulated"
  std::string device;           // where it is, for humans: "8255 at 0x300 via /dev/port"
  std::vector<Camera> cameras;  // the cameras that can be selected, in input order
  GainRange gain;
  int width = 0;   // pixels of every grabbed frame
  int height = 0;  // rows of every grabbed frame

  // True when `camera` is one of `cameras`.
  bool HasCamera(Camera camera) const;
};

// When a grab happened, on the monotonic clock (std::chrono::steady_clock),
// plus the wall-clock time for the store. requested <= exposed <= delivered.
struct FrameTimestamps {
  std::chrono::steady_clock::time_point requested;  // grab command given to the device
  std::chrono::steady_clock::time_point exposed;    // the picture was complete in the device
  std::chrono::steady_clock::time_point delivered;  // every pixel in host memory
  std::chrono::system_clock::time_point wall;       // wall-clock time at `delivered`
};

// One grabbed 8-bit grey frame and what it was taken with.
struct GreyFrame {
  int width = 0;
  int height = 0;
  int stride = 0;                    // bytes from one row to the next, >= width
  std::vector<std::uint8_t> pixels;  // stride * height bytes, row major, top row first
  Camera camera = Camera::kLeft;
  int gain = 0;                // in the backend's GainRange steps
  std::uint64_t sequence = 0;  // grabs by this backend since it was opened, from 1
  FrameTimestamps timestamps;

  // The grey level at column x, row y; (x, y) must be inside the frame.
  std::uint8_t at(int x, int y) const { return pixels[static_cast<std::size_t>(y) * stride + x]; }
};

// How one grab may be bounded by its caller.
struct GrabOptions {
  // The grab fails with kDeadlineExceeded rather than run past this time
  // (the gRPC call's deadline); nullopt: only the backend's own timeouts.
  std::optional<std::chrono::steady_clock::time_point> deadline;
};

// A frame grabber with selectable cameras and a manual gain.
class Framestore {
 public:
  virtual ~Framestore() = default;

  // What this backend can do; the same for its whole life.
  virtual const Capabilities& capabilities() const = 0;
  // Makes `camera` the source of the next grabs. kInvalidArgument for a camera
  // not in capabilities().cameras; device errors otherwise.
  virtual Status SelectCamera(Camera camera) = 0;
  // Sets the manual gain for the next grabs. kInvalidArgument outside
  // capabilities().gain; device errors otherwise.
  virtual Status SetGain(int gain) = 0;
  // The selected camera (the initial one is the first of capabilities().cameras).
  virtual Camera camera() const = 0;
  // The gain in force (initially capabilities().gain.nominal).
  virtual int gain() const = 0;
  // Grabs one frame of the selected camera: capabilities().width x height,
  // never a partial frame. Fails with a Status naming the device step.
  virtual Result<GreyFrame> Grab(const GrabOptions& options = {}) = 0;
};

}  // namespace bsls::framestore

#endif  // BSLS_FRAMESTORE_FRAMESTORE_H_
