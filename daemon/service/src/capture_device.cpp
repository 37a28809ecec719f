#include "bsls/service/capture_device.h"

#include <utility>

namespace bsls::service {

using framestore::Camera;
using framestore::Framestore;
using framestore::GreyFrame;

namespace {

// Errors that say the device itself is gone or not answering.
bool IsDeviceLoss(ErrorCode code) {
  return code == ErrorCode::kUnavailable || code == ErrorCode::kDeadlineExceeded;
}

struct Unit {};

}  // namespace

CaptureDevice::CaptureDevice(std::unique_ptr<Framestore> framestore, DeviceCallbacks callbacks)
    : framestore_(std::move(framestore)), callbacks_(std::move(callbacks)) {
  snapshot_.capabilities = framestore_->capabilities();
  snapshot_.camera = framestore_->camera();
  snapshot_.gain = framestore_->gain();
  thread_ = std::thread([this] { Loop(); });
}

CaptureDevice::~CaptureDevice() {
  {
    std::lock_guard lock(mutex_);
    stopping_ = true;
  }
  wake_.notify_all();
  thread_.join();
}

DeviceSnapshot CaptureDevice::Snapshot() const {
  std::lock_guard lock(mutex_);
  DeviceSnapshot out = snapshot_;
  const Clock::time_point now = Clock::now();
  std::size_t recent = 0;
  for (const Clock::time_point t : preview_times_)
    if (now - t <= std::chrono::seconds(1)) ++recent;
  out.preview_rate_hz = static_cast<double>(recent);
  return out;
}

template <typename T>
Result<T> CaptureDevice::Run(std::function<Result<T>(Framestore&)> work,
                             Clock::time_point deadline) {
  auto promise = std::make_shared<std::promise<Result<T>>>();
  std::future<Result<T>> future = promise->get_future();
  {
    std::lock_guard lock(mutex_);
    if (stopping_) return Status(ErrorCode::kUnavailable, "the capture device is shutting down");
    commands_.push_back({[promise, work = std::move(work), deadline](Framestore* store) {
                           if (store == nullptr) {
                             promise->set_value(Status(ErrorCode::kUnavailable,
                                                       "the capture device is shutting down"));
                             return;
                           }
                           if (Clock::now() >= deadline) {
                             promise->set_value(Status(ErrorCode::kDeadlineExceeded,
                                                       "the call's deadline passed while it "
                                                       "waited for the capture thread"));
                             return;
                           }
                           promise->set_value(work(*store));
                         },
                         deadline});
  }
  wake_.notify_all();
  // The command always completes (the loop runs or fails every queued one);
  // the caller stops waiting at its deadline plus a grace for the device's
  // own timeout to report first.
  if (future.wait_until(deadline + std::chrono::milliseconds(200)) != std::future_status::ready)
    return Status(ErrorCode::kDeadlineExceeded,
                  "the framestore did not answer before the deadline");
  return future.get();
}

Status CaptureDevice::SelectCamera(Camera camera, Clock::time_point deadline) {
  Result<Unit> result = Run<Unit>(
      [this, camera](Framestore& store) -> Result<Unit> {
        Status status = store.SelectCamera(camera);
        NoteResult(status);
        if (!status.ok()) return status;
        {
          std::lock_guard lock(mutex_);
          snapshot_.camera = camera;
        }
        if (callbacks_.camera_changed) callbacks_.camera_changed(camera, store.gain());
        return Unit{};
      },
      deadline);
  return result.ok() ? Status() : result.status();
}

Status CaptureDevice::SetGain(int gain, Clock::time_point deadline) {
  Result<Unit> result = Run<Unit>(
      [this, gain](Framestore& store) -> Result<Unit> {
        Status status = store.SetGain(gain);
        NoteResult(status);
        if (!status.ok()) return status;
        {
          std::lock_guard lock(mutex_);
          snapshot_.gain = gain;
        }
        if (callbacks_.camera_changed) callbacks_.camera_changed(store.camera(), gain);
        return Unit{};
      },
      deadline);
  return result.ok() ? Status() : result.status();
}

Result<std::vector<GreyFrame>> CaptureDevice::Grab(GrabSides sides, Clock::time_point deadline) {
  return Run<std::vector<GreyFrame>>(
      [this, sides, deadline](Framestore& store) -> Result<std::vector<GreyFrame>> {
        framestore::GrabOptions options;
        options.deadline = deadline;
        std::vector<GreyFrame> frames;
        const Camera selected = store.camera();
        std::vector<Camera> cameras;
        if (sides == GrabSides::kBoth) {
          cameras = {Camera::kLeft, Camera::kRight};
        } else {
          cameras = {sides == GrabSides::kLeft ? Camera::kLeft : Camera::kRight};
        }
        Status failure;
        for (Camera camera : cameras) {
          if (Status s = store.SelectCamera(camera); !s.ok()) {
            failure = s;
            break;
          }
          Result<GreyFrame> frame = store.Grab(options);
          if (!frame.ok()) {
            failure = frame.status();
            break;
          }
          frames.push_back(std::move(frame).value());
        }
        // The operator's selection stays what it was.
        if (store.camera() != selected) {
          if (Status s = store.SelectCamera(selected); !s.ok() && failure.ok()) failure = s;
        }
        NoteResult(failure);
        if (!failure.ok()) return failure;
        return frames;
      },
      deadline);
}

Result<CaptureDevice::SlideGrab> CaptureDevice::GrabWithSlides(GrabSides sides,
                                                               slides::SlideController* slides,
                                                               Clock::time_point deadline) {
  SlideGrab out;
  out.slide = slides ? slides->State().slide : 0;
  if (sides != GrabSides::kBoth || (out.slide != 2 && out.slide != 3)) {
    Result<std::vector<GreyFrame>> frames = Grab(sides, deadline);
    if (!frames.ok()) return frames.status();
    out.frames = std::move(frames).value();
    return out;
  }
  for (const auto& [one, side_slide] : {std::pair{GrabSides::kLeft, 2}, {GrabSides::kRight, 3}}) {
    if (Status changed = slides->ChangeTo(side_slide, deadline); !changed.ok())
      return Status(changed.code(), "slide " + std::to_string(side_slide) +
                                        " for the grab of both sides: " + changed.message());
    Result<std::vector<GreyFrame>> grabbed = Grab(one, deadline);
    if (!grabbed.ok()) return grabbed.status();
    for (GreyFrame& frame : *grabbed) out.frames.push_back(std::move(frame));
  }
  out.slide = 0;  // per frame: 2 for the left, 3 for the right
  return out;
}

CaptureDevice::Preview::~Preview() {
  {
    std::lock_guard lock(device_->mutex_);
    std::erase(device_->previews_, this);
  }
  device_->wake_.notify_all();
}

std::shared_ptr<const GreyFrame> CaptureDevice::Preview::Take(std::uint64_t* dropped) {
  std::lock_guard lock(device_->mutex_);
  if (device_->stopping_ || !device_->latest_ || device_->published_ <= last_) return nullptr;
  if (dropped) *dropped = last_ == 0 ? 0 : device_->published_ - last_ - 1;
  last_ = device_->published_;
  return device_->latest_;
}

std::unique_ptr<CaptureDevice::Preview> CaptureDevice::OpenPreview(std::function<void()> on_frame) {
  std::unique_ptr<Preview> preview(new Preview(this));
  preview->on_frame_ = std::move(on_frame);
  {
    std::lock_guard lock(mutex_);
    previews_.push_back(preview.get());
  }
  wake_.notify_all();
  return preview;
}

int CaptureDevice::preview_streams() const {
  std::lock_guard lock(mutex_);
  return static_cast<int>(previews_.size());
}

void CaptureDevice::Publish(GreyFrame frame) {
  std::vector<std::function<void()>> notify;
  {
    std::lock_guard lock(mutex_);
    latest_ = std::make_shared<const GreyFrame>(std::move(frame));
    ++published_;
    const Clock::time_point now = Clock::now();
    preview_times_.push_back(now);
    while (!preview_times_.empty() && now - preview_times_.front() > std::chrono::seconds(1))
      preview_times_.pop_front();
    for (const Preview* preview : previews_)
      if (preview->on_frame_) notify.push_back(preview->on_frame_);
  }
  // Copies, called without the lock: a stream may close (and its Preview
  // go) meanwhile; what its callback holds outlives it.
  for (const auto& on_frame : notify) on_frame();
}

void CaptureDevice::NoteResult(const Status& status) {
  bool lost = false;
  bool found = false;
  {
    std::lock_guard lock(mutex_);
    if (!status.ok() && IsDeviceLoss(status.code())) {
      lost = snapshot_.available;
      snapshot_.available = false;
      snapshot_.availability_reason = status.message();
    } else if (status.ok() && !snapshot_.available) {
      found = true;
      snapshot_.available = true;
      snapshot_.availability_reason.clear();
    }
  }
  if (lost && callbacks_.lost) callbacks_.lost(status.message());
  if (found && callbacks_.found) callbacks_.found(framestore_->capabilities().device);
}

void CaptureDevice::Loop() {
  // While the device is lost, previews retry at this pace, not flat out.
  constexpr auto kRetryPause = std::chrono::milliseconds(500);
  constexpr auto kIdleTick = std::chrono::milliseconds(500);
  for (;;) {
    if (callbacks_.tick) callbacks_.tick();
    std::optional<Command> command;
    bool preview = false;
    {
      std::unique_lock lock(mutex_);
      wake_.wait_for(lock, kIdleTick,
                     [&] { return stopping_ || !commands_.empty() || !previews_.empty(); });
      if (stopping_) break;
      if (!commands_.empty()) {
        command = std::move(commands_.front());
        commands_.pop_front();
      } else {
        preview = !previews_.empty();
      }
    }
    if (command) {
      command->run(framestore_.get());
      continue;
    }
    if (!preview) continue;
    framestore::GrabOptions options;
    options.deadline = Clock::now() + std::chrono::seconds(2);
    Result<GreyFrame> frame = framestore_->Grab(options);
    NoteResult(frame.ok() ? Status() : frame.status());
    if (frame.ok()) {
      Publish(std::move(frame).value());
    } else {
      std::unique_lock lock(mutex_);
      wake_.wait_for(lock, kRetryPause, [&] { return stopping_ || !commands_.empty(); });
    }
  }
  // Fail what is still queued.
  std::deque<Command> left;
  {
    std::lock_guard lock(mutex_);
    left.swap(commands_);
  }
  for (Command& command : left) command.run(nullptr);
}

}  // namespace bsls::service
