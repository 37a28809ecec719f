// GpioLines on a real chip through libgpiod v1.6 (Debian bookworm).
#include <gpiod.h>
#include <poll.h>

#include <cerrno>
#include <cstring>
#include <map>
#include <mutex>

#include "bsls/slides/gpio_lines.h"

namespace bsls::slides {

namespace {

constexpr const char* kConsumer = "bslsd";

Status FromErrno(int error, const std::string& what) {
  const std::string reason = what + ": " + std::strerror(error);
  switch (error) {
    case EACCES:
    case EPERM:
      return {ErrorCode::kPermissionDenied,
              reason + " (the udev rule 70-bsls.rules gives the bsls group the slide chip)"};
    case ENOENT:
    case ENODEV:
    case ENXIO:
      return {ErrorCode::kUnavailable, reason};
    case EBUSY:
      return {ErrorCode::kFailedPrecondition, reason};
    case EINVAL:
      return {ErrorCode::kInvalidArgument, reason};
    default:
      return {ErrorCode::kUnavailable, reason};
  }
}

class LibgpiodLines final : public GpioLines {
 public:
  LibgpiodLines(gpiod_chip* chip, std::string name) : chip_(chip), name_(std::move(name)) {}
  ~LibgpiodLines() override {
    for (auto& [offset, line] : lines_) gpiod_line_release(line);
    gpiod_chip_close(chip_);
  }

  Status RequestOutput(unsigned offset, int initial) override {
    std::lock_guard lock(mutex_);
    gpiod_line* line = nullptr;
    if (Status s = Line(offset, &line); !s.ok()) return s;
    if (gpiod_line_request_output(line, kConsumer, initial) != 0) return Busy(offset, line);
    lines_[offset] = line;
    return {};
  }

  Status RequestInput(unsigned offset) override {
    std::lock_guard lock(mutex_);
    gpiod_line* line = nullptr;
    if (Status s = Line(offset, &line); !s.ok()) return s;
    // Edge events when the chip has them; plain input otherwise (then WaitFor polls).
    if (gpiod_line_request_both_edges_events(line, kConsumer) == 0) {
      events_[offset] = true;
    } else if (gpiod_line_request_input(line, kConsumer) != 0) {
      return Busy(offset, line);
    }
    lines_[offset] = line;
    return {};
  }

  Status Set(unsigned offset, int value) override {
    std::lock_guard lock(mutex_);
    auto it = lines_.find(offset);
    if (it == lines_.end()) return NotRequested(offset);
    if (gpiod_line_set_value(it->second, value) != 0)
      return FromErrno(errno, "setting line " + std::to_string(offset) + " of " + name_);
    return {};
  }

  Result<int> Get(unsigned offset) override {
    std::lock_guard lock(mutex_);
    auto it = lines_.find(offset);
    if (it == lines_.end()) return NotRequested(offset);
    const int value = gpiod_line_get_value(it->second);
    if (value < 0)
      return FromErrno(errno, "reading line " + std::to_string(offset) + " of " + name_);
    return value;
  }

  Result<bool> WaitFor(unsigned offset, int value, Clock::time_point deadline) override {
    for (;;) {
      Result<int> now = Get(offset);
      if (!now.ok()) return now.status();
      if (*now == value) return true;
      const Clock::time_point t = Clock::now();
      if (t >= deadline) return false;
      const auto left = std::min<Clock::duration>(deadline - t, std::chrono::milliseconds(20));
      gpiod_line* line = nullptr;
      bool events = false;
      {
        std::lock_guard lock(mutex_);
        line = lines_[offset];
        events = events_.count(offset) > 0;
      }
      if (events) {
        timespec timeout{
            0,
            static_cast<long>(std::chrono::duration_cast<std::chrono::nanoseconds>(left).count())};
        const int rc = gpiod_line_event_wait(line, &timeout);
        if (rc < 0)
          return FromErrno(errno, "waiting on line " + std::to_string(offset) + " of " + name_);
        if (rc == 1) {
          gpiod_line_event event{};
          gpiod_line_event_read(line, &event);  // consumed; the level is read above
        }
      } else {
        ::poll(
            nullptr, 0,
            static_cast<int>(std::chrono::duration_cast<std::chrono::milliseconds>(left).count()) +
                1);
      }
    }
  }

  std::string Describe() const override { return name_; }

 private:
  Status Line(unsigned offset, gpiod_line** out) {
    if (lines_.count(offset))
      return {ErrorCode::kFailedPrecondition,
              "line " + std::to_string(offset) + " of " + name_ + " is requested twice"};
    *out = gpiod_chip_get_line(chip_, offset);
    if (*out == nullptr)
      return {ErrorCode::kInvalidArgument,
              "line " + std::to_string(offset) + " does not exist on " + name_ + " (" +
                  std::to_string(gpiod_chip_num_lines(chip_)) + " lines)"};
    return {};
  }
  Status Busy(unsigned offset, gpiod_line* line) {
    const int error = errno;
    const char* owner = gpiod_line_consumer(line);
    std::string what = "requesting line " + std::to_string(offset) + " of " + name_;
    if (error == EBUSY && owner != nullptr) what += " (used by " + std::string(owner) + ")";
    return FromErrno(error, what);
  }
  Status NotRequested(unsigned offset) const {
    return {ErrorCode::kInternal,
            "line " + std::to_string(offset) + " of " + name_ + " was not requested"};
  }

  std::mutex mutex_;
  gpiod_chip* chip_;
  std::string name_;
  std::map<unsigned, gpiod_line*> lines_;
  std::map<unsigned, bool> events_;
};

}  // namespace

Result<std::unique_ptr<GpioLines>> OpenLibgpiodChip(const std::string& chip) {
  if (chip.empty()) return Status(ErrorCode::kInvalidArgument, "the GPIO chip name is empty");
  errno = 0;
  gpiod_chip* handle = gpiod_chip_open_lookup(chip.c_str());
  if (handle == nullptr)
    return FromErrno(errno ? errno : ENOENT, "opening GPIO chip '" + chip + "'");
  std::string name = gpiod_chip_name(handle);
  const char* label = gpiod_chip_label(handle);
  if (label && *label) name += " [" + std::string(label) + "]";
  return std::unique_ptr<GpioLines>(new LibgpiodLines(handle, std::move(name)));
}

}  // namespace bsls::slides
