// The capture thread of bslsd: the one owner of the Framestore (which is not
// thread-safe). gRPC handlers hand it commands (select camera, set gain,
// grab) and wait for their results; while any preview stream is open it
// grabs continuously at the camera's rate and publishes each frame to every
// stream. A stream only ever holds the newest frame: a slow client skips old
// frames (it is told how many), it never holds up the capture thread or the
// other streams, and memory per stream is one shared frame.
//
// Commands run between preview frames, in arrival order. A grab of both
// sides selects the left camera, grabs, selects the right camera, grabs, and
// puts the previously selected camera back.
//
// Every pass of the loop calls the tick callback (bslsd feeds the systemd
// watchdog from it): a device that hangs inside Grab stops the ticks.
//
// Thread-safety: every public member is safe from any thread.
#ifndef BSLS_SERVICE_CAPTURE_DEVICE_H_
#define BSLS_SERVICE_CAPTURE_DEVICE_H_

#include <chrono>
#include <condition_variable>
#include <deque>
#include <functional>
#include <future>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "bsls/framestore/framestore.h"
#include "bsls/slides/slide_controller.h"

namespace bsls::service {

using Clock = std::chrono::steady_clock;

// Which cameras one grab takes.
enum class GrabSides { kLeft, kRight, kBoth };

// A snapshot of the device for status replies.
struct DeviceSnapshot {
  framestore::Capabilities capabilities;
  framestore::Camera camera = framestore::Camera::kLeft;
  int gain = 0;
  bool available = true;
  std::string availability_reason;  // why not available
  double preview_rate_hz = 0.0;     // measured over the last second of previews
};

// What the device reports to the rest of the daemon.
struct DeviceCallbacks {
  std::function<void()> tick;                            // every loop pass (watchdog)
  std::function<void(const std::string& reason)> lost;   // a grab found the device gone
  std::function<void(const std::string& device)> found;  // it answers again
  std::function<void(framestore::Camera, int gain)> camera_changed;
};

class CaptureDevice {
 public:
  // Takes the framestore and starts the capture thread.
  CaptureDevice(std::unique_ptr<framestore::Framestore> framestore, DeviceCallbacks callbacks);
  // Stops the thread; pending commands fail with kUnavailable.
  ~CaptureDevice();
  CaptureDevice(const CaptureDevice&) = delete;
  CaptureDevice& operator=(const CaptureDevice&) = delete;

  // The device now.
  DeviceSnapshot Snapshot() const;
  // Makes `camera` the selected one (previews and single-side grabs follow it).
  Status SelectCamera(framestore::Camera camera, Clock::time_point deadline);
  // Sets the gain of every camera.
  Status SetGain(int gain, Clock::time_point deadline);
  // Grabs `sides`: one frame per camera, in camera order. kDeadlineExceeded
  // when `deadline` passes before the device delivered.
  Result<std::vector<framestore::GreyFrame>> Grab(GrabSides sides, Clock::time_point deadline);

  // A grab of `sides` as the rig's slides want it (contracts section 1):
  // each side has its own brick slide (2 left, 3 right), so with a brick
  // slide in place a grab of both sides puts slide 2 in place for the left
  // frame and slide 3 for the right (which then stays in), and the capture
  // records slide 0 ("each its own"); otherwise (one side, the reference
  // cross for calibration, no slide controller) the slide in place serves
  // every frame and is the one recorded. `slides` may be nullptr.
  struct SlideGrab {
    std::vector<framestore::GreyFrame> frames;
    int slide = 0;  // the slide of every frame; 0: each side its own
  };
  Result<SlideGrab> GrabWithSlides(GrabSides sides, slides::SlideController* slides,
                                   Clock::time_point deadline);

  // One open preview stream.
  class Preview {
   public:
    ~Preview();
    // The newest frame if it is newer than the last one taken, else nullptr
    // (also once the device stopped); never waits. `dropped` counts the
    // frames published in between that this stream never took.
    std::shared_ptr<const framestore::GreyFrame> Take(std::uint64_t* dropped);

   private:
    friend class CaptureDevice;
    explicit Preview(CaptureDevice* device) : device_(device) {}
    CaptureDevice* device_;
    std::uint64_t last_ = 0;  // publication number of the last frame taken
    std::function<void()> on_frame_;
  };
  // Opens a preview stream; the capture thread grabs while any is open and
  // calls `on_frame` after publishing each frame (on the capture thread,
  // without the device's lock: it may Take, it must not block).
  std::unique_ptr<Preview> OpenPreview(std::function<void()> on_frame);
  // Streams open now.
  int preview_streams() const;

 private:
  struct Command {
    std::function<void(framestore::Framestore*)> run;  // nullptr: fail, shutting down
    Clock::time_point deadline;
  };
  void Loop();
  void Publish(framestore::GreyFrame frame);
  void NoteResult(const Status& status);
  // Runs `work` on the capture thread and waits for it (or the deadline).
  template <typename T>
  Result<T> Run(std::function<Result<T>(framestore::Framestore&)> work, Clock::time_point deadline);

  std::unique_ptr<framestore::Framestore> framestore_;
  DeviceCallbacks callbacks_;

  mutable std::mutex mutex_;
  std::condition_variable wake_;  // the capture thread: commands, previews, stop
  std::deque<Command> commands_;
  bool stopping_ = false;
  std::vector<Preview*> previews_;
  std::shared_ptr<const framestore::GreyFrame> latest_;
  std::uint64_t published_ = 0;
  DeviceSnapshot snapshot_;
  std::deque<Clock::time_point> preview_times_;  // publications of the last second
  std::thread thread_;
};

}  // namespace bsls::service

#endif  // BSLS_SERVICE_CAPTURE_DEVICE_H_
