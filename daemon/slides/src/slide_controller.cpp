#include "bsls/slides/slide_controller.h"

#include <set>
#include <thread>

namespace bsls::slides {

namespace {

Status Invalid(const std::string& message) {
  return {ErrorCode::kInvalidArgument, "slide controller: " + message};
}

std::string Ms(std::chrono::milliseconds ms) { return std::to_string(ms.count()) + " ms"; }

}  // namespace

Status Validate(const SlideControllerConfig& config) {
  if (config.select0_line.has_value() != config.select1_line.has_value())
    return Invalid("select0_line and select1_line must both be set or both be absent");
  std::set<unsigned> used;
  auto line = [&used](const char* name, unsigned offset) -> Status {
    if (offset > 1023)
      return Invalid(std::string(name) + " " + std::to_string(offset) + " is above 1023");
    if (!used.insert(offset).second)
      return Invalid(std::string(name) + " " + std::to_string(offset) + " is used by another line");
    return {};
  };
  for (const auto& [name, offset] :
       {std::pair<const char*, unsigned>{"advance_line", config.advance_line},
        {"in_place_line", config.in_place_line},
        {"lamp_line", config.lamp_line},
        {"focus_in_line", config.focus_in_line},
        {"focus_out_line", config.focus_out_line}})
    if (Status s = line(name, offset); !s.ok()) return s;
  if (config.select0_line) {
    if (Status s = line("select0_line", *config.select0_line); !s.ok()) return s;
    if (Status s = line("select1_line", *config.select1_line); !s.ok()) return s;
  }
  using std::chrono::milliseconds;
  if (config.pulse < milliseconds(1) || config.pulse > milliseconds(2000))
    return Invalid("pulse " + Ms(config.pulse) + " is outside 1..2000 ms");
  if (config.settle < milliseconds(0) || config.settle > milliseconds(2000))
    return Invalid("settle " + Ms(config.settle) + " is outside 0..2000 ms");
  if (config.change_timeout < milliseconds(10) || config.change_timeout > milliseconds(120000))
    return Invalid("change_timeout " + Ms(config.change_timeout) + " is outside 10..120000 ms");
  if (config.focus_step < milliseconds(1) || config.focus_step > milliseconds(1000))
    return Invalid("focus_step " + Ms(config.focus_step) + " is outside 1..1000 ms");
  if (config.initial_slide < 1 || config.initial_slide > kSlides)
    return Invalid("initial_slide " + std::to_string(config.initial_slide) + " is outside 1..3");
  if (config.emulated_travel < milliseconds(0) || config.emulated_travel > milliseconds(60000))
    return Invalid("emulated_travel " + Ms(config.emulated_travel) + " is outside 0..60000 ms");
  if (config.chip.empty()) return Invalid("chip is empty");
  return {};
}

SlideController::SlideController(std::unique_ptr<GpioLines> lines,
                                 const SlideControllerConfig& config)
    : lines_(std::move(lines)), config_(config) {}

Result<std::unique_ptr<SlideController>> SlideController::Open(
    std::unique_ptr<GpioLines> lines, const SlideControllerConfig& config) {
  if (Status s = Validate(config); !s.ok()) return s;
  std::unique_ptr<SlideController> controller(new SlideController(std::move(lines), config));
  GpioLines& io = *controller->lines_;
  const int idle = config.active_low ? 1 : 0;
  std::vector<unsigned> outputs = {config.advance_line, config.lamp_line, config.focus_in_line,
                                   config.focus_out_line};
  if (config.select0_line) {
    outputs.push_back(*config.select0_line);
    outputs.push_back(*config.select1_line);
  }
  for (unsigned offset : outputs)
    if (Status s = io.RequestOutput(offset, idle); !s.ok()) return s;
  if (Status s = io.RequestInput(config.in_place_line); !s.ok()) return s;
  Result<int> in_place = io.Get(config.in_place_line);
  if (!in_place.ok()) return in_place.status();
  controller->state_.in_place = (*in_place == 1) != config.active_low;
  // Without select lines the position is what the operator set at power-on.
  controller->state_.slide = config.initial_slide;
  return controller;
}

SlideState SlideController::State() const {
  std::lock_guard lock(state_mutex_);
  return state_;
}

void SlideController::SetListener(std::function<void(const SlideState&)> listener) {
  std::lock_guard lock(state_mutex_);
  listener_ = std::move(listener);
}

void SlideController::Update(const std::function<void(SlideState&)>& change) {
  SlideState copy;
  std::function<void(const SlideState&)> listener;
  {
    std::lock_guard lock(state_mutex_);
    change(state_);
    copy = state_;
    listener = listener_;
  }
  if (listener) listener(copy);
}

Status SlideController::Drive(unsigned line, bool logical) {
  return lines_->Set(line, logical != config_.active_low ? 1 : 0);
}

Status SlideController::Pulse(unsigned line, std::chrono::milliseconds width) {
  if (Status s = Drive(line, true); !s.ok()) return s;
  std::this_thread::sleep_for(width);
  return Drive(line, false);
}

Result<bool> SlideController::WaitInPlace(bool logical, Clock::time_point deadline) {
  return lines_->WaitFor(config_.in_place_line, logical != config_.active_low ? 1 : 0, deadline);
}

// Thesis 2.4: slide 1 for set-up and positioning, 2 and 3 for the two sides.
Status SlideController::ChangeTo(int slide, Clock::time_point deadline) {
  if (slide < 1 || slide > kSlides)
    return Invalid("slide " + std::to_string(slide) +
                   " does not exist: 1 reference, 2 left pattern, 3 right pattern");
  std::lock_guard command(command_mutex_);
  const Clock::time_point start = Clock::now();
  deadline = std::min(deadline, start + config_.change_timeout);
  {
    const SlideState now = State();
    if (now.slide == slide && now.in_place && now.last_error.empty()) return {};
  }
  Update([](SlideState& s) {
    s.moving = true;
    s.in_place = false;
    s.last_error.clear();
  });
  auto fail = [this](Status status) {
    Update([&status](SlideState& s) {
      s.moving = false;
      s.last_error = status.message();
    });
    return status;
  };
  // With select lines one pulse goes straight there; without, one pulse per
  // position counted from the slide believed in place.
  int pulses = 1;
  if (config_.select0_line) {
    if (Status s = Drive(*config_.select0_line, (slide & 1) != 0); !s.ok()) return fail(s);
    if (Status s = Drive(*config_.select1_line, (slide & 2) != 0); !s.ok()) return fail(s);
  } else {
    // After a change that timed out, the carousel may have finished it late:
    // once in_place is back, it stands at the slide it was sent to.
    int from = State().slide;
    if (from == 0) {
      Result<bool> back = WaitInPlace(true, Clock::now());
      if (!back.ok()) return fail(back.status());
      if (!*back)
        return fail({ErrorCode::kFailedPrecondition,
                     "slide " + std::to_string(slide) +
                         ": the carousel has confirmed no slide "
                         "since the last change failed (" +
                         lines_->Describe() +
                         "); free it so that a slide is in place, then retry"});
      from = unconfirmed_;
    }
    pulses = (slide - from + kSlides) % kSlides;
    if (pulses == 0) {
      Update([slide](SlideState& s) {
        s.slide = slide;
        s.in_place = true;
        s.moving = false;
      });
      return {};
    }
  }
  for (int i = 0; i < pulses; ++i) {
    if (Status s = Pulse(config_.advance_line, config_.pulse); !s.ok()) return fail(s);
    // Counting pulses, the mechanism must leave the gate (in_place drops)
    // within `settle`: one that never drops it has not moved. With select
    // lines it may already be at the coded slide and stay in place.
    bool moved = true;
    if (!config_.select0_line) {
      Result<bool> left = WaitInPlace(false, std::min(deadline, Clock::now() + config_.settle));
      if (!left.ok()) return fail(left.status());
      moved = *left;
    } else {
      std::this_thread::sleep_for(config_.settle);
    }
    Result<bool> arrived = moved ? WaitInPlace(true, deadline) : Result<bool>(false);
    if (!arrived.ok()) return fail(arrived.status());
    if (!*arrived) {
      const auto waited =
          std::chrono::duration_cast<std::chrono::milliseconds>(Clock::now() - start);
      unconfirmed_ = slide;
      Update([](SlideState& s) { s.slide = 0; });  // the carousel is somewhere in between
      return fail({ErrorCode::kDeadlineExceeded,
                   "slide " + std::to_string(slide) + " not confirmed in place after " +
                       std::to_string(waited.count()) + " ms (" + lines_->Describe() +
                       (!moved ? ": the in-place line never dropped, the carousel did not move)"
                               : ": the in-place line did not rise)")});
    }
  }
  Update([slide](SlideState& s) {
    s.slide = slide;
    s.in_place = true;
    s.moving = false;
  });
  return {};
}

Status SlideController::Focus(int steps, Clock::time_point deadline) {
  if (steps < -1000 || steps > 1000)
    return Invalid("focus steps " + std::to_string(steps) + " is outside -1000..1000");
  std::lock_guard command(command_mutex_);
  const unsigned line = steps > 0 ? config_.focus_out_line : config_.focus_in_line;
  int done = 0;
  for (; done < std::abs(steps); ++done) {
    if (Clock::now() + 2 * config_.focus_step > deadline) break;
    if (Status s = Pulse(line, config_.focus_step); !s.ok()) return s;
    std::this_thread::sleep_for(config_.focus_step);
  }
  const int moved = steps > 0 ? done : -done;
  Update([moved](SlideState& s) { s.focus_position += moved; });
  if (done < std::abs(steps))
    return {ErrorCode::kDeadlineExceeded, "focus moved " + std::to_string(moved) + " of " +
                                              std::to_string(steps) +
                                              " steps before the call's deadline"};
  return {};
}

Status SlideController::SetLamp(bool on) {
  std::lock_guard command(command_mutex_);
  if (Status s = Drive(config_.lamp_line, on); !s.ok()) return s;
  Update([on](SlideState& s) { s.lamp_on = on; });
  return {};
}

}  // namespace bsls::slides
