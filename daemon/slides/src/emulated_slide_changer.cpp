#include "bsls/slides/emulated_slide_changer.h"

#include <thread>

namespace bsls::slides {

EmulatedSlideChanger::EmulatedSlideChanger(const SlideControllerConfig& config,
                                           std::chrono::milliseconds min_pulse)
    : config_(config), min_pulse_(min_pulse), position_(config.initial_slide) {}

Status EmulatedSlideChanger::RequestOutput(unsigned offset, int initial) {
  std::lock_guard lock(mutex_);
  if (outputs_.count(offset) || inputs_.count(offset))
    return {ErrorCode::kFailedPrecondition,
            "line " + std::to_string(offset) + " of the emulated mechanism is requested twice"};
  outputs_.insert(offset);
  levels_[offset] = initial;
  return {};
}

Status EmulatedSlideChanger::RequestInput(unsigned offset) {
  std::lock_guard lock(mutex_);
  if (outputs_.count(offset) || inputs_.count(offset))
    return {ErrorCode::kFailedPrecondition,
            "line " + std::to_string(offset) + " of the emulated mechanism is requested twice"};
  if (offset != config_.in_place_line)
    return {ErrorCode::kInvalidArgument,
            "line " + std::to_string(offset) + " is not an input of the emulated mechanism"};
  inputs_.insert(offset);
  return {};
}

void EmulatedSlideChanger::Settle() const {
  if (target_ && !faults_.jammed && Clock::now() >= arrive_at_) {
    position_ = *target_;
    target_.reset();
  }
}

int EmulatedSlideChanger::Level(unsigned offset) const {
  auto it = levels_.find(offset);
  return it == levels_.end() ? 0 : it->second;
}

int EmulatedSlideChanger::InPlaceLevel() const {
  if (faults_.in_place_stuck_at) return *faults_.in_place_stuck_at;
  Settle();
  const bool in_place = !target_.has_value();
  return in_place != config_.active_low ? 1 : 0;
}

Status EmulatedSlideChanger::Set(unsigned offset, int value) {
  {
    std::lock_guard lock(mutex_);
    if (!outputs_.count(offset))
      return {ErrorCode::kInternal,
              "line " + std::to_string(offset) + " of the emulated mechanism is not an output"};
    const bool was = Active(Level(offset));
    const bool now = Active(value);
    levels_[offset] = value;
    Settle();
    if (offset == config_.advance_line && now && !was) advance_rose_ = Clock::now();
    if (offset == config_.advance_line && !now && was &&
        Clock::now() - advance_rose_ >= min_pulse_) {
      // A complete pulse: start a move (a pulse during a move is ignored,
      // as a real mechanism ignores commands until the gate is settled).
      if (!target_) {
        int next = position_ % kSlides + 1;
        if (config_.select0_line && config_.select1_line) {
          const int code = (Active(Level(*config_.select1_line)) ? 2 : 0) +
                           (Active(Level(*config_.select0_line)) ? 1 : 0);
          if (code >= 1 && code <= kSlides) next = code;
        }
        if (next != position_) {
          const int distance = (next - position_ + kSlides) % kSlides;
          target_ = next;
          arrive_at_ = Clock::now() + config_.emulated_travel * distance;
        }
        ++advances_;
      }
    }
    if ((offset == config_.focus_in_line || offset == config_.focus_out_line) && !now && was)
      focus_steps_ += offset == config_.focus_out_line ? 1 : -1;
  }
  changed_.notify_all();
  return {};
}

Result<int> EmulatedSlideChanger::Get(unsigned offset) {
  std::lock_guard lock(mutex_);
  if (inputs_.count(offset)) return InPlaceLevel();
  if (outputs_.count(offset)) return Level(offset);
  return Status(ErrorCode::kInternal,
                "line " + std::to_string(offset) + " of the emulated mechanism was not requested");
}

Result<bool> EmulatedSlideChanger::WaitFor(unsigned offset, int value, Clock::time_point deadline) {
  std::unique_lock lock(mutex_);
  if (!inputs_.count(offset))
    return Status(ErrorCode::kInternal,
                  "line " + std::to_string(offset) + " of the emulated mechanism is not an input");
  for (;;) {
    if (InPlaceLevel() == value) return true;
    const Clock::time_point now = Clock::now();
    if (now >= deadline) return false;
    // Wake at the arrival time or on a line change, whichever is first.
    Clock::time_point wake = deadline;
    if (target_ && !faults_.jammed && arrive_at_ < wake) wake = arrive_at_;
    changed_.wait_until(lock, wake);
  }
}

int EmulatedSlideChanger::position() const {
  std::lock_guard lock(mutex_);
  Settle();
  return position_;
}

bool EmulatedSlideChanger::moving() const {
  std::lock_guard lock(mutex_);
  Settle();
  return target_.has_value();
}

int EmulatedSlideChanger::focus_steps() const {
  std::lock_guard lock(mutex_);
  return focus_steps_;
}

bool EmulatedSlideChanger::lamp_lit() const {
  std::lock_guard lock(mutex_);
  return Active(Level(config_.lamp_line));
}

int EmulatedSlideChanger::advances() const {
  std::lock_guard lock(mutex_);
  return advances_;
}

void EmulatedSlideChanger::SetFaults(const EmulatedSlideChangerFaults& faults) {
  {
    std::lock_guard lock(mutex_);
    faults_ = faults;
    if (!faults.jammed && target_) arrive_at_ = std::min(arrive_at_, Clock::now());
  }
  changed_.notify_all();
}

}  // namespace bsls::slides
